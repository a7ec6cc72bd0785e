#include "semsegmap/eval/localization_metrics.h"

#include <algorithm>
#include <stdexcept>

namespace semsegmap {

std::vector<size_t> cumulativeCounts(const std::vector<double>& errors,
                                     const std::vector<double>& thresholds) {
  std::vector<double> sorted = errors;
  std::sort(sorted.begin(), sorted.end());
  std::vector<size_t> out;
  out.reserve(thresholds.size());
  for (double t : thresholds)
    out.push_back(
        static_cast<size_t>(std::upper_bound(sorted.begin(), sorted.end(), t) - sorted.begin()));
  return out;
}

double recallAlongTrajectory(const std::vector<double>& travelled_m,
                             const std::vector<size_t>& correct_frames, double window_m) {
  if (travelled_m.size() < 2 || travelled_m.back() <= 0.0) return 0.0;
  std::vector<size_t> correct = correct_frames;
  std::sort(correct.begin(), correct.end());
  for (size_t f : correct)
    if (f >= travelled_m.size())
      throw std::out_of_range("recallAlongTrajectory: a localization after the last frame");
  // Each correct fix covers the stretch [d, d + window_m] after it; the union of those
  // stretches within the drive, over the drive's length.
  double covered = 0.0, reached = 0.0;  // the union so far ends at `reached`
  for (size_t f : correct) {
    const double from = std::max(travelled_m[f], reached);
    const double to = std::min(travelled_m[f] + window_m, travelled_m.back());
    if (to > from) covered += to - from;
    reached = std::max(reached, to);
  }
  return covered / travelled_m.back();
}

}  // namespace semsegmap
