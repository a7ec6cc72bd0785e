// The long-run memory check of the README: builds a target map from one run, then localizes a
// long run against it (the simulator's S2 driven many laps: `sim:world=1,run=S2,laps=46` is
// 18 286 scans, half an hour at 10 Hz) and samples the resident set size as the frames go by. A
// robot localizes for hours: whatever the live core keeps per frame shows here as a slope.
//
//   semsegmap_memory_run CONFIG MAP_SPEC QUERY_SPEC OUT_DIR [EVERY_N_FRAMES]
//
// Writes OUT_DIR/rss.csv (phase, frame, distance_m, rss_mb), OUT_DIR/rss.png and prints the
// RSS at the first kilometre, the largest after it and the growth between them.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/describe/learned_describer.h"
#include "semsegmap/pipeline/input_modalities.h"
#include "semsegmap/pipeline/live_session.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/viz/plot.h"

using namespace semsegmap;

namespace {

// The resident set size now (not the peak, which getrusage gives): /proc/self/statm's second
// field, in pages.
double residentMegabytes() {
  std::ifstream statm("/proc/self/statm");
  size_t pages_total = 0, pages_resident = 0;
  if (!(statm >> pages_total >> pages_resident))
    throw std::runtime_error("/proc/self/statm: cannot read the resident set size");
  return static_cast<double>(pages_resident) * static_cast<double>(sysconf(_SC_PAGESIZE)) / 1e6;
}

// The largest resident set size of the process so far (getrusage: KiB on Linux), in the MB
// (10^6 bytes) of residentMegabytes.
double peakResidentMegabytes() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) * 1024.0 / 1e6;
}

struct Sample {
  std::string phase;
  size_t frame = 0;
  double distance_m = 0.0, rss_mb = 0.0;
};

// Forwards a source's frames and samples the RSS every `every` frames, with the distance driven
// by ground truth (the long run has it; odometry would do as well).
class MeteredSource : public FrameSource {
 public:
  MeteredSource(FrameSource& source, std::string phase, size_t every, std::vector<Sample>& out)
      : source_(source), phase_(std::move(phase)), every_(every), out_(out) {}
  const DatasetInfo& info() const override { return source_.info(); }
  size_t size() const override { return source_.size(); }
  double frameTime(size_t index) override { return source_.frameTime(index); }
  Frame frame(size_t index) override {
    Frame f = source_.frame(index);
    if (!f.T_world_base)
      throw std::runtime_error(info().name + ": the memory run needs ground-truth poses");
    if (last_) distance_ += (f.T_world_base->translation() - last_->translation()).norm();
    last_ = f.T_world_base;
    // Sampled before the pipeline sees this frame: the memory of the frames before it.
    if (index % every_ == 0) out_.push_back({phase_, index, distance_, residentMegabytes()});
    return f;
  }

 private:
  FrameSource& source_;
  std::string phase_;
  size_t every_;
  std::vector<Sample>& out_;
  std::optional<Pose> last_;
  double distance_ = 0.0;
};

void writeSamples(const std::filesystem::path& out, const std::vector<Sample>& samples) {
  std::ostringstream csv;
  csv << "phase,frame,distance_m,rss_mb\n";
  for (const Sample& s : samples)
    csv << s.phase << "," << s.frame << "," << s.distance_m << "," << s.rss_mb << "\n";
  writeBytesAtomically(out / "rss.csv", csv.str());
  viz::Panel panel{"resident memory while localizing", "distance driven (km)", "RSS (MB)", {}};
  panel.auto_y = true;
  for (const std::string phase : {"map", "localize"}) {
    viz::Series series{phase == "map" ? "building the map" : "localizing against it", {}, {}, {}};
    for (const Sample& s : samples)
      if (s.phase == phase) {
        series.x.push_back(s.distance_m / 1000.0);
        series.y.push_back(s.rss_mb);
      }
    if (!series.x.empty()) panel.series.push_back(series);
  }
  viz::plotPanels(out / "rss.png", "semsegmap: memory over a long run", {panel});
}

// RSS at the first kilometre of localizing, the largest after it, and the growth in percent.
void printGrowth(const std::vector<Sample>& samples) {
  double at_1km = -1.0, largest = 0.0, last_km = 0.0;
  for (const Sample& s : samples) {
    if (s.phase != "localize") continue;
    if (s.distance_m >= 1000.0 && at_1km < 0) at_1km = s.rss_mb;
    if (at_1km >= 0) largest = std::max(largest, s.rss_mb);
    last_km = s.distance_m / 1000.0;
  }
  if (at_1km < 0) {
    std::printf("localized %.2f km: too short to measure growth after the first kilometre\n",
                last_km);
    return;
  }
  std::printf("localized %.2f km: RSS %.0f MB at 1 km, at most %.0f MB after it (%+.1f %%)\n",
              last_km, at_1km, largest, 100.0 * (largest - at_1km) / at_1km);
}

int run(int argc, char** argv) {
  if (argc < 5 || argc > 6) {
    std::cerr << "usage: semsegmap_memory_run CONFIG MAP_SPEC QUERY_SPEC OUT_DIR [EVERY]\n";
    return 2;
  }
  const PipelineConfig config = loadPipelineConfig(argv[1]);
  const std::filesystem::path out = argv[4];
  const size_t every = argc == 6 ? std::max(1, std::stoi(argv[5])) : 50;
  std::filesystem::create_directories(out);
  auto map_source = openDataset(argv[2]);
  auto query_source = openDataset(argv[3]);
  const DescriptorChoice choice =
      chooseDescriptor(config.descriptor, inputModalitiesOf(query_source->info()));
  std::shared_ptr<Describer> describer = makeDescriber(choice.descriptor);
  std::vector<Sample> samples;
  MeteredSource metered_map(*map_source, "map", every, samples);
  auto map = std::make_shared<const TargetMap>(
      runMapping(metered_map, config, PoseSource::kGroundTruth, describer).map);
  std::printf("map: %zu segments, RSS %.0f MB\n", map->size(), residentMegabytes());
  MeteredSource metered_query(*query_source, "localize", every, samples);
  // As the ROS node localizes: through the live core, the poses handed out and not kept
  // (keepHistory(false)); a run's records would grow with it by design. Never dropping, so
  // that every frame is worked on.
  LocalizationSession session(config, metered_query.info(), map, describer);
  session.keepHistory(false);
  LiveConfig live_config;
  live_config.never_drop = true;
  LiveSession live(live_config, localizingProcess(session));
  size_t localizations = 0;
  const size_t frames = metered_query.size();
  for (size_t i = 0; i < frames; ++i) {
    live.addFrame(metered_query.frame(i));
    localizations += live.poll().size();
    if ((i + 1) % 1000 == 0 || i + 1 == frames)
      std::fprintf(stderr, "localize %zu/%zu  RSS %.0f MB\n", i + 1, frames, residentMegabytes());
  }
  live.finish();
  localizations += live.poll().size();
  std::printf("localize: %zu frames, %zu localizations, %.2f km by odometry\n",
              session.run().stats.frames, localizations, session.run().distance_m / 1000.0);
  writeSamples(out, samples);
  printGrowth(samples);
  std::printf("peak RSS of the whole run (simulator, map, localization): %.0f MB\n",
              peakResidentMegabytes());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  semsegmap::keepFreedMemoryForTorch();  // as the command line does
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "semsegmap_memory_run: error: " << e.what() << "\n";
    return 1;
  }
}
