// The --dataset SPEC of every subcommand, turned into a FrameSource:
//   DIR                    a dataset directory in the project's format (docs/dataset-format.md)
//   kitti-raw:PATH         a KITTI raw drive
//   semantickitti:PATH     a SemanticKITTI sequence
//   nclt:PATH              an NCLT session
//   folder:DIR[,...]       a robot's own scans and pictures (io/folder_reader.h): keys rig,
//                          times, tolerance; also a DIR with scans and no meta.yaml
//   rosbag:PATH[,...]      a ROS 1 .bag, ROS 2 .db3 / .mcap or bag folder (io/rosbag_reader.h)
//   sim:KEY=VALUE,...      the built-in simulator, streamed without touching the disk; keys:
//                          world (seed, default 1), run (S0..S3, default S2), condition,
//                          traffic (seed), frames (maximum), preset (full|small|tiny), cameras
//                          (0|1), sweep (0|1: motion distortion, per-point times); a build
//                          without the simulator (SEMSEGMAP_WITH_SIM=OFF)
//                          says so in one line
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/odometry/lidar_odometry.h"

namespace semsegmap {

// What the command line adds to a --dataset SPEC.
struct DatasetOptions {
  std::filesystem::path rig;  // --rig: the rig file of a folder (docs/rig-format.md)
  // --odometry FILE: TUM or KITTI poses of the base; "lidar": LiDAR odometry on the scans.
  std::filesystem::path odometry;
  OdometryConfig lidar_odometry;       // the LiDAR odometry's settings, for --odometry lidar
  std::filesystem::path ground_truth;  // --ground-truth FILE: likewise
  std::filesystem::path kitti_calib;   // --kitti-calib: calib.txt for KITTI camera-0 poses
};

// Throws std::runtime_error / std::invalid_argument naming the spec and what was wrong.
std::unique_ptr<FrameSource> openDataset(const std::string& spec,
                                         const DatasetOptions& options = {});

}  // namespace semsegmap
