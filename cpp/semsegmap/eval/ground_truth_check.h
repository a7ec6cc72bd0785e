// Is a recording's ground truth consistent between its passes? The mapped scans, placed by their
// ground-truth poses, form a reference point cloud; a query scan registered to it from its own
// ground-truth pose lands where the map's geometry says it is. Where a GPS/INS ground truth
// drifts between two passes (KITTI 00's second pass sits about 0.8 m above its first), a
// localization against the map is judged against the registered pose, not the drifted one.
#pragma once

#include <optional>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/odometry/voxel_map.h"

namespace semsegmap {

struct GroundTruthCheckConfig {
  double voxel_size_m = 0.5;       // of the reference map and the downsampled query scan
  double coarse_distance_m = 1.5;  // first registration: correspondences this far
  double fine_distance_m = 0.3;    // then this far
  double max_correction_m = 3.0;   // a registration moving the pose farther has failed
  size_t min_correspondences = 500;
};

class GroundTruthCheck {
 public:
  explicit GroundTruthCheck(const GroundTruthCheckConfig& config = {});
  // A mapped scan: its points (LiDAR frame) at its ground-truth LiDAR pose.
  void addMapped(const std::vector<LidarPoint>& points, const Pose& T_world_lidar);
  // The query scan's LiDAR pose as registered to the mapped scans from `T_world_lidar`, or
  // nothing when too little of it overlaps them or the registration fails.
  std::optional<Pose> registered(const std::vector<LidarPoint>& points,
                                 const Pose& T_world_lidar) const;

 private:
  GroundTruthCheckConfig config_;
  VoxelMap map_;
};

}  // namespace semsegmap
