// Is a recording's ground truth consistent between its passes? The mapped scans, placed by their
// ground-truth poses, form a reference point cloud; a query scan registered to it from its own
// ground-truth pose lands where the map's geometry says it is. Where a GPS/INS ground truth
// drifts between two passes (KITTI 00's second pass sits about 0.8 m above its first), a
// localization against the map is judged against the registered pose, not the drifted one.
// The query is registered to the mapped scans nearest it, the nearest first: the ground truth of
// mapped scans far apart disagrees too, the reference keeps each voxel's first points, and the
// localization matches the segments where the robot is (KITTI 00's scan 1576 registers 1.6 deg
// apart in yaw to mapped scan 95, 13 m away, and to scans 120 and 129, 5 and 1.5 m away; with the
// 24 mapped scans added in recording order it lands where scan 95 puts it).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/odometry/voxel_map.h"

namespace semsegmap {

struct GroundTruthCheckConfig {
  double voxel_size_m = 0.5;       // of the reference map and the downsampled query scan
  double coarse_distance_m = 1.5;  // coarse registration: correspondences this far
  double fine_distance_m = 0.3;    // then this far
  double max_correction_m = 3.0;   // a registration moving the pose farther has failed
  // For a pose off by more than the coarse registration reaches: a voxel map finds a point's
  // correspondence among the voxels around it alone, about one voxel away, so the coarse pass
  // covers about voxel_size_m whatever coarse_distance_m says. Above 0, a first registration to
  // a reference of voxels this large, with correspondences this far, comes before it (Scan
  // Context's matches start metres from the query: eval/scan_context_localizer.h).
  double initial_distance_m = 0.0;
  size_t min_correspondences = 500;
  // The reference of a query: every mapped scan within place_m of it, but at least the
  // nearest_scans nearest and at most max_scans, all within near_m (with none that near, the
  // query is not registered: too little of it overlaps the map to judge by). A query next to
  // one or two mapped scans of the same LiDAR would otherwise snap to their scan pattern (on the
  // simulator, onto the mapped scan's pose), so where the map is dense it takes them all.
  double place_m = 10.0;
  size_t nearest_scans = 2;
  size_t max_scans = 20;
  double near_m = 25.0;
};

class GroundTruthCheck {
 public:
  explicit GroundTruthCheck(const GroundTruthCheckConfig& config = {});
  // A mapped scan: its points (LiDAR frame) at its ground-truth LiDAR pose.
  void addMapped(const std::vector<LidarPoint>& points, const Pose& T_world_lidar);
  // The query scan's LiDAR pose as registered to the mapped scans nearest `T_world_lidar` from
  // it, or nothing when too little of it overlaps them or the registration fails.
  std::optional<Pose> registered(const std::vector<LidarPoint>& points,
                                 const Pose& T_world_lidar) const;
  uint64_t bytes() const;  // of the mapped scans' points it keeps

 private:
  // A mapped scan in the world frame, downsampled to a quarter of the reference map's voxels
  // (enough points for each voxel's plane; about 0.5 MB for a 120k-point HDL-64E scan).
  struct MappedScan {
    Eigen::Vector3d position;
    std::vector<Eigen::Vector3f> points;
  };
  // The mapped scans a query at `position` registers to, the nearest first.
  std::vector<size_t> scansNear(const Eigen::Vector3d& position) const;
  VoxelMap reference(const std::vector<size_t>& scans, double voxel_size_m) const;

  GroundTruthCheckConfig config_;
  std::vector<MappedScan> scans_;
};

}  // namespace semsegmap
