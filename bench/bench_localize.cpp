// One localization query against synthetic target maps of 10k, 100k and 1M segments: the k = 16
// nearest map descriptors of 100 local segments, their centroid correspondences, geometric
// verification. Targets on 2 cores: 5 / 10 / 30 ms a query.
//
// Map descriptors are 64-d and unit-norm like learned ones, drawn around 1000 centres (segments
// of similar objects describe alike) rather than uniform on the sphere, where no neighbour
// means anything. Centroids are uniform over 2 km x 2 km. A query has 30 local segments that
// are map segments within 50 m of the robot (descriptor noise, centroid noise 0.1 m, one
// random 6-DoF pose) and 70 that are not in the map.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/random.h"
#include "semsegmap/localize/descriptor_index.h"
#include "semsegmap/localize/geometric_verification.h"

using namespace semsegmap;

namespace {

constexpr int kDim = 64, kLocalSegments = 100, kTrue = 30, kQueries = 16;
constexpr double kAreaM = 2000;

struct Query {
  DescriptorMatrix descriptors;
  std::vector<Eigen::Vector3d> centroids;  // local map frame
  std::vector<int64_t> sources;            // map segment of each of the first kTrue
  Pose T_map_local;
};

struct Fixture {
  std::vector<Eigen::Vector3d> centroids;
  DescriptorIndex index;
  std::vector<Query> queries;
  double build_s = 0, recall = 0, sources_found = 0;
};

DescriptorMatrix descriptorsAround(SeededRng& rng, const DescriptorMatrix& centres, int n) {
  DescriptorMatrix m(n, kDim);
  for (int i = 0; i < n; ++i) {
    const int c = rng.integer(0, static_cast<int>(centres.rows()) - 1);
    for (int j = 0; j < kDim; ++j) m(i, j) = centres(c, j) + static_cast<float>(rng.gaussian(0.08));
  }
  m.rowwise().normalize();
  return m;
}

Query makeQuery(SeededRng& rng, const DescriptorMatrix& map_descriptors,
                const std::vector<Eigen::Vector3d>& map_centroids,
                const DescriptorMatrix& centres) {
  Query q;
  const Eigen::Vector3d centre(rng.uniform(200, kAreaM - 200), rng.uniform(200, kAreaM - 200), 0);
  q.T_map_local = planarPose(centre.x(), centre.y(), 0, rng.uniform(-M_PI, M_PI));
  // At least twice as many map segments around as true ones, also in the sparse 10k map.
  const double density = static_cast<double>(map_centroids.size()) / (kAreaM * kAreaM);
  double radius = std::max(50.0, std::sqrt(2.0 * kTrue / (density * M_PI)));
  std::vector<int> near;
  for (;; radius *= 1.2) {
    near.clear();
    for (size_t i = 0; i < map_centroids.size(); ++i)
      if ((map_centroids[i] - centre).head<2>().norm() < radius)
        near.push_back(static_cast<int>(i));
    if (near.size() >= 2 * static_cast<size_t>(kTrue)) break;
  }
  q.descriptors = descriptorsAround(rng, centres, kLocalSegments);
  const Pose T_local_map = q.T_map_local.inverse();
  for (int s = 0; s < kLocalSegments; ++s) {
    if (s < kTrue) {
      const size_t pick = static_cast<size_t>(rng.integer(s, static_cast<int>(near.size()) - 1));
      std::swap(near[static_cast<size_t>(s)], near[pick]);
      const int id = near[static_cast<size_t>(s)];
      q.sources.push_back(id);
      for (int j = 0; j < kDim; ++j)
        q.descriptors(s, j) = map_descriptors(id, j) + static_cast<float>(rng.gaussian(0.02));
      q.descriptors.row(s).normalize();
      const Eigen::Vector3d noise(rng.gaussian(0.1), rng.gaussian(0.1), rng.gaussian(0.1));
      q.centroids.push_back(T_local_map * map_centroids[static_cast<size_t>(id)] + noise);
    } else {
      const double r = radius * std::sqrt(rng.uniform()), a = rng.uniform(-M_PI, M_PI);
      q.centroids.emplace_back(r * std::cos(a), r * std::sin(a), rng.uniform(0, 10));
    }
  }
  return q;
}

// Built once per map size: descriptors, index (timed apart), queries, recall against exact.
const Fixture& fixture(int n) {
  static std::map<int, std::unique_ptr<Fixture>> cache;
  auto& slot = cache[n];
  if (slot) return *slot;
  slot = std::make_unique<Fixture>();
  Fixture& f = *slot;
  SeededRng rng(static_cast<uint64_t>(n));
  DescriptorMatrix centres(1000, kDim);
  for (int i = 0; i < centres.rows(); ++i)
    for (int j = 0; j < kDim; ++j) centres(i, j) = static_cast<float>(rng.gaussian(1));
  centres.rowwise().normalize();
  const DescriptorMatrix descriptors = descriptorsAround(rng, centres, n);
  for (int i = 0; i < n; ++i)
    f.centroids.emplace_back(rng.uniform(0, kAreaM), rng.uniform(0, kAreaM), rng.uniform(0, 10));
  const auto start = std::chrono::steady_clock::now();
  f.index.build(descriptors);
  f.build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (int i = 0; i < kQueries; ++i)
    f.queries.push_back(makeQuery(rng, descriptors, f.centroids, centres));

  DescriptorIndexConfig exact_cfg;
  exact_cfg.exact_below = static_cast<size_t>(n) + 1;
  DescriptorIndex exact(exact_cfg);
  exact.build(descriptors);
  size_t hits = 0, total = 0;
  for (int i = 0; i < 2; ++i) {
    const Neighbours a = f.index.search(f.queries[i].descriptors, 16);
    const Neighbours e = exact.search(f.queries[i].descriptors, 16);
    for (size_t q = 0; q < e.queries(); ++q)
      for (int j = 0; j < 16; ++j, ++total)
        hits += std::count(e.idsOf(q), e.idsOf(q) + 16, a.id(q, j));
  }
  f.recall = static_cast<double>(hits) / static_cast<double>(total);
  // What localization needs: the true map segment among a true local segment's k candidates.
  size_t found = 0;
  for (const Query& q : f.queries) {
    const Neighbours a = f.index.search(q.descriptors, 16);
    for (int s = 0; s < kTrue; ++s)
      found += std::count(a.idsOf(s), a.idsOf(s) + 16, q.sources[static_cast<size_t>(s)]);
  }
  f.sources_found = static_cast<double>(found) / (kTrue * f.queries.size());
  return f;
}

void BM_LocalizationQuery(benchmark::State& state) {
  const Fixture& f = fixture(static_cast<int>(state.range(0)));
  const GeometricVerificationConfig verification;
  size_t i = 0, inliers = 0, correspondences = 0;
  double search_s = 0;
  for (auto _ : state) {
    const Query& q = f.queries[i++ % f.queries.size()];
    const auto t0 = std::chrono::steady_clock::now();
    const Neighbours nn = f.index.search(q.descriptors, 16);
    search_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<Correspondence> c;
    c.reserve(nn.ids.size());
    for (size_t s = 0; s < nn.queries(); ++s)
      for (int j = 0; j < nn.k && nn.id(s, j) >= 0; ++j)
        c.push_back({q.centroids[s], f.centroids[static_cast<size_t>(nn.id(s, j))],
                     static_cast<int64_t>(s), nn.id(s, j), nn.squaredDistance(s, j)});
    const VerificationResult r = verify(c, verification);
    if (!r.found || translationError(r.T_target_local, q.T_map_local) > 0.5 ||
        rotationErrorDeg(r.T_target_local, q.T_map_local) > 1.0) {
      state.SkipWithError("the query did not localize at its true pose");
      break;
    }
    inliers += r.inliers.size();
    correspondences += c.size();
  }
  state.counters["inliers"] =
      benchmark::Counter(static_cast<double>(inliers), benchmark::Counter::kAvgIterations);
  state.counters["correspondences"] =
      benchmark::Counter(static_cast<double>(correspondences), benchmark::Counter::kAvgIterations);
  // The retrieval's share of the query; the rest is building correspondences and verification.
  state.counters["search_ms"] =
      benchmark::Counter(1000.0 * search_s, benchmark::Counter::kAvgIterations);
  state.counters["build_s"] = f.build_s;
  state.counters["recall16"] = f.recall;
  state.counters["sources_found"] = f.sources_found;
  state.SetLabel(f.index.approximate() ? "ivf" : "exact");
}
BENCHMARK(BM_LocalizationQuery)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
