// The last word on a relocalization: a pose proposed by a few segment matches is accepted only
// when the robot's segment points, carried into the map by it, register to the map's stored
// points and then lie on them. A handful of consistent centroids can come from a place that only
// looks alike (four trees in a row, a corner of a building); the points of every local segment
// lying on the map's surfaces cannot, unless the two places have the same geometry throughout.
//
// The check registers (the odometry's point-to-plane ICP, coarse then fine, from the proposed
// pose) and measures the fitness: the share of local points with a map point within `near_m`.
// Points of things the map never held (a parked car that left) lower it, so the threshold is a
// share, not all of them. The map's stored points must be dense enough for it: about one per
// near_m x near_m of surface (target_map.max_points_per_segment: a 20 x 8 m facade needs ~600
// for 0.5 m).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/odometry/icp.h"

namespace semsegmap {

struct RegistrationCheckConfig {
  size_t max_points_per_segment = 128;  // local points a segment contributes (evenly spaced)
  double coarse_distance_m = 3.0;       // correspondences of the first registration pass
  // A coarse pass that leaves the points off the map's (fitness below min_fitness) is run again
  // from the proposed pose with correspondences this near, and the better of the two goes on
  // (0: never). Wide correspondences reach a proposal metres off, but can drag one that was a
  // metre off onto a neighbouring wall (a real KITTI wake-up: 0.95 m off, 3.9 m after 3 m).
  double retry_coarse_distance_m = 2.0;
  double fine_distance_m = 0.5;      // then these
  double kernel_scale_m = 0.2;       // Geman-McClure scale
  double near_m = 0.5;               // a local point with a map point this near is an inlier
  double min_fitness = 0.6;          // share of local points that must be inliers
  size_t min_points = 200;           // fewer local points (or map points near them): refused
  double max_correction_m = 5.0;     // registration may move the proposed pose this far
  double max_correction_deg = 15.0;  // and turn it this much
  // The registered pose may tilt the local map this much against the map: both are level (a
  // ground robot's odometry frame and the map built from one), so a pose tilted further fits
  // the points by a symmetry. Four matched centroids at one height are as consistent upside
  // down: a simulated VLP-32 scan registered 67 % of its points 232 m off, rolled 179 degrees
  // (world 5); right relocalizations of the simulator and the KITTI scans tilt less than 6.
  double max_tilt_deg = 10.0;
  double place_radius_m = 60.0;  // map points this near the robot are registered to
};

struct RegistrationCheck {
  bool accepted = false;
  Pose T_map_local = Pose::Identity();  // registered (when the registration ran)
  double fitness = 0.0;                 // share of local points that are inliers
  size_t points = 0;                    // local points checked
  double correction_m = 0.0, correction_deg = 0.0;
  std::string reason;  // why it was refused ("" when accepted)
  // The fine registration's evidence at T_map_local (pose_covariance.h), when it ran to the end.
  RegistrationEvidence evidence;
};

// `local_points[i]`: the points of local segment i (local map frame; empty ones are skipped);
// `robot_local`: where the robot is in the local map frame (map points near its proposed place
// are registered to); the map's segments must hold points (hasSegmentPoints).
RegistrationCheck checkRegistration(const std::vector<std::vector<Eigen::Vector3f>>& local_points,
                                    const Eigen::Vector3d& robot_local, const TargetMap& map,
                                    const Pose& T_map_local, const RegistrationCheckConfig& config);

}  // namespace semsegmap
