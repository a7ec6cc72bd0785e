// Enrichment, local map update and incremental segmentation per frame on simulated S2 frames
// (full world, the paper's rig). Targets on 2 cores: local map + segmentation at most 20 ms a
// frame, with enrichment at most 35 ms.
#include <benchmark/benchmark.h>

#include "semsegmap/enrich/enricher.h"
#include "semsegmap/local_map/local_map.h"
#include "semsegmap/segment/incremental_segmenter.h"
#include "semsegmap/sim/simulator.h"

using namespace semsegmap;

namespace {

struct Recorded {
  DatasetInfo info;
  std::vector<Frame> frames;
  std::vector<EnrichedCloud> clouds;
};

// 60 consecutive frames of S2, rendered once and reused by every benchmark.
const Recorded& recorded() {
  static const Recorded r = [] {
    Recorded out;
    sim::SimConfig c;
    c.run = sim::Run::S2;
    c.max_frames = 60;
    sim::Simulator s(c);
    out.info = s.info();
    for (size_t i = 0; i < s.size(); ++i) {
      out.frames.push_back(s.frame(i));
      out.clouds.push_back(enrichFrame(out.frames.back(), out.info.rig, EnrichmentConfig{}));
    }
    return out;
  }();
  return r;
}

void BM_Enrich(benchmark::State& state) {
  const Recorded& r = recorded();
  size_t i = 0;
  for (auto _ : state) {
    EnrichedCloud c = enrichFrame(r.frames[i++ % r.frames.size()], r.info.rig, EnrichmentConfig{});
    benchmark::DoNotOptimize(c.data());
  }
}
BENCHMARK(BM_Enrich)->Unit(benchmark::kMillisecond)->UseRealTime();

// Local map + segmentation over the recorded sequence, frame after frame; state.range(0) picks
// the configuration: 0 SemSegMap (d 0.3 with penalties), 1 SegMap (d 0.2, geometry only).
void BM_LocalMapAndSegmentation(benchmark::State& state) {
  const Recorded& r = recorded();
  SegmentationConfig seg;
  if (state.range(0) == 1) {
    seg.d_segment_m = 0.2;
    seg.hue_penalty = seg.class_penalty = 0.0;
  }
  auto map = std::make_unique<LocalMap>(LocalMapConfig{}, r.info.classes);
  auto segmenter = std::make_unique<IncrementalSegmenter>(seg);
  size_t i = 0, new_voxels = 0, observations = 0;
  for (auto _ : state) {
    if (i == r.frames.size()) {
      state.PauseTiming();
      map = std::make_unique<LocalMap>(LocalMapConfig{}, r.info.classes);
      segmenter = std::make_unique<IncrementalSegmenter>(seg);
      i = 0;
      state.ResumeTiming();
    }
    const Pose T = *r.frames[i].T_world_base;
    const LocalMapUpdate u =
        map->update(r.clouds[i], T * r.info.rig.T_base_lidar, T.translation().head<2>());
    auto s = segmenter->update(*map, u, i, r.frames[i].timestamp_s);
    benchmark::DoNotOptimize(s.observed.data());
    new_voxels += u.newly_active.size();
    observations += s.observed.size();
    ++i;
  }
  state.SetLabel(state.range(0) == 0 ? "semsegmap" : "segmap");
  state.counters["new_voxels"] =
      benchmark::Counter(static_cast<double>(new_voxels), benchmark::Counter::kAvgIterations);
  state.counters["observations"] =
      benchmark::Counter(static_cast<double>(observations), benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_LocalMapAndSegmentation)
    ->Arg(0)
    ->Arg(1)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(240);

}  // namespace

namespace {

// The local map alone, to see where the per-frame time goes.
void BM_LocalMapOnly(benchmark::State& state) {
  const Recorded& r = recorded();
  auto map = std::make_unique<LocalMap>(LocalMapConfig{}, r.info.classes);
  size_t i = 0, voxels = 0;
  for (auto _ : state) {
    if (i == r.frames.size()) {
      state.PauseTiming();
      map = std::make_unique<LocalMap>(LocalMapConfig{}, r.info.classes);
      i = 0;
      state.ResumeTiming();
    }
    const Pose T = *r.frames[i].T_world_base;
    const LocalMapUpdate u =
        map->update(r.clouds[i], T * r.info.rig.T_base_lidar, T.translation().head<2>());
    benchmark::DoNotOptimize(u.newly_active.data());
    voxels = map->size();
    ++i;
  }
  state.counters["voxels"] = static_cast<double>(voxels);
}
BENCHMARK(BM_LocalMapOnly)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(240);

}  // namespace
