// The absolute trajectory error between an estimate and ground truth (stamped poses:
// core/stamped_pose.h; the files: io/trajectory_file.h).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/stamped_pose.h"

namespace semsegmap {

struct TrajectoryError {
  double rmse_m = 0.0;  // translation errors, pairwise
  double mean_m = 0.0;
  double max_m = 0.0;
  double rotation_mean_deg = 0.0;
  size_t n = 0;
};

// Pairs estimate[i] with ground_truth[i] (same length, not empty, else std::invalid_argument).
// With `align`, the estimate is first moved by the rigid transform (SE3, no scale; Umeyama) that
// minimises the translation RMSE, as evo's `ape --align` does.
TrajectoryError absoluteTrajectoryError(const std::vector<Pose>& estimate,
                                        const std::vector<Pose>& ground_truth, bool align);

}  // namespace semsegmap
