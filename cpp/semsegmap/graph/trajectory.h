// Stamped poses and the absolute trajectory error between an estimate and ground truth (the
// files: io/trajectory_file.h).
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "semsegmap/core/pose.h"

namespace semsegmap {

struct StampedPose {
  double timestamp_s = 0.0;
  Pose T = Pose::Identity();
};

// The poses of a stamped trajectory, without their timestamps.
std::vector<Pose> posesOf(const std::vector<StampedPose>& trajectory);

// The pose at time t, interpolated between the two stamped poses around it (sorted by time).
// Nothing when t lies outside the trajectory, or when the poses around it are more than
// max_gap_s apart (a gap in the recording is not bridged by a straight line).
std::optional<Pose> poseAt(const std::vector<StampedPose>& trajectory, double t, double max_gap_s);

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
