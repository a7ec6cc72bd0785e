// Numbers a person wants from a localization run besides the paper's counts: how many
// localizations fall under each error threshold (the paper's accuracy figures), how much of the
// drive the robot knew where it was, and how often it was confidently wrong.
#pragma once

#include <cstddef>
#include <vector>

namespace semsegmap {

// For each threshold t, the number of errors <= t.
std::vector<size_t> cumulativeCounts(const std::vector<double>& errors,
                                     const std::vector<double>& thresholds);

// Recall along the trajectory: the fraction of the metres driven at which the robot had been
// localized correctly within the last `window_m` metres, i.e. the length of the union of the
// stretches [d, d + window_m] after each correct localization at distance d, over the drive's
// length. `travelled_m` is the distance driven at each frame (non-decreasing); `correct_frames`
// are the frames (indices into it) with a correct localization. A drive of zero length has
// recall 0.
double recallAlongTrajectory(const std::vector<double>& travelled_m,
                             const std::vector<size_t>& correct_frames, double window_m = 20.0);

// Distance driven at each pose of a trajectory, starting at 0.
template <typename Pose>
std::vector<double> travelledDistances(const std::vector<Pose>& trajectory) {
  std::vector<double> d;
  for (size_t i = 0; i < trajectory.size(); ++i)
    d.push_back(
        i == 0 ? 0.0
               : d.back() + (trajectory[i].translation() - trajectory[i - 1].translation()).norm());
  return d;
}

}  // namespace semsegmap
