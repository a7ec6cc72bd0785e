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

}  // namespace semsegmap
