#include "semsegmap/core/stamped_pose.h"

#include <algorithm>

namespace semsegmap {

std::vector<Pose> posesOf(const std::vector<StampedPose>& trajectory) {
  std::vector<Pose> poses;
  poses.reserve(trajectory.size());
  for (const StampedPose& p : trajectory) poses.push_back(p.T);
  return poses;
}

std::optional<Pose> poseAt(const std::vector<StampedPose>& trajectory, double t, double max_gap_s) {
  if (trajectory.empty() || !(t >= trajectory.front().timestamp_s) ||
      !(t <= trajectory.back().timestamp_s))
    return std::nullopt;
  const auto hi =
      std::lower_bound(trajectory.begin(), trajectory.end(), t,
                       [](const StampedPose& p, double time) { return p.timestamp_s < time; });
  if (hi->timestamp_s == t) return hi->T;
  const auto lo = hi - 1;
  const double gap = hi->timestamp_s - lo->timestamp_s;
  if (gap > max_gap_s) return std::nullopt;
  return interpolatePose(lo->T, hi->T, (t - lo->timestamp_s) / gap);
}

}  // namespace semsegmap
