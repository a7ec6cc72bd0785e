// Pose refinement after the segment match: the verified matches give T_map_local from centroids
// only, and a centroid moves with what part of a segment was seen (a wall seen from one end, a
// tree from one side), so the pose is off by tenths of a metre. Registering the matched local
// segments' points to the matched target segments' points (the target map's optional point sets)
// removes most of that. Registration is the odometry's point-to-plane ICP with a robust kernel,
// coarse then fine; a refinement that disagrees with the match is not applied.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/localize/localizer.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/odometry/icp.h"

namespace semsegmap {

struct RefinementConfig {
  bool enabled = false;
  // Points a local segment contributes (evenly spaced); the target map's stored points are used
  // as they are (`map --points N`).
  size_t max_points_per_segment = 256;
  // Correspondences within this distance: the coarse pass covers the centroid pose's error, the
  // fine one what is left.
  double coarse_distance_m = 1.0;
  double fine_distance_m = 0.3;
  double kernel_scale_m = 0.1;  // Geman-McClure scale
  // A refinement that moves the pose by more than this, or has fewer correspondences, keeps the
  // centroid pose: the points then disagree with the verified match more than its error allows.
  double max_correction_m = 1.5;
  size_t min_correspondences = 50;
  // Also register the segments the match did not pair: every local segment whose centroid, under
  // the match's pose, lies within this distance of a target segment's centroid, with those target
  // segments. A few matched segments constrain the rotation poorly (seven poles and trunks in a
  // row leave a roll about their line); the place's other segments pin it. 0: matched only.
  double neighbours_m = 0.0;
};

struct Refinement {
  Pose T_map_local = Pose::Identity();  // refined, or the match's when not applied
  bool applied = false;
  size_t correspondences = 0;
  double correction_m = 0.0;  // how far the refinement moved the local map's origin
  std::string reason;         // why it was not applied ("" when applied)
  // The fine pass's evidence at T_map_local, when applied (pose_covariance.h).
  RegistrationEvidence evidence;
};

// Refines `match.T_map_local`. `local_points[i]` are the points of query segment i (local map
// frame), as indexed by match.matches (with neighbours_m, of every query segment; an empty one is
// left out); target points come from map.segments[j].points.
Refinement refinePose(const Localization& match,
                      const std::vector<std::vector<Eigen::Vector3f>>& local_points,
                      const TargetMap& map, const RefinementConfig& config);

// Whether every segment of the map has stored points: refinement needs them.
bool hasSegmentPoints(const TargetMap& map);

}  // namespace semsegmap
