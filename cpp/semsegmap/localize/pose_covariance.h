// The uncertainty of a localization, from its own evidence: a robot must tell a pose held by
// walls on every side from one that slides along a single wall, or from a handful of matched
// centroids. Each pose gets a 6 x 6 covariance in the map frame in ROS order (x, y, z, roll,
// pitch, yaw; the rotation a small one about the map's axes), from
//   - the registration that gave or checked it (relocalization's check, pose refinement): the
//     point-to-plane Gauss-Newton information at the solution, scaled by the residuals' variance;
//   - otherwise the matched centroids: the same least-squares system over the verified matches,
//     point to point, scaled by their spread.
// Neighbouring points of one surface are not independent observations (the same plane, the same
// sampling of the map), so the inverse information is far too small by itself: `inflation`
// multiplies it, and floors keep a pose from claiming millimetres; both were chosen on
// validation worlds (docs/real-data.md, "An honest uncertainty"). A direction the evidence does
// not constrain (along a lone wall) gets a large but finite variance, never infinity or NaN.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"
#include "semsegmap/odometry/icp.h"

namespace semsegmap {

using Covariance6 = Eigen::Matrix<double, 6, 6>;

struct PoseCovarianceConfig {
  // Chosen on the HDL-64E wake-ups of validation worlds 5 and 6 (133 poses of
  // config/lidar-camera.yaml, docs/real-data.md): 96 % within Mahalanobis distance 3, mean NEES
  // 2.1, median sigma 3 cm. The centroids' inflation is not calibrated yet.
  double registration_inflation = 40.0;  // on the point-to-plane evidence
  double centroid_inflation = 1.0;       // on the matched centroids' evidence
  double min_sigma_m = 0.02;             // floors under every position and rotation sigma
  double min_sigma_deg = 0.5;
  double max_sigma_m = 100.0;  // caps: what an unconstrained direction gets
  double max_sigma_deg = 180.0;
  // A direction whose information (rotations in metres at the robot) is below this share of
  // what one correspondence along it would give, per correspondence, is unconstrained (gets the
  // caps), as the registration's own update treats it (odometry/icp.h): along a lone wall the
  // voxels' normals, tilted by noise, still "constrain" the slide a little, which would claim
  // centimetres where the scan knows nothing.
  double degeneracy_ratio = 1e-3;
};

// The covariance of the robot at `robot_map` (map frame) from a registration's evidence, which
// `inflation` multiplies.
Covariance6 covarianceFromEvidence(const RegistrationEvidence& evidence,
                                   const Eigen::Vector3d& robot_map, double inflation,
                                   const PoseCovarianceConfig& config);

// The evidence of matched centroids: `pairs` are (local centroid carried into the map by the
// pose, the target's centroid).
RegistrationEvidence centroidEvidence(
    const std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>>& pairs);

// The standard deviations of the covariance's diagonal: metres, then degrees.
Eigen::Matrix<double, 6, 1> sigmasOf(const Covariance6& covariance);

// (p - q)^T C^-1 (p - q) over the position block: how many sigmas a position error is, squared
// (the NEES of the position).
double positionNees(const Covariance6& covariance, const Eigen::Vector3d& error);

}  // namespace semsegmap
