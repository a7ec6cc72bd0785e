#include "semsegmap/eval/ground_truth_check.h"

#include "semsegmap/odometry/icp.h"

namespace semsegmap {

namespace {

std::vector<Eigen::Vector3d> toVectors(const std::vector<LidarPoint>& points, const Pose& T) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const LidarPoint& p : points) out.push_back(T * Eigen::Vector3d(p.x, p.y, p.z));
  return out;
}

}  // namespace

GroundTruthCheck::GroundTruthCheck(const GroundTruthCheckConfig& config)
    : config_(config), map_(config.voxel_size_m, 20) {}

void GroundTruthCheck::addMapped(const std::vector<LidarPoint>& points, const Pose& T_world_lidar) {
  const std::vector<Eigen::Vector3d> world = toVectors(points, T_world_lidar);
  map_.add(voxelDownsample(world, 0.5 * config_.voxel_size_m), world);
}

std::optional<Pose> GroundTruthCheck::registered(const std::vector<LidarPoint>& points,
                                                 const Pose& T_world_lidar) const {
  if (map_.empty()) return std::nullopt;
  const std::vector<Eigen::Vector3d> scan =
      voxelDownsample(toVectors(points, Pose::Identity()), config_.voxel_size_m);
  IcpConfig icp;
  icp.min_correspondences = config_.min_correspondences;
  // Coarse then fine, as the pose refinement does: the kernel a third of the reach.
  IcpResult r = alignToMap(scan, map_, T_world_lidar, config_.coarse_distance_m,
                           config_.coarse_distance_m / 3, icp);
  if (!r.enough_correspondences) return std::nullopt;
  r = alignToMap(scan, map_, r.T, config_.fine_distance_m, config_.fine_distance_m / 3, icp);
  if (!r.enough_correspondences) return std::nullopt;
  if ((r.T.translation() - T_world_lidar.translation()).norm() > config_.max_correction_m)
    return std::nullopt;
  return r.T;
}

}  // namespace semsegmap
