#include "semsegmap/localize/registration_check.h"

#include <cmath>

#include <Eigen/Geometry>

#include "semsegmap/odometry/icp.h"
#include "semsegmap/odometry/voxel_map.h"

namespace semsegmap {

namespace {

RegistrationCheck refused(const Pose& T_map_local, std::string reason) {
  RegistrationCheck c;
  c.T_map_local = T_map_local;
  c.reason = std::move(reason);
  return c;
}

// The stored points of the map segments near the robot's proposed place. A linear scan over the
// segments: it runs for a handful of proposed places per relocalization, and 10^4 centroid
// distances are a fraction of a millisecond.
std::vector<Eigen::Vector3d> mapPointsNear(const TargetMap& map, const Eigen::Vector3d& place,
                                           double radius_m) {
  std::vector<Eigen::Vector3d> out;
  for (const MapSegment& s : map.segments)
    if ((s.centroid.cast<double>() - place).norm() <= radius_m)
      for (const Eigen::Vector3f& p : s.points) out.push_back(p.cast<double>());
  return out;
}

// Share of `source` points (already in the map frame) with a map point within near_m. Distance
// to the nearest point rather than to a voxel's plane: a voxel at a building's corner or where
// two segments meet fits a plane through neither, and counted a third of the points of the
// right pose of a town of small buildings as off.
double fitnessOf(const std::vector<Eigen::Vector3d>& source, const VoxelMap& map,
                 const RegistrationCheckConfig& config) {
  size_t inliers = 0;
  for (const Eigen::Vector3d& p : source) inliers += map.closest(p, config.near_m).found;
  return source.empty() ? 0.0 : static_cast<double>(inliers) / static_cast<double>(source.size());
}

}  // namespace

RegistrationCheck checkRegistration(const std::vector<std::vector<Eigen::Vector3f>>& local_points,
                                    const Eigen::Vector3d& robot_local, const TargetMap& map,
                                    const Pose& T_map_local,
                                    const RegistrationCheckConfig& config) {
  std::vector<Eigen::Vector3d> local;
  for (const std::vector<Eigen::Vector3f>& segment : local_points)
    for (const Eigen::Vector3f& p : subsamplePoints(segment, config.max_points_per_segment))
      local.push_back(p.cast<double>());
  const std::vector<Eigen::Vector3d> target =
      mapPointsNear(map, T_map_local * robot_local, config.place_radius_m);
  if (local.size() < config.min_points || target.size() < config.min_points)
    return refused(T_map_local, "too few points to register");
  // About the local points' centroid, as the pose refinement does: ICP linearises rotations
  // about the source frame's origin, which may lie far from the robot.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : local) c += p;
  c /= static_cast<double>(local.size());
  for (Eigen::Vector3d& p : local) p -= c;
  const Pose proposed = T_map_local * Eigen::Translation3d(c);
  // Voxels as large as the coarse distance, so that the 3 x 3 x 3 searched hold every point
  // within it and each holds enough of the map's sparse stored points for a plane.
  VoxelMap reference(config.coarse_distance_m, 256);
  reference.add(target, target);
  IcpConfig icp;
  icp.min_correspondences = config.min_points;
  IcpResult r =
      alignToMap(local, reference, proposed, config.coarse_distance_m, config.kernel_scale_m, icp);
  if (r.enough_correspondences)
    r = alignToMap(local, reference, r.T, config.fine_distance_m, config.kernel_scale_m, icp);
  if (!r.enough_correspondences) return refused(T_map_local, "the points do not overlap the map");
  RegistrationCheck out;
  out.T_map_local = r.T * Eigen::Translation3d(-c);
  out.points = local.size();
  out.correction_m = translationError(r.T, proposed);
  out.correction_deg = rotationErrorDeg(r.T, proposed);
  for (Eigen::Vector3d& p : local) p = r.T * p;
  out.fitness = fitnessOf(local, reference, config);
  if (out.correction_m > config.max_correction_m || out.correction_deg > config.max_correction_deg)
    out.reason = "registration moved the pose too far";
  else if (out.fitness < config.min_fitness)
    out.reason = "the points do not lie on the map's";
  out.accepted = out.reason.empty();
  return out;
}

}  // namespace semsegmap
