// Registration of a scan to the voxel map: Gauss-Newton on point-to-plane residuals (or
// point-to-point where a voxel has no plane, or everywhere when asked), weighted by the
// Geman-McClure kernel so that wrong correspondences pull little.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"
#include "semsegmap/odometry/voxel_map.h"

namespace semsegmap {

enum class IcpMetric { kPointToPlane, kPointToPoint };

struct IcpConfig {
  IcpMetric metric = IcpMetric::kPointToPlane;
  int max_iterations = 50;
  // Stop when an update moves the pose by less than this (metres; radians times 10 m).
  double convergence = 1e-3;
  // A direction of motion is degenerate when the scan constrains it by less than this fraction
  // of what one correspondence along it would give per correspondence; the update leaves such
  // directions alone, so they keep the prediction (a straight corridor says nothing along it).
  double degeneracy_ratio = 3e-4;
  size_t min_correspondences = 20;
};

struct IcpResult {
  Pose T = Pose::Identity();
  int iterations = 0;
  size_t correspondences = 0;  // in the last iteration
  int degenerate_directions = 0;
  bool enough_correspondences = false;
};

// Aligns `source` (points in the sensor frame) to `map` starting from `initial` (sensor ->
// map frame). Correspondences farther than max_distance_m are ignored; a correspondence with
// residual r weighs (k^2 / (k^2 + r^2))^2 with k = kernel_scale_m (Geman-McClure).
IcpResult alignToMap(const std::vector<Eigen::Vector3d>& source, const VoxelMap& map,
                     const Pose& initial, double max_distance_m, double kernel_scale_m,
                     const IcpConfig& config);

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// What a registration's correspondences say about its pose, at the pose it ended on: the
// Gauss-Newton information (rotation vector about the source frame's origin carried into the
// map, then translation, the update's parameters) and the variance of one residual. Their
// quotient's inverse is the pose's covariance were the residuals independent
// (localize/pose_covariance.h says why they are not).
struct RegistrationEvidence {
  Matrix6d information = Matrix6d::Zero();           // sum of w J J^T over the correspondences
  double residual_variance = 0.0;                    // sum of w r^2 over sum of w, per residual
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the rotation's centre, map frame
  size_t correspondences = 0;
};

// The evidence of `source` registered at `T` with the same correspondences and kernel as the
// last iterations of alignToMap.
RegistrationEvidence evidenceAt(const std::vector<Eigen::Vector3d>& source, const VoxelMap& map,
                                const Pose& T, double max_distance_m, double kernel_scale_m,
                                IcpMetric metric = IcpMetric::kPointToPlane);

// Eigenvalues and eigenvectors of a symmetric 6 x 6 matrix (columns of `vectors`).
void symmetricEigen6(const Matrix6d& A, Eigen::Matrix<double, 6, 1>* values, Matrix6d* vectors);

}  // namespace semsegmap
