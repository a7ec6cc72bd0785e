// Uses the installed library the way a user's program would: a target map saved and loaded
// through io/, localized against with localize/. Exit 0 and "consumer ok" when it all works.
#include <cstdio>
#include <filesystem>

#include <semsegmap/artefacts/map_file.h>
#include <semsegmap/localize/localizer.h>

int main(int argc, char** argv) {
  using namespace semsegmap;
  if (argc != 2) return 2;
  TargetMap map;
  map.descriptor = "eigen";
  map.fingerprint = "eigen-v1";
  map.descriptors.resize(12, 4);
  std::vector<Eigen::Vector3f> local;
  for (int i = 0; i < 12; ++i) {
    MapSegment s;
    s.centroid = Eigen::Vector3f(3.0f * (i % 4), 5.0f * (i / 4), 0.5f * (i % 3));
    map.segments.push_back(s);
    map.descriptors.row(i) = Eigen::Vector4f(i, i * i % 7, i % 3, 1).transpose();
    local.push_back(s.centroid - Eigen::Vector3f(1, 2, 0));  // the robot 1 m, 2 m away
  }
  const std::filesystem::path path = argv[1];
  saveTargetMap(path, map);
  const Localizer localizer(loadTargetMap(path), LocalizerConfig{});
  const auto found = localizer.localize(local, map.descriptors);
  if (!found || (found->T_map_local.translation() - Eigen::Vector3d(1, 2, 0)).norm() > 1e-3) {
    std::printf("consumer: wrong localization\n");
    return 1;
  }
  std::printf("consumer ok: %d inliers\n", found->inliers);
  return 0;
}
