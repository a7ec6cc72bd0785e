// LiDAR odometry: each scan is registered to a local map of voxels around the robot, after the
// design of kiss-icp (Vizzo et al. 2023): a voxel-downsampled scan, a constant-velocity
// prediction, a correspondence threshold that adapts to how far reality strays from that
// prediction, and ICP with a robust kernel. Points with per-point times are deskewed first (the
// robot moves while a spinning LiDAR sweeps). The poses are those of the LiDAR in the odometry
// frame, which is the LiDAR's pose at the first scan.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/odometry/adaptive_threshold.h"
#include "semsegmap/odometry/icp.h"
#include "semsegmap/odometry/voxel_map.h"

namespace semsegmap {

struct OdometryConfig {
  // The local map's voxel edge; the scan is kept at half of it for the map and at 1.5 times it
  // for registration (fewer, well-spread points). 1 m suits 100 m LiDARs (kiss-icp: range / 100).
  double voxel_size_m = 1.0;
  double max_range_m = 100.0;  // farther points are dropped, and the map is cropped at this
  double min_range_m = 1.0;    // nearer points are dropped (the robot itself)
  int max_points_per_voxel = 20;
  // The correspondence threshold before enough motion has been seen to adapt it, and the motion
  // a frame must show to count as a sample of the prediction's error.
  double initial_threshold_m = 2.0;
  double min_motion_m = 0.1;
  // The correspondence threshold never drops below this: a hard turn the prediction missed by a
  // few degrees moves far points by more than a smooth drive's threshold, and ICP could not pull
  // the pose in (the robust kernel still narrows to the adaptive scale, icp.h).
  double min_threshold_m = 1.5;
  bool deskew = true;  // when the scan has per-point times
  IcpConfig icp;
  // Fewer registration points than this and the frame is not registered: the prediction is used.
  int min_points = 50;
};

// Why a frame's pose is the prediction rather than a registration result.
enum class OdometryFallback {
  kNone,           // registered
  kFirstFrame,     // the map was empty: the first scan defines the odometry frame
  kTooFewPoints,   // after range and NaN filtering the scan had fewer than min_points
  kTooFewMatches,  // ICP found fewer correspondences than IcpConfig::min_correspondences
  kNotFinite,      // the solution was not finite (never expected; checked all the same)
};
const char* fallbackName(OdometryFallback fallback);

struct OdometryResult {
  Pose T_odom_lidar = Pose::Identity();  // at the frame's timestamp
  OdometryFallback fallback = OdometryFallback::kNone;
  int iterations = 0;
  size_t correspondences = 0;
  size_t input_points = 0;
  size_t skipped_nonfinite = 0;  // input points with a NaN or infinite coordinate, ignored
  size_t registration_points = 0;
  // Directions of the 6-DoF motion the scan does not constrain (a straight corridor has one):
  // along them the pose keeps the prediction.
  int degenerate_directions = 0;
  bool deskewed = false;
  double threshold_m = 0.0;  // the correspondence threshold used
  size_t map_voxels = 0;
  bool usedPrediction() const { return fallback != OdometryFallback::kNone; }
};

// The usable points of a scan: finite, within the range limits; with their times when the scan
// has one per point.
struct FilteredScan {
  std::vector<Eigen::Vector3d> points;
  std::vector<double> times;
  size_t nonfinite = 0;
};

// The base's pose in its odometry frame (the base at the first scan) from the LiDAR's in its
// own (the LiDAR at the first scan): T_odom_base = T_base_lidar * T_odom_lidar * T_base_lidar^-1.
inline Pose baseOdometryFromLidar(const Pose& T_odom_lidar, const Pose& T_base_lidar) {
  return T_base_lidar * T_odom_lidar * T_base_lidar.inverse();
}

class LidarOdometry {
 public:
  explicit LidarOdometry(const OdometryConfig& config = {});

  // Registers one scan (points in the LiDAR frame; point_times empty or one per point, seconds
  // after timestamp_s) and returns the LiDAR's pose at timestamp_s. Never throws on bad data:
  // a scan it cannot register continues the prediction and says why.
  OdometryResult registerFrame(const std::vector<LidarPoint>& points,
                               const std::vector<float>& point_times, double timestamp_s);

  Pose pose() const { return poses_.empty() ? Pose::Identity() : poses_.back(); }
  const std::vector<Pose>& poses() const { return poses_; }
  const VoxelMap& map() const { return map_; }
  const OdometryConfig& config() const { return config_; }

 private:
  // The motion of the last frame, scaled to the time since it (constant velocity).
  Pose predictedDelta(double timestamp_s) const;
  // A scan made ready for registration: deskewed by `motion` over `dt` when given, downsampled
  // for the map (frame) and for registration (source).
  struct Prepared {
    std::vector<Eigen::Vector3d> points, frame, source;
  };
  Prepared prepare(const FilteredScan& scan, const Pose* motion, double dt) const;
  IcpResult align(const std::vector<Eigen::Vector3d>& source, const Pose& initial, double sigma,
                  OdometryResult& result) const;
  void rebuildFirstFrame(const Pose& motion, double dt);
  // Stores the frame's pose and adds its points (sensor frame) to the map: the downsampled
  // ones as map points, all of them to the voxels' planes.
  OdometryResult finishFrame(OdometryResult& result, const Pose& T, double timestamp_s,
                             const std::vector<Eigen::Vector3d>& frame,
                             const std::vector<Eigen::Vector3d>& all_points);

  OdometryConfig config_;
  VoxelMap map_;
  AdaptiveThreshold threshold_;
  std::vector<Pose> poses_;
  std::vector<double> timestamps_;
  std::optional<FilteredScan> first_scan_;  // kept until the second frame can deskew it
};

}  // namespace semsegmap
