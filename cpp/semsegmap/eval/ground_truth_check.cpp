#include "semsegmap/eval/ground_truth_check.h"

#include <algorithm>
#include <stdexcept>
#include <utility>

#include "semsegmap/odometry/icp.h"

namespace semsegmap {

namespace {

// Points that are not finite (a robot's driver may mark missing returns so) are left out: their
// voxel keys would be undefined.
std::vector<Eigen::Vector3d> toVectors(const std::vector<LidarPoint>& points, const Pose& T) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const LidarPoint& p : points) {
    const Eigen::Vector3d v(p.x, p.y, p.z);
    if (v.allFinite()) out.push_back(T * v);
  }
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

uint64_t GroundTruthCheck::bytes() const {
  uint64_t bytes = 0;
  for (const MappedScan& scan : scans_) bytes += scan.points.size() * sizeof(Eigen::Vector3f);
  return bytes;
}

std::vector<size_t> GroundTruthCheck::scansNear(const Eigen::Vector3d& position) const {
  std::vector<std::pair<double, size_t>> by_distance;
  for (size_t i = 0; i < scans_.size(); ++i) {
    const double d = (scans_[i].position - position).norm();
    if (d <= config_.near_m) by_distance.emplace_back(d, i);
  }
  std::sort(by_distance.begin(), by_distance.end());
  std::vector<size_t> near;
  while (near.size() < by_distance.size() && near.size() < config_.max_scans &&
         (near.size() < config_.nearest_scans || by_distance[near.size()].first <= config_.place_m))
    near.push_back(by_distance[near.size()].second);
  return near;
}

VoxelMap GroundTruthCheck::reference(const std::vector<size_t>& scans, double voxel_size_m) const {
  // The nearest first: a voxel keeps its first points.
  VoxelMap map(voxel_size_m, 20);
  for (const size_t i : scans) {
    std::vector<Eigen::Vector3d> world;
    for (const Eigen::Vector3f& p : scans_[i].points) world.push_back(p.cast<double>());
    map.add(voxelDownsample(world, 0.5 * voxel_size_m), world);
  }
  return map;
}

std::optional<Pose> GroundTruthCheck::registered(const std::vector<LidarPoint>& points,
                                                 const Pose& T_world_lidar) const {
  const std::vector<size_t> near = scansNear(T_world_lidar.translation());
  const VoxelMap map = reference(near, config_.voxel_size_m);
  if (map.empty()) return std::nullopt;
  const std::vector<Eigen::Vector3d> scan =
      voxelDownsample(toVectors(points, Pose::Identity()), config_.voxel_size_m);
  IcpConfig icp;
  icp.min_correspondences = config_.min_correspondences;
  IcpResult r;
  r.T = T_world_lidar;
  // The scan as fine as in the later passes: downsampled to the first pass's voxels, KITTI 00's
  // scans 1615 and 1634 kept too few correspondences (min_correspondences).
  if (config_.initial_distance_m > 0) {
    const double reach = config_.initial_distance_m;
    r = alignToMap(scan, reference(near, reach), r.T, reach, reach / 3, icp);
    if (!r.enough_correspondences) return std::nullopt;
  }
  // Coarse then fine, as the pose refinement does: the kernel a third of the reach.
  r = alignToMap(scan, map, r.T, config_.coarse_distance_m, config_.coarse_distance_m / 3, icp);
  if (!r.enough_correspondences) return std::nullopt;
  r = alignToMap(scan, map, r.T, config_.fine_distance_m, config_.fine_distance_m / 3, icp);
  if (!r.enough_correspondences) return std::nullopt;
  if ((r.T.translation() - T_world_lidar.translation()).norm() > config_.max_correction_m)
    return std::nullopt;
  return r.T;
}

}  // namespace semsegmap
