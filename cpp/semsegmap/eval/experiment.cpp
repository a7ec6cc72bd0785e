#include "semsegmap/eval/experiment.h"

#include <cstdio>
#include <stdexcept>

#include "semsegmap/settings/config.h"

namespace semsegmap {

NamedConfig loadNamedConfig(const std::filesystem::path& path) {
  return {path.stem().string(), path, loadPipelineConfig(path.string())};
}

std::string simulatedRunSpec(uint64_t world_seed, const std::string& run, const std::string& preset,
                             size_t max_frames, int label_noise, const std::string& rig) {
  std::string spec =
      "sim:world=" + std::to_string(world_seed) + ",run=" + run + ",preset=" + preset;
  if (max_frames > 0) spec += ",frames=" + std::to_string(max_frames);
  if (label_noise > 0) spec += ",label_noise=" + std::to_string(label_noise);
  if (!rig.empty()) spec += "," + rig;
  return spec;
}

bool forEachFrame(FrameSource& source, const std::string& stage, const ExperimentProgress& progress,
                  const StopToken& stop, const std::function<void(const Frame&)>& use) {
  const size_t n = source.size();
  for (size_t i = 0; i < n; ++i) {
    if (stop.stopRequested()) return false;
    const Frame frame = source.frame(i);
    if (frame.index != i)
      throw std::logic_error(source.info().name +
                             ": the experiments expect frames numbered from 0");
    use(frame);
    if (progress) progress(stage, i + 1, n);
  }
  return true;
}

std::string partialNote() {
  return "\nPartial: interrupted (Ctrl-C) before the end; these numbers cover only the frames "
         "done.\n";
}

std::string countText(const std::optional<size_t>& n) {
  return n ? std::to_string(*n) : "-";
}

std::string meanErrorText(const std::optional<double>& translation_m,
                          const std::optional<double>& rotation_deg) {
  if (!translation_m || !rotation_deg) return "-";
  char text[64];
  std::snprintf(text, sizeof(text), "%.2f m / %.2f°", *translation_m, *rotation_deg);
  return text;
}

}  // namespace semsegmap
