#include "semsegmap/datasets/open_dataset.h"

#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "semsegmap/io/dataset_reader.h"
#include "semsegmap/io/kitti_raw_reader.h"
#include "semsegmap/io/nclt_reader.h"
#include "semsegmap/io/semantic_kitti_reader.h"
#if SEMSEGMAP_WITH_SIM
#include "semsegmap/sim/simulator.h"
#endif

namespace semsegmap {

namespace {

#if SEMSEGMAP_WITH_SIM
uint64_t parseUnsigned(const std::string& spec, const std::string& key, const std::string& value) {
  size_t used = 0;
  unsigned long long v = 0;
  try {
    v = std::stoull(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != value.size())
    throw std::invalid_argument("dataset '" + spec + "': " + key + " expects a number, got '" +
                                value + "'");
  return v;
}

std::unique_ptr<FrameSource> openSimulator(const std::string& spec, const std::string& args) {
  std::string preset = "full";
  uint64_t world_seed = 1;
  sim::SimConfig config;
  std::stringstream ss(args);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    const auto eq = item.find('=');
    if (eq == std::string::npos)
      throw std::invalid_argument("dataset '" + spec + "': expected key=value, got '" + item + "'");
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    if (key == "world")
      world_seed = parseUnsigned(spec, key, value);
    else if (key == "run")
      config.run = sim::parseRun(value);
    else if (key == "condition")
      config.condition = value;
    else if (key == "traffic")
      config.traffic_seed = parseUnsigned(spec, key, value);
    else if (key == "frames")
      config.max_frames = parseUnsigned(spec, key, value);
    else if (key == "preset")
      preset = value;
    else if (key == "cameras")
      config.render_cameras = parseUnsigned(spec, key, value) != 0;
    else
      throw std::invalid_argument("dataset '" + spec + "': unknown key '" + key + "'");
  }
  config.world = sim::worldPreset(preset, world_seed);
  return std::make_unique<sim::Simulator>(config);
}
#else
std::unique_ptr<FrameSource> openSimulator(const std::string& spec, const std::string&) {
  throw std::runtime_error("dataset '" + spec +
                           "': this build has no simulator (built without Embree, reconfigure "
                           "with -DSEMSEGMAP_WITH_SIM=ON)");
}
#endif

}  // namespace

std::unique_ptr<FrameSource> openDataset(const std::string& spec) {
  const auto colon = spec.find(':');
  if (colon != std::string::npos) {
    const std::string kind = spec.substr(0, colon), rest = spec.substr(colon + 1);
    if (kind == "kitti-raw") return std::make_unique<KittiRawReader>(rest);
    if (kind == "semantickitti") return std::make_unique<SemanticKittiReader>(rest);
    if (kind == "nclt") return std::make_unique<NcltReader>(rest);
    if (kind == "sim") return openSimulator(spec, rest);
    // Anything else with a colon may still be a directory name.
    if (!std::filesystem::exists(spec))
      throw std::invalid_argument(
          "dataset '" + spec + "': unknown kind '" + kind +
          "' (expected kitti-raw:, semantickitti:, nclt:, sim: or a directory)");
  }
  if (!std::filesystem::is_directory(spec))
    throw std::runtime_error(spec + ": no such dataset directory");
  return std::make_unique<DatasetReader>(spec);
}

}  // namespace semsegmap
