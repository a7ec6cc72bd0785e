// LiDAR odometry over a dataset, as `semsegmap odometry` runs it: the trajectory, each frame's
// diagnostics, the errors against ground truth, and the files (trajectories, summary.json,
// trajectory.png).
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/core/stop_token.h"
#include "semsegmap/eval/odometry_metrics.h"
#include "semsegmap/odometry/lidar_odometry.h"

namespace semsegmap {

struct OdometryRun {
  std::string dataset;
  std::vector<StampedPose> trajectory;  // T_odom_base per frame
  std::vector<OdometryResult> frames;   // the odometry's diagnostics per frame
  std::vector<Pose> ground_truth;       // T_world_base per frame, when every frame has it
  std::vector<FrameStamp> stamps;       // per frame: the data's names (trajectory.csv)
  double seconds = 0.0;                 // in registerFrame only (not reading the data)
  bool interrupted = false;             // the stop request ended it early: `frames` are those done
  // The trajectory's times are the data's; false: made up from the rate
  // (DatasetInfo::has_frame_times), and writeOdometryFiles writes no TUM file.
  bool has_frame_times = true;
};

// Registers the first max_frames frames (0: all) of `source`; progress(done, total) after each.
// `stop` is checked before each frame: once asked, the run ends with the frames done.
OdometryRun runLidarOdometry(FrameSource& source, const OdometryConfig& config, size_t max_frames,
                             const std::function<void(size_t, size_t)>& progress = {},
                             const StopToken& stop = {});

struct OdometryErrors {
  KittiRelativeError kitti;
  TrajectoryError ate;          // estimate moved onto the ground truth at the first pose
  TrajectoryError ate_aligned;  // estimate aligned by the best rigid transform (evo's --align)
};

// Nothing when the run has no ground truth.
std::optional<OdometryErrors> odometryErrors(const OdometryRun& run);

nlohmann::ordered_json toJson(const OdometryRun& run, const std::optional<OdometryErrors>& errors);

// trajectory_tum.txt (only with the data's frame times: a made-up time would pair poses with the
// wrong data), trajectory_kitti.txt, trajectory.csv (frame, dataset_frame, timestamp, odom_*,
// gt_*: outputs/run_output.h), summary.json and, with ground truth, trajectory.png (estimate
// against ground truth, from above) in `out`.
void writeOdometryFiles(const std::filesystem::path& out, const OdometryRun& run);

}  // namespace semsegmap
