#include "semsegmap/eval/experiment.h"

#include "semsegmap/io/config.h"

namespace semsegmap {

NamedConfig loadNamedConfig(const std::filesystem::path& path) {
  return {path.stem().string(), path, loadPipelineConfig(path.string())};
}

std::string simulatedRunSpec(uint64_t world_seed, const std::string& run, const std::string& preset,
                             size_t max_frames) {
  std::string spec =
      "sim:world=" + std::to_string(world_seed) + ",run=" + run + ",preset=" + preset;
  if (max_frames > 0) spec += ",frames=" + std::to_string(max_frames);
  return spec;
}

}  // namespace semsegmap
