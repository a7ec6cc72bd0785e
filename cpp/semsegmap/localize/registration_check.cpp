#include "semsegmap/localize/registration_check.h"

#include <algorithm>
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

// About n of `points`, evenly spaced.
std::vector<Eigen::Vector3d> about(const std::vector<Eigen::Vector3d>& points, size_t n) {
  const size_t step = std::max<size_t>(1, points.size() / n);
  std::vector<Eigen::Vector3d> out;
  for (size_t i = 0; i < points.size(); i += step) out.push_back(points[i]);
  return out;
}

// Share of `points` with a map point within distance_m at `T`, the fitness at near_m. Distance
// to the nearest point rather than to a voxel's plane: a voxel at a building's corner or where
// two segments meet fits a plane through neither, and counted a third of the points of the
// right pose of a town of small buildings as off.
double overlap(const std::vector<Eigen::Vector3d>& points, const VoxelMap& map, const Pose& T,
               double distance_m) {
  size_t near = 0;
  for (const Eigen::Vector3d& p : points) near += map.closest(T * p, distance_m).found;
  return points.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(points.size());
}

// The coarse registration from the proposed pose, with correspondences within distance_m, and
// the share of the points then within near_m of the map's.
struct CoarsePass {
  IcpResult icp;
  double fine_overlap = 0.0;
};

CoarsePass coarsePass(const std::vector<Eigen::Vector3d>& few, const VoxelMap& coarse,
                      const VoxelMap& fine, const Pose& proposed, double distance_m,
                      const RegistrationCheckConfig& config, const IcpConfig& icp) {
  CoarsePass out;
  out.icp = alignToMap(few, coarse, proposed, distance_m, config.kernel_scale_m, icp);
  if (out.icp.enough_correspondences)
    out.fine_overlap = overlap(few, fine, out.icp.T, config.near_m);
  return out;
}

// The coarse pass again with nearer correspondences (retry_coarse_distance_m), kept when it
// leaves more of the points on the map's than `first` did.
CoarsePass retriedNearer(const CoarsePass& first, const std::vector<Eigen::Vector3d>& few,
                         const std::vector<Eigen::Vector3d>& target, const VoxelMap& fine,
                         const Pose& proposed, const RegistrationCheckConfig& config,
                         const IcpConfig& icp) {
  VoxelMap nearer(config.retry_coarse_distance_m, 32);
  nearer.add(target, target);
  CoarsePass again =
      coarsePass(few, nearer, fine, proposed, config.retry_coarse_distance_m, config, icp);
  return again.fine_overlap > first.fine_overlap ? again : first;
}

// The angle between the local map's up and the map's, degrees.
double tiltDeg(const Pose& T_map_local) {
  const double up = std::clamp(T_map_local.linear()(2, 2), -1.0, 1.0);
  return std::acos(up) * 180.0 / M_PI;
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
  // Voxels as large as each pass's distance, so that the 3 x 3 x 3 searched hold every point
  // within it. The coarse pass keeps 32 points a voxel: a real scan's segments put hundreds in a
  // 3 m voxel, and searching them all was most of a relocalization; its planes still come from
  // every point. The fine pass and the fitness search 1 m voxels, whose points are all kept.
  // (8 a voxel was a tenth faster and left the synthetic town's poses 0.3 m off, not 0.2.)
  VoxelMap coarse(config.coarse_distance_m, 32);
  coarse.add(target, target);
  VoxelMap fine(std::max(1.0, std::max(config.fine_distance_m, config.near_m)), 64);
  fine.add(target, target);
  // Most proposed places of a relocalization are wrong. On about 1600 points, a wrong one is
  // refused when it has not half the fitness asked for, at the coarse distance before the coarse
  // pass, then at near_m after it: only a likely place pays for the fine pass on every point.
  // 800 would halve a lost frame (BM_LostFrame), but lost a simulated HDL-64E wake-up once and
  // the real KITTI 1615's now.
  const std::vector<Eigen::Vector3d> few = about(local, 1600);
  const char* apart = "the points do not overlap the map";
  if (overlap(few, coarse, proposed, config.coarse_distance_m) < config.min_fitness / 2)
    return refused(T_map_local, apart);
  IcpConfig icp;
  icp.min_correspondences = std::min(config.min_points, few.size());
  CoarsePass r = coarsePass(few, coarse, fine, proposed, config.coarse_distance_m, config, icp);
  if (r.fine_overlap < config.min_fitness && config.retry_coarse_distance_m > 0)
    r = retriedNearer(r, few, target, fine, proposed, config, icp);
  if (!r.icp.enough_correspondences) return refused(T_map_local, apart);
  if (r.fine_overlap < config.min_fitness / 2)
    return refused(r.icp.T * Eigen::Translation3d(-c), "the points do not lie on the map's");
  icp.min_correspondences = config.min_points;
  const IcpResult f =
      alignToMap(local, fine, r.icp.T, config.fine_distance_m, config.kernel_scale_m, icp);
  if (!f.enough_correspondences) return refused(T_map_local, apart);
  RegistrationCheck out;
  out.T_map_local = f.T * Eigen::Translation3d(-c);
  out.points = local.size();
  out.correction_m = translationError(f.T, proposed);
  out.correction_deg = rotationErrorDeg(f.T, proposed);
  out.fitness = overlap(local, fine, f.T, config.near_m);
  out.evidence = evidenceAt(local, fine, f.T, config.fine_distance_m, config.kernel_scale_m);
  if (out.correction_m > config.max_correction_m || out.correction_deg > config.max_correction_deg)
    out.reason = "registration moved the pose too far";
  else if (tiltDeg(out.T_map_local) > config.max_tilt_deg)
    out.reason = "the pose tilts the local map against the map";
  else if (out.fitness < config.min_fitness)
    out.reason = "the points do not lie on the map's";
  out.accepted = out.reason.empty();
  return out;
}

}  // namespace semsegmap
