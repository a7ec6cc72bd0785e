// The whole pipeline per frame on simulated S2 frames (full world), as a robot runs it while
// localizing: enrichment, local map, segmentation, describing the changed segments with the
// shipped model and querying a target map (built from the same stretch at sunrise beforehand,
// untimed). Arg 0: SemSegMap (0) or SegMap (1). Arg 1: the segmentation network in front: -1
// none, the simulator's labels (as in the paper); 0 on every picture; r > 0 at r Hz per camera,
// the scans in between taking its latest labels (bench_semantics.cpp has the network). Target:
// at least 20 Hz on 2 cores without the network.
#include <benchmark/benchmark.h>

#include <chrono>
#include <thread>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/describe/learned_describer.h"
#include "semsegmap/pipeline/live_session.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/semantics/frame_labeler.h"
#include "semsegmap/semantics/live_labeler.h"
#include "semsegmap/settings/class_map_file.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/sim/simulator.h"

using namespace semsegmap;

namespace {

class Recorded : public FrameSource {
 public:
  Recorded(std::vector<Frame> frames, DatasetInfo info)
      : frames_(std::move(frames)), info_(std::move(info)) {}
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return frames_.size(); }
  Frame frame(size_t i) override { return frames_.at(i); }
  const Frame& at(size_t i) const { return frames_.at(i); }

 private:
  std::vector<Frame> frames_;
  DatasetInfo info_;
};

// 80 consecutive S2 frames, rendered once.
Recorded s2Frames(const std::string& condition, uint64_t traffic) {
  sim::SimConfig c;
  c.run = sim::Run::S2;
  c.condition = condition;
  c.traffic_seed = traffic;
  c.max_frames = 80;
  sim::Simulator s(c);
  std::vector<Frame> frames;
  for (size_t i = 0; i < s.size(); ++i) frames.push_back(s.frame(i));
  return Recorded(std::move(frames), s.info());
}

// The network of the second argument: -1 none; 0 or R > 0: the MobileNet-class network of
// bench_semantics.cpp (seeded random weights) through Cityscapes' map on every picture, or at
// R pictures a second per camera, in the scan loop; kShippedLive: the project's trained network
// (models/semsegmap-seg.onnx) at its shipped budget on its own thread beside the scans, as on a
// robot; kShippedEvery: the same network on every picture, in the scan loop.
constexpr int64_t kShippedLive = 1000, kShippedEvery = 1001;

std::unique_ptr<FrameLabeler> networkLabeler(int64_t code) {
  if (code < 0) return nullptr;
  const std::string source = SEMSEGMAP_SOURCE_DIR;
  if (code >= kShippedLive) {
    SemanticsConfig c = loadSemanticsConfig(source + "/config/semantics-sim-network.yaml");
    auto network = std::make_shared<SegmentationNetwork>(
        c, readFileBytes(c.model),
        readClassMap(source + "/config/class_maps/semsegmap.yaml", ClassTable::Default()), c.model);
    if (code == kShippedEvery) {
      c.rate_hz = c.budget_cores = c.latency_s = 0;
      return std::make_unique<ReplayLabeler>(c, networkFunction(network));
    }
    return std::make_unique<LiveLabeler>(network, Pose::Identity());
  }
  SemanticsConfig c;
  c.model = std::string(SEMSEGMAP_ONNX_DIR) + "/mobilenet_seg.onnx";
  c.rate_hz = static_cast<double>(code);
  c.tolerance_s = 1.0;
  c.replace_dataset_labels = true;
  auto network = std::make_shared<SegmentationNetwork>(
      c, readFileBytes(c.model),
      readClassMap(source + "/config/class_maps/cityscapes.yaml", ClassTable::Default()), c.model);
  return std::make_unique<ReplayLabeler>(network);
}

std::string networkText(int64_t code) {
  if (code == kShippedLive) return " + the shipped network at its budget, beside the scans";
  if (code == kShippedEvery) return " + the shipped network on every picture";
  return " + network at " + std::to_string(code) + " Hz";
}

