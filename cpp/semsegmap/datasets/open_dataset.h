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
//                          (0|1), sweep (0|1: motion distortion, per-point times),
//                          label_noise (0..3: camera labels as a network's, sim/label_noise.h);
//                          a build
//                          without the simulator (SEMSEGMAP_WITH_SIM=OFF)
//                          says so in one line
#pragma once

#include <filesystem>
#include <memory>
#include <string>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/odometry/lidar_odometry.h"
#include "semsegmap/pipeline/front_end_stages.h"
#include "semsegmap/semantics/segmentation_network.h"

namespace semsegmap {

// What the command line adds to a --dataset SPEC.
struct DatasetOptions {
  std::filesystem::path rig;  // --rig: the rig file of a folder (docs/rig-format.md)
  // --odometry FILE: TUM or KITTI poses of the base; "lidar": LiDAR odometry on the scans.
  std::filesystem::path odometry;
  OdometryConfig lidar_odometry;       // the LiDAR odometry's settings, for --odometry lidar
  std::filesystem::path ground_truth;  // --ground-truth FILE: likewise
  std::filesystem::path kitti_calib;   // --kitti-calib: calib.txt for KITTI camera-0 poses
  // --labels DIR: a label set's images replace the dataset's (datasets/semantic_sources.h).
  std::filesystem::path labels;
  // The config's semantics: section; with a model, the network labels pictures that have none.
  SemanticsConfig semantics;
  std::filesystem::path class_maps_dir;  // the shipped class maps (config/class_maps)
  // The frames the run reads (--max-frames; 0: all): a dataset directory checks their rows and
  // files before any frame is read (io/dataset_reader.h), and no more.
  size_t frames_to_check = 0;
};

// Throws std::runtime_error / std::invalid_argument naming the spec and what was wrong. The
// network (semantics.model) is loaded and checked against the rig's cameras here, before any
// frame is read; it is the outermost step, so that odometry never waits for it.
std::unique_ptr<FrameSource> openDataset(const std::string& spec,
                                         const DatasetOptions& options = {});

// The same dataset for a Pipeline that runs the network and LiDAR odometry itself
// (pipeline/front_end_stages.h): the source without them, and the stages the options ask for,
// the network loaded and checked against the rig's cameras as openDataset does.
struct DatasetWithStages {
  std::unique_ptr<FrameSource> source;
  FrontEndStages stages;
};
DatasetWithStages openDatasetForPipeline(const std::string& spec,
                                         const DatasetOptions& options = {});

}  // namespace semsegmap
