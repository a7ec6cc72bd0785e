#include "semsegmap/datasets/open_dataset.h"

#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/nearest_name.h"
#include "semsegmap/datasets/lidar_odometry_source.h"
#include "semsegmap/datasets/pose_files.h"
#include "semsegmap/datasets/semantic_sources.h"
#include "semsegmap/datasets/spec_guess.h"
#include "semsegmap/io/dataset_reader.h"
#include "semsegmap/io/folder_reader.h"
#if SEMSEGMAP_WITH_ROS
#include "semsegmap/io/rosbag_reader.h"
#endif
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

LidarModel lidarPresetOf(const std::string& spec, const std::string& name) {
  try {
    return lidarPreset(name);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("dataset '" + spec + "': lidar=" + name + ": " + e.what());
  }
}

// cameras=0 or 1 (none or all), or the cameras to keep by name joined by '+': cameras=front.
void parseSimCameras(const std::string& spec, const std::string& value, sim::SimConfig& config) {
  if (value == "0" || value == "1") {
    config.render_cameras = value == "1";
    return;
  }
  std::stringstream names(value);
  for (std::string name; std::getline(names, name, '+');) {
    if (name.empty())
      throw std::invalid_argument("dataset '" + spec + "': cameras=" + value +
                                  ": expected 0, 1 or camera names joined by '+'");
    config.camera_names.push_back(name);
  }
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
      parseSimCameras(spec, value, config);
    else if (key == "lidar")
      config.rig.lidar = lidarPresetOf(spec, value);
    else if (key == "classes")
      config.point_classes = parseUnsigned(spec, key, value) != 0;
    else if (key == "laps") {
      const uint64_t laps = parseUnsigned(spec, key, value);
      if (laps < 1 || laps > 1000)
        throw std::invalid_argument("dataset '" + spec + "': laps is 1 to 1000, got " + value);
      config.trajectory.laps = static_cast<int>(laps);
    } else if (key == "sweep")
      config.lidar_sweep = parseUnsigned(spec, key, value) != 0;
    else if (key == "label_noise") {
      const uint64_t level = parseUnsigned(spec, key, value);
      if (level > sim::kMaxLabelNoiseLevel)
        throw std::invalid_argument("dataset '" + spec + "': label_noise is 0 (perfect) to " +
                                    std::to_string(sim::kMaxLabelNoiseLevel) + ", got " + value);
      config.label_noise = static_cast<int>(level);
    } else
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

namespace {

std::unique_ptr<FrameSource> openFolder(const std::string& spec, const std::string& args,
                                        const DatasetOptions& options) {
  FolderOptions folder;
  folder.rig = options.rig;
  const std::filesystem::path dir = parseFolderSpec(spec, args, folder);
  return std::make_unique<FolderReader>(dir, folder);
}

#if SEMSEGMAP_WITH_ROS
// rosbag:PATH[,key=value...]: the bag file or folder, then the reader's options.
std::unique_ptr<FrameSource> openRosbag(const std::string& spec, const std::string& args) {
  const auto comma = args.find(',');
  const std::string path = args.substr(0, comma);
  if (path.empty()) throw std::invalid_argument("dataset '" + spec + "': no bag after rosbag:");
  RosbagOptions options;
  try {
    if (comma != std::string::npos) options = parseRosbagOptions(args.substr(comma + 1));
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("dataset '" + spec + "': " + e.what());
  }
  return std::make_unique<RosbagReader>(path, options);
}
#else
std::unique_ptr<FrameSource> openRosbag(const std::string& spec, const std::string&) {
  throw std::runtime_error("dataset '" + spec +
                           "': this build reads no ROS bags (reconfigure with "
                           "-DSEMSEGMAP_WITH_ROS=ON)");
}
#endif

std::invalid_argument unknownKind(const std::string& spec, const std::string& kind) {
  const std::string nearest =
      nearestName(kind, {"kitti-raw", "semantickitti", "nclt", "sim", "folder", "rosbag"});
  return std::invalid_argument(
      "dataset '" + spec + "': unknown kind '" + kind + "' " +
      (nearest.empty()
           ? "(expected kitti-raw:, semantickitti:, nclt:, sim:, folder:, rosbag: or a directory)"
           : "(did you mean " + nearest + ":?)"));
}

// A spec without a kind that is no dataset directory: what it looks like and what to write
// instead, when that can be told cheaply (datasets/spec_guess.h).
std::runtime_error notADatasetDirectory(const std::string& spec) {
  if (const auto guess = guessDatasetSpec(spec)) {
    const bool folder = std::filesystem::is_directory(spec);
    return std::runtime_error(spec + ": " + guess->what + ", not a dataset directory" +
                              (folder ? " of the project's format" : "") + ": write " +
                              guess->spec);
  }
  if (std::filesystem::exists(spec))
    return std::runtime_error(
        spec +
        ": a file, not a dataset directory (a dataset is a directory, or "
        "KIND:PATH with kitti-raw:, semantickitti:, nclt:, folder:, rosbag:)");
  return std::runtime_error(spec + ": no such dataset directory");
}

std::unique_ptr<FrameSource> openSource(const std::string& spec, const DatasetOptions& options) {
  const auto colon = spec.find(':');
  if (colon != std::string::npos) {
    const std::string kind = spec.substr(0, colon), rest = spec.substr(colon + 1);
    if (kind == "kitti-raw") return std::make_unique<KittiRawReader>(rest);
    if (kind == "semantickitti") return std::make_unique<SemanticKittiReader>(rest);
    if (kind == "nclt") return std::make_unique<NcltReader>(rest);
    if (kind == "sim") return openSimulator(spec, rest);
    if (kind == "folder") return openFolder(spec, rest, options);
    if (kind == "rosbag") return openRosbag(spec, rest);
    // Anything else with a colon may still be a directory name.
    if (!std::filesystem::exists(spec)) throw unknownKind(spec, kind);
  }
  if (!std::filesystem::is_directory(spec)) throw notADatasetDirectory(spec);
  if (!std::filesystem::exists(std::filesystem::path(spec) / "meta.yaml")) {
    // A KITTI raw drive, a bag folder...: read as a folder of scans it would fail on no scans.
    if (guessDatasetSpec(spec)) throw notADatasetDirectory(spec);
    note(spec + " has no meta.yaml: reading it as folder:" + spec);
    return openFolder("folder:" + spec, spec, options);
  }
  return std::make_unique<DatasetReader>(spec, options.frames_to_check);
}

}  // namespace

namespace {

// The dataset as read, with its pose files, label set and rig checked; without the stages a
// pipeline may own (LiDAR odometry, the network).
std::unique_ptr<FrameSource> openRead(const std::string& spec, const DatasetOptions& options) {
  auto source = openSource(spec, options);
  if (!options.rig.empty() && dynamic_cast<FolderReader*>(source.get()) == nullptr)
    throw std::invalid_argument(optionText("rig", "FILE") + ": dataset '" + spec +
                                "' brings its own calibration; a rig file is for folder: datasets");
  const bool lidar_odometry = options.odometry == "lidar";
  PoseFileOptions poses;
  if (!lidar_odometry) poses.odometry = options.odometry;
  poses.ground_truth = options.ground_truth;
  poses.kitti_calib = options.kitti_calib;
  source = withPoseFiles(std::move(source), poses);
  if (!lidar_odometry && source->info().odometry_is_ground_truth)
    note(source->info().name + ": its ground-truth poses serve as its odometry too (" +
         optionText("odometry", "FILE") + " or " + optionText("odometry", "lidar", true) +
         " for odometry of its own): errors measured against them are marked so");
  if (!options.labels.empty())
    source = withLabelSet(std::move(source), options.labels, options.class_maps_dir,
                          options.frames_to_check);
  return source;
}

}  // namespace

std::unique_ptr<FrameSource> openDataset(const std::string& spec, const DatasetOptions& options) {
  DatasetWithStages d = openDatasetForPipeline(spec, options);
  if (d.stages.lidar_odometry)
    d.source = withLidarOdometry(std::move(d.source), *d.stages.lidar_odometry);
  if (!d.stages.network) return std::move(d.source);
  return withSegmentationNetwork(std::move(d.source), std::move(d.stages.network));
}

DatasetWithStages openDatasetForPipeline(const std::string& spec, const DatasetOptions& options) {
  DatasetWithStages d;
  d.source = openRead(spec, options);
  if (options.odometry == "lidar") d.stages.lidar_odometry = options.lidar_odometry;
  if (!options.semantics.model.empty())
    d.stages.network =
        loadSegmentationNetwork(options.semantics, d.source->info(), options.class_maps_dir);
  return d;
}

}  // namespace semsegmap
