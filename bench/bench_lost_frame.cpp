// A lost frame, whole: a robot woken up with one scan finds itself against a map it did not see
// being built, as `eval revisits --wake-up` and the node's start-up do. Timed, per scan: the
// front end (enrichment, local map, segmentation), describing every segment with the shipped
// real-data model, the local map's own try, the relocalization's places and scan context, and
// the registration check of each place proposed (LocalizationSession::relocalize).
// The map: frames 0-700 of S1 in world 21 with the HDL-64E rig and config/lidar-camera.yaml as
// it ships (512 points a segment, a scan context a metre), built once, untimed (about two
// minutes); the scans: every 25th of 701-1300, where S1 drives its first street again, half of
// them revisits, as docs/real-data.md's wake-up table. Target on 2 cores: <= 150 ms a lost frame.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/frame_subset.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/describe/learned_describer.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/settings/config.h"

using namespace semsegmap;

namespace {

struct WakeUps {
  PipelineConfig config;
  DatasetInfo info;
  std::shared_ptr<Describer> describer;
  std::shared_ptr<const TargetMap> map;
  std::vector<Frame> scans;
};

const WakeUps& wakeUps() {
  static const WakeUps w = [] {
    WakeUps out;
    out.config =
        loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/lidar-camera.yaml");
    keepFreedMemoryForTorch();  // as the command line does at start-up
    out.describer = makeDescriber(out.config.descriptor);
    const std::unique_ptr<FrameSource> run = openDataset("sim:world=21,run=S1,lidar=hdl64");
    out.info = run->info();
    std::vector<size_t> mapped(701);
    for (size_t i = 0; i < mapped.size(); ++i) mapped[i] = i;
    FrameSubset mapping(*run, mapped);
    out.map = std::make_shared<const TargetMap>(
        runMapping(mapping, out.config, PoseSource::kGroundTruth, out.describer).map);
    for (size_t i = 701; i <= 1300; i += 25) out.scans.push_back(run->frame(i));
    return out;
  }();
  return w;
}

void BM_LostFrame(benchmark::State& state) {
  const WakeUps* w = nullptr;
  try {
    w = &wakeUps();
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  const LocalizationSession session(w->config, w->info, w->map, w->describer);
  size_t i = 0, tries = 0, localized = 0, wrong = 0;
  for (auto _ : state) {
    const Frame& scan = w->scans[i++ % w->scans.size()];
    const std::optional<LocalizationRecord> r = session.relocalize(scan);
    ++tries;
    if (r && r->translation_error_m > 5.0) ++wrong;
    if (r && r->translation_error_m <= 1.0) ++localized;
  }
  const double n = static_cast<double>(std::max<size_t>(1, tries));
  state.counters["localized"] = static_cast<double>(localized) / n;
  state.counters["wrong"] = static_cast<double>(wrong) / n;
  state.counters["scans"] = static_cast<double>(w->scans.size());
}
// Each of the 24 scans twice.
BENCHMARK(BM_LostFrame)->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(48);

}  // namespace
