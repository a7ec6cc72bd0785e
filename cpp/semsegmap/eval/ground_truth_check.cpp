#include "semsegmap/eval/ground_truth_check.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

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

GroundTruthCheck::GroundTruthCheck(const GroundTruthCheckConfig& config) : config_(config) {
  if (config.nearest_scans == 0 || config.max_scans < config.nearest_scans)
    throw std::invalid_argument(
        "ground-truth check: need 1 <= nearest_scans <= max_scans mapped scans a query");
}

void GroundTruthCheck::addMapped(const std::vector<LidarPoint>& points, const Pose& T_world_lidar) {
  MappedScan scan;
  scan.position = T_world_lidar.translation();
  for (const Eigen::Vector3d& p :
       voxelDownsample(toVectors(points, T_world_lidar), 0.25 * config_.voxel_size_m))
    scan.points.push_back(p.cast<float>());
  scans_.push_back(std::move(scan));
}

VoxelMap GroundTruthCheck::referenceNear(const Eigen::Vector3d& position) const {
  std::vector<std::pair<double, size_t>> by_distance;
  for (size_t i = 0; i < scans_.size(); ++i) {
    const double d = (scans_[i].position - position).norm();
    if (d <= config_.near_m) by_distance.emplace_back(d, i);
  }
  std::sort(by_distance.begin(), by_distance.end());
  size_t n = 0;
  while (n < by_distance.size() && n < config_.max_scans &&
         (n < config_.nearest_scans || by_distance[n].first <= config_.place_m))
    ++n;
  // The nearest first: a voxel keeps its first points.
  VoxelMap map(config_.voxel_size_m, 20);
  for (size_t k = 0; k < n; ++k) {
    std::vector<Eigen::Vector3d> world;
    for (const Eigen::Vector3f& p : scans_[by_distance[k].second].points)
      world.push_back(p.cast<double>());
    map.add(voxelDownsample(world, 0.5 * config_.voxel_size_m), world);
  }
  return map;
}

std::optional<Pose> GroundTruthCheck::registered(const std::vector<LidarPoint>& points,
                                                 const Pose& T_world_lidar) const {
  const VoxelMap map = referenceNear(T_world_lidar.translation());
  if (map.empty()) return std::nullopt;
  const std::vector<Eigen::Vector3d> scan =
      voxelDownsample(toVectors(points, Pose::Identity()), config_.voxel_size_m);
  IcpConfig icp;
  icp.min_correspondences = config_.min_correspondences;
  // Coarse then fine, as the pose refinement does: the kernel a third of the reach.
  IcpResult r = alignToMap(scan, map, T_world_lidar, config_.coarse_distance_m,
                           config_.coarse_distance_m / 3, icp);
  if (!r.enough_correspondences) return std::nullopt;
  r = alignToMap(scan, map, r.T, config_.fine_distance_m, config_.fine_distance_m / 3, icp);
  if (!r.enough_correspondences) return std::nullopt;
  if ((r.T.translation() - T_world_lidar.translation()).norm() > config_.max_correction_m)
    return std::nullopt;
  return r.T;
}

}  // namespace semsegmap
