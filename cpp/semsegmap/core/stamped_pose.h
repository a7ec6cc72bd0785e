// A pose with its time, and the poses of a stamped trajectory: what readers, trajectory files and
// the pose graph share (graph/trajectory.h adds the trajectory errors).
#pragma once

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

}  // namespace semsegmap