// The configuration of arg 0; with the shipped network (arg 1 >= kShippedLive) the ground goes by
// geometry as well, as its file says and as the demo and `eval localization --labels network`
// run it: a network's ground with another class would be segmented.
PipelineConfig wholePipelineConfig(const std::string& name, int64_t network) {
  const std::string source = SEMSEGMAP_SOURCE_DIR;
  PipelineConfig config = loadPipelineConfig(source + "/config/" + name + ".yaml");
  if (network >= kShippedLive)
    config.local_map.geometric_ground_removal =
        loadSettings(source + "/config/semantics-sim-network.yaml")
            .local_map.geometric_ground_removal;
  return config;
}

void BM_WholePipeline(benchmark::State& state) {
  const std::string name = state.range(0) == 0 ? "semsegmap" : "segmap";
  const PipelineConfig config = wholePipelineConfig(name, state.range(1));
  std::shared_ptr<Describer> describer;
  keepFreedMemoryForTorch();  // as the command line does at start-up
  try {
    describer = makeDescriber(config.descriptor);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  static Recorded mapping = s2Frames("sunrise", 11);
  static Recorded query = s2Frames("sunny", 12);
  const auto map = std::make_shared<const TargetMap>(
      runMapping(mapping, config, PoseSource::kGroundTruth, describer).map);
  const std::unique_ptr<FrameLabeler> labeler = networkLabeler(state.range(1));
  std::unique_ptr<LocalizationSession> session;
  size_t i = 0, localized = 0, frames = 0;
  StageTimes total;
  const auto lap = [&] {  // adds up a finished pass over the query frames
    if (!session) return;
    localized += session->run().localizations.size();
    total += session->run().stats.total;
  };
  for (auto _ : state) {
    if (!session || i == query.size()) {
      state.PauseTiming();
      lap();
      session = std::make_unique<LocalizationSession>(config, query.info(), map, describer);
      i = 0;
      state.ResumeTiming();
    }
    if (labeler) {
      Frame f = query.at(i++);
      labeler->label(f, "frame");
      session->process(f);
    } else {
      session->process(query.at(i++));
    }
    ++frames;
  }
  lap();
  state.SetLabel(name + " + " + config.descriptor.kind +
                 (labeler ? networkText(state.range(1)) : "") +
                 (config.local_map.geometric_ground_removal ? ", ground by geometry too" : ""));
  const double n = static_cast<double>(std::max<size_t>(1, frames));
  state.counters["localized"] = static_cast<double>(localized) / n;
  state.counters["enrich_ms"] = total.enrich_ms / n;
  state.counters["map_seg_ms"] = (total.local_map_ms + total.segment_ms) / n;
  state.counters["describe_ms"] = total.describe_ms / n;
  state.counters["localize_ms"] = total.localize_ms / n;
  if (labeler) {
    const LabelingStats l = labeler->stats();
    state.counters["network_ms"] = l.network_ms / n;  // per scan
    state.counters["network_share"] = l.share();
    state.counters["unlabelled"] = static_cast<double>(l.unlabelled) / n;  // pictures per scan
  }
  state.counters["Hz"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
}
// The front end alone (enrich, local map, segmentation; no describing or querying) on the
// same frames, to tell the stages' cost apart from their interference in the whole pipeline.
void BM_PipelineFrontEnd(benchmark::State& state) {
  const PipelineConfig config =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semsegmap.yaml");
  static Recorded query = s2Frames("sunny", 12);
  std::unique_ptr<Pipeline> pipeline;
  size_t i = 0, frames = 0;
  StageTimes total;
  for (auto _ : state) {
    if (!pipeline || i == query.size()) {
      state.PauseTiming();
      pipeline = std::make_unique<Pipeline>(config, query.info(), PoseSource::kOdometry);
      i = 0;
      state.ResumeTiming();
    }
    total += pipeline->process(query.at(i++)).times;
    ++frames;
  }
  const double n = static_cast<double>(std::max<size_t>(1, frames));
  state.counters["enrich_ms"] = total.enrich_ms / n;
  state.counters["map_seg_ms"] = (total.local_map_ms + total.segment_ms) / n;
}
BENCHMARK(BM_PipelineFrontEnd)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(160);

// The live core at a robot's pace ([live]): each S2 frame split into its messages (odometry, the
// scan, each camera's picture 10 ms later) and handed to a LiveSession (queue of 2, dropping) at
// arg 0 Hz of scans, the caller sleeping between them as a driver would. Latency: a scan's
// arrival to its pose (or to its frame's end when it gives none). Target: <= 100 ms at 10 Hz on
// 2 cores, no frame dropped; fed faster than it works it drops, and its queue stays at 2.
void BM_LiveLatency(benchmark::State& state) {
  const PipelineConfig config =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/semsegmap.yaml");
  keepFreedMemoryForTorch();
  const std::shared_ptr<Describer> describer = makeDescriber(config.descriptor);
  static Recorded mapping = s2Frames("sunrise", 11);
  static Recorded query = s2Frames("sunny", 12);
  const auto map = std::make_shared<const TargetMap>(
      runMapping(mapping, config, PoseSource::kGroundTruth, describer).map);
  const auto period = std::chrono::duration<double>(1.0 / static_cast<double>(state.range(0)));
  LiveStats total;
  double latency_sum = 0.0, pipeline_ms = 0.0;
  for (auto _ : state) {  // one pass over the query frames
    LocalizationSession session(config, query.info(), map, describer);
    LiveConfig c;
    c.assembly.cameras = query.info().rig.cameras.size();
    LiveSession live(c, localizingProcess(session));
    auto next = std::chrono::steady_clock::now();
    for (size_t i = 0; i < query.size(); ++i) {
      std::this_thread::sleep_until(next);
      next += std::chrono::duration_cast<std::chrono::steady_clock::duration>(period);
      const Frame& f = query.at(i);
      live.addOdometry({f.timestamp_s, f.T_odom_base});
      live.addScan({f.timestamp_s, f.points, {}});
      for (size_t k = 0; k < f.cameras.size(); ++k)
        live.addPicture(k, {f.timestamp_s + 0.01, f.cameras[k].rgb, f.cameras[k].label});
    }
    live.finish();
    pipeline_ms += session.run().stats.total.total();
    const LiveStats s = live.stats();
    total.processed += s.processed;
    total.dropped += s.dropped;
    total.localized += s.localized;
    total.max_queued = std::max(total.max_queued, s.max_queued);
    total.max_latency_ms = std::max(total.max_latency_ms, s.max_latency_ms);
    latency_sum += s.mean_latency_ms * static_cast<double>(s.processed);
  }
  state.SetLabel("semsegmap at " + std::to_string(state.range(0)) + " Hz of scans");
  state.counters["latency_ms"] =
      latency_sum / static_cast<double>(std::max<size_t>(1, total.processed));
  state.counters["max_latency_ms"] = total.max_latency_ms;
  // The pipeline's own time a frame worked on: the rest of the latency is waiting.
  state.counters["pipeline_ms"] =
      pipeline_ms / static_cast<double>(std::max<size_t>(1, total.processed));
  state.counters["processed"] = static_cast<double>(total.processed);
  state.counters["dropped"] = static_cast<double>(total.dropped);
  state.counters["localized"] = static_cast<double>(total.localized);
  state.counters["max_queued"] = static_cast<double>(total.max_queued);
}
BENCHMARK(BM_LiveLatency)
    ->Arg(10)
    ->Arg(40)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

// The rows whose local map and segmentation time must stay the same beside the network are as
// noisy as the difference (the VM's run-to-run noise is about 15 %): the documented run repeats
// every benchmark (--benchmark_repetitions) and the table takes the fastest repetition.
BENCHMARK(BM_WholePipeline)
    ->Args({0, -1})
    ->Args({0, kShippedLive})
    ->Args({1, -1})
    ->Args({0, 0})
    ->Args({0, 2})
    ->Args({1, kShippedLive})
    ->Args({0, kShippedEvery})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(160);

}  // namespace
