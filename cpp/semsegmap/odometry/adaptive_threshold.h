// The correspondence threshold of the odometry, adapted to how far the true motion strays from
// the constant-velocity prediction (kiss-icp's idea): a robot that drives smoothly needs a
// tight threshold (few wrong matches), one that brakes and turns hard a wide one.
#pragma once

#include <cstddef>

#include "semsegmap/core/pose.h"

namespace semsegmap {

class AdaptiveThreshold {
 public:
  AdaptiveThreshold(double initial_threshold_m, double min_motion_m, double max_range_m);

  // `deviation` = prediction^-1 * estimate of one frame. Its size is how far a point at range
  // `range_m` (the scan's typical range, at most the maximum range) moved because the prediction
  // was off; deviations below the minimum motion are not counted (a robot at rest says nothing
  // about the prediction's error). The maximum range itself would count a small rotation error
  // as metres of error, and the threshold would stay wide long after one hard turn.
  void addDeviation(const Pose& deviation, double range_m);

  // The standard deviation of the prediction error over all frames so far (the initial
  // threshold until one frame has been counted).
  double sigma() const;
  size_t samples() const { return samples_; }

 private:
  double initial_, min_motion_, max_range_;
  double sum_sq_ = 0.0;
  size_t samples_ = 0;
};

}  // namespace semsegmap
