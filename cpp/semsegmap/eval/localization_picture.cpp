#include "semsegmap/eval/localization_picture.h"

#include "semsegmap/viz/localization_png.h"

namespace semsegmap {

void writeLocalizationPicture(const std::filesystem::path& png, const LocalizationRun& run,
                              const TargetMap& map, const std::string& title) {
  viz::LocalizationPicture pic;
  pic.title = title;
  for (const MapSegment& s : map.segments) {
    pic.map_centroids.push_back(s.centroid);
    pic.map_points.insert(pic.map_points.end(), s.points.begin(), s.points.end());
  }
  pic.has_ground_truth = !run.trajectory_gt.empty();
  pic.trajectory = pic.has_ground_truth ? run.trajectory_gt : run.trajectory_odom;
  const LocalizationRecord* best = nullptr;
  for (const LocalizationRecord& r : run.localizations) {
    pic.localizations.emplace_back(r.T_map_base.translation(),
                                   r.T_world_base ? r.translation_error_m : -1.0);
    if (!best || r.inliers > best->inliers) best = &r;
  }
  if (best) {
    pic.highlight = best->T_map_base.translation();
    pic.matches = best->matches;
  }
  viz::writeLocalizationPng(png, pic);
}

}  // namespace semsegmap
