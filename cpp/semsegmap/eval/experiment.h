// What the paper's experiments (eval/*_experiment.h) share: the configurations they compare,
// named after their files, the simulated runs they read, and how they report progress.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/core/stop_token.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap {

struct NamedConfig {
  std::string name;  // the file's stem: "semsegmap", "segmap"
  std::filesystem::path path;
  PipelineConfig config;
};
NamedConfig loadNamedConfig(const std::filesystem::path& path);

// "sim:world=N,run=R,preset=P[,frames=F][,label_noise=L][,RIG]": the dataset spec of a
// simulated run; `rig` holds more simulator keys ("lidar=hdl64,cameras=front").
std::string simulatedRunSpec(uint64_t world_seed, const std::string& run, const std::string& preset,
                             size_t max_frames = 0, int label_noise = 0,
                             const std::string& rig = "");

// Called as work advances: a stage name (e.g. "map S0") and how far it is.
using ExperimentProgress = std::function<void(const std::string& stage, size_t done, size_t total)>;

// Renders (reads) every frame of `source` once and hands it to `use`, which feeds it to every
// configuration compared; reports progress as `stage`. The experiments index their per-frame
// records by frame number, so frames must come numbered from 0 in order (throws otherwise).
// `stop` is checked before each frame, so a frame started is always finished: true when every
// frame was used, false when the stop request ended the loop early (the experiment then reports
// the frames done, marked interrupted).
bool forEachFrame(FrameSource& source, const std::string& stage, const ExperimentProgress& progress,
                  const StopToken& stop, const std::function<void(const Frame&)>& use);

// The line a results table of an interrupted experiment ends with: its numbers are partial.
std::string partialNote();

// What a results table shows for a count or a mean error the run does not know (no ground
// truth, no localization): "-", never a zero that would read as a measurement.
std::string countText(const std::optional<size_t>& n);
// "0.32 m / 1.19°", or "-".
std::string meanErrorText(const std::optional<double>& translation_m,
                          const std::optional<double>& rotation_deg);
inline std::string meanErrorText(const LocalizationSummary& s) {
  return meanErrorText(s.mean_translation_error_m, s.mean_rotation_error_deg);
}

}  // namespace semsegmap
