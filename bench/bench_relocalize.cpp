// One relocalization from one scan (localize/relocalizer.h) against a synthetic town of 10 000
// segments (tests/synthetic_town.h, 2.2 km x 2.2 km, 512 stored points a segment as
// `map --points 512` keeps): a robot's local segments are the buildings within 60 m, their
// points sampled every 0.2 m so that a query holds about 120 000 points, as a 64-beam scan
// without its ground does, and their 64-d descriptors the map's with noise. Timed: the 64
// nearest map descriptors of each local segment, the place votes, the verification of each
// voted place and the registration check of the scan's points. The town's wrong places seldom
// reach the registration; a real lost frame's do, and its target (150 ms on 2 cores, front end
// included) is bench_lost_frame.cpp's.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "semsegmap/localize/relocalizer.h"
#include "synthetic_town.h"

using namespace semsegmap;

namespace {

constexpr int kSegments = 10000, kDim = 64, kRobots = 8;
constexpr double kSideM = 2236, kRadiusM = 60, kNoise = 1.7;

struct Fixture {
  Town town;
  std::unique_ptr<Localizer> localizer;
  std::vector<Query> queries;
  std::vector<Eigen::Vector3d> robots;
  Pose T_map_local = someLocalFrame();
};

const Fixture& fixture() {
  static const Fixture f = [] {
    Fixture out;
    out.town = makeTown(kSegments, kSideM, 21, kDim, 512);
    out.localizer = std::make_unique<Localizer>(out.town.map, LocalizerConfig{});
    SeededRng rng(22);
    for (int i = 0; i < kRobots; ++i) {
      const Eigen::Vector3d robot(rng.uniform(200, kSideM - 200), rng.uniform(200, kSideM - 200),
                                  0);
      out.robots.push_back(robot);
      out.queries.push_back(
          queryAt(out.town, robot, out.T_map_local, kRadiusM, kNoise, 23 + i, 0.2));
    }
    return out;
  }();
  return f;
}

void BM_Relocalize(benchmark::State& state) {
  const Fixture& f = fixture();
  const RelocalizationConfig config;
  size_t i = 0, tries = 0, right = 0, wrong = 0, points = 0;
  for (auto _ : state) {
    const Query& q = f.queries[i % f.queries.size()];
    const auto r =
        relocalize(*f.localizer, q.centroids, q.descriptors, q.points, q.robot_local, config);
    if (r) {
      const double off =
          (r->match.T_map_local * q.robot_local - f.robots[i % f.robots.size()]).norm();
      (off < 1.0 ? right : wrong) += 1;
    }
    for (const auto& segment : q.points) points += segment.size();
    ++tries;
    ++i;
  }
  const double n = static_cast<double>(std::max<size_t>(1, tries));
  state.counters["relocalized"] = static_cast<double>(right) / n;
  state.counters["wrong"] = static_cast<double>(wrong) / n;
  state.counters["points"] = static_cast<double>(points) / n;
}
BENCHMARK(BM_Relocalize)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2 * kRobots);

}  // namespace
