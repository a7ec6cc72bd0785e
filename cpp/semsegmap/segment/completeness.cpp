#include "semsegmap/segment/completeness.h"

#include <algorithm>

namespace semsegmap {

std::vector<double> estimateCompleteness(const std::vector<ObservationSize>& observations,
                                         size_t window_frames) {
  std::vector<double> estimate(observations.size(), 0.0);
  double running = 0.0;
  size_t before = 0;  // observations taken at or before the window's start
  for (size_t k = 0; k < observations.size(); ++k) {
    const ObservationSize& o = observations[k];
    while (before < k && observations[before].frame_index + window_frames <= o.frame_index)
      ++before;
    const size_t then = before > 0 ? observations[before - 1].n_points : 0;
    if (o.n_points > 0)
      running = std::max(running, std::min(1.0, static_cast<double>(then) / o.n_points));
    estimate[k] = running;
  }
  return estimate;
}

}  // namespace semsegmap
