// The rig file (docs/rig-format.md): a robot's own LiDAR and cameras, their lens models and
// extrinsics, and where a folder or a bag keeps each sensor's data. Extrinsics are named by
// direction (T_camera_lidar or T_lidar_camera, T_base_lidar or T_lidar_base), so that a matrix
// cannot be read backwards.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/sensor_rig.h"

namespace semsegmap {

struct RigFile {
  std::string name;  // empty: the dataset names itself
  SensorRig rig;
  // The file did not mount the LiDAR on a base: the base is the LiDAR, and poses read from
  // files are LiDAR poses. Readers say so once.
  bool base_is_lidar = true;
  std::string lidar_topic;                  // for bags; empty: found by type
  std::string lidar_folder;                 // for folders; empty: the dataset folder itself
  std::vector<std::string> camera_topics;   // per camera, for bags
  std::vector<std::string> camera_folders;  // per camera, for folders (default: its name)
};

// Throws std::runtime_error "<file>: <field>: <what was wrong>" for an unknown key, a missing or
// malformed field, both or neither direction of an extrinsic, or a rig that cannot be right
// (SensorRig::validate).
RigFile readRigFile(const std::filesystem::path& path);

}  // namespace semsegmap
