#include "semsegmap/localize/pose_refinement.h"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Geometry>

#include "semsegmap/odometry/icp.h"
#include "semsegmap/odometry/voxel_map.h"

namespace semsegmap {

namespace {

// The registered segments' points: local ones (subsampled, local frame) and target ones (map
// frame); the matched segments, and with neighbours_m their neighbours.
struct MatchedPoints {
  std::vector<Eigen::Vector3d> local, target;
};

void addPoints(const std::vector<Eigen::Vector3f>& points, std::vector<Eigen::Vector3d>& out) {
  for (const Eigen::Vector3f& p : points) out.push_back(p.cast<double>());
}

Eigen::Vector3d meanOf(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : points) c += p.cast<double>();
  return c / static_cast<double>(points.size());
}

// Unpaired segments near each other under the match's pose join the registration. A linear scan
// of the map: it runs once a localization, and 100 local segments against a map of 10^4 are 10^6
// distance checks, a few milliseconds.
void markNeighbours(const Localization& match,
                    const std::vector<std::vector<Eigen::Vector3f>>& local_points,
                    const TargetMap& map, double distance_m, std::vector<bool>& local_used,
                    std::vector<bool>& target_used) {
  for (size_t i = 0; i < local_points.size(); ++i) {
    if (local_points[i].empty()) continue;
    const Eigen::Vector3f c = (match.T_map_local * meanOf(local_points[i])).cast<float>();
    for (size_t j = 0; j < map.size(); ++j)
      if ((map.segments[j].centroid - c).norm() < distance_m) local_used[i] = target_used[j] = true;
  }
}

MatchedPoints gather(const Localization& match,
                     const std::vector<std::vector<Eigen::Vector3f>>& local_points,
                     const TargetMap& map, const RefinementConfig& config) {
  std::vector<bool> local_used(local_points.size()), target_used(map.size());
  for (const auto& [query, target] : match.matches) {
    if (query >= local_points.size() || target >= map.size())
      throw std::out_of_range("refinePose: a match names a segment that is not there");
    local_used[query] = target_used[target] = true;
  }
  if (config.neighbours_m > 0)
    markNeighbours(match, local_points, map, config.neighbours_m, local_used, target_used);
  MatchedPoints out;
  for (size_t i = 0; i < local_points.size(); ++i)
    if (local_used[i])
      addPoints(subsamplePoints(local_points[i], config.max_points_per_segment), out.local);
  for (size_t j = 0; j < map.size(); ++j)
    if (target_used[j]) addPoints(map.segments[j].points, out.target);
  return out;
}

// One ICP pass with correspondences within `distance_m`. The map's voxels are as large as the
// coarse distance in both passes, so that the 3 x 3 x 3 voxels searched hold every point within
// either distance and each voxel holds enough of a segment's sparse stored points to fit a plane
// (voxels of the fine distance would mostly hold one or two).
IcpResult registerPass(const std::vector<Eigen::Vector3d>& source, const VoxelMap& target,
                       const Pose& initial, double distance_m, const RefinementConfig& config) {
  IcpConfig icp;
  icp.min_correspondences = config.min_correspondences;
  return alignToMap(source, target, initial, distance_m, config.kernel_scale_m, icp);
}

Refinement notApplied(const Localization& match, std::string reason) {
  Refinement r;
  r.T_map_local = match.T_map_local;
  r.reason = std::move(reason);
  return r;
}

}  // namespace

bool hasSegmentPoints(const TargetMap& map) {
  return std::all_of(map.segments.begin(), map.segments.end(),
                     [](const MapSegment& s) { return !s.points.empty(); });
}

Refinement refinePose(const Localization& match,
                      const std::vector<std::vector<Eigen::Vector3f>>& local_points,
                      const TargetMap& map, const RefinementConfig& config) {
  const MatchedPoints m = gather(match, local_points, map, config);
  if (m.local.size() < config.min_correspondences || m.target.size() < config.min_correspondences)
    return notApplied(match, "too few segment points");
  // ICP linearises rotations about the source frame's origin; the local map's origin (where the
  // odometry started) may lie kilometres from the matched segments, so register their points
  // about their own centroid instead.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : m.local) c += p;
  c /= static_cast<double>(m.local.size());
  std::vector<Eigen::Vector3d> source(m.local.size());
  for (size_t i = 0; i < source.size(); ++i) source[i] = m.local[i] - c;
  const Pose at_centroid = match.T_map_local * Eigen::Translation3d(c);
  // A segment's stored points are few: 256 a voxel keeps nearly all of them.
  VoxelMap target(config.coarse_distance_m, 256);
  target.add(m.target, m.target);
  IcpResult icp = registerPass(source, target, at_centroid, config.coarse_distance_m, config);
  if (icp.enough_correspondences)
    icp = registerPass(source, target, icp.T, config.fine_distance_m, config);
  if (!icp.enough_correspondences) return notApplied(match, "too few correspondences");
  Refinement r;
  r.T_map_local = icp.T * Eigen::Translation3d(-c);
  r.correspondences = icp.correspondences;
  r.correction_m = (icp.T.translation() - at_centroid.translation()).norm();
  if (r.correction_m > config.max_correction_m)
    return notApplied(match, "the points disagree with the match");
  r.evidence = evidenceAt(source, target, icp.T, config.fine_distance_m, config.kernel_scale_m);
  r.applied = true;
  return r;
}

}  // namespace semsegmap
