#include "semsegmap/odometry/adaptive_threshold.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace semsegmap {

AdaptiveThreshold::AdaptiveThreshold(double initial_threshold_m, double min_motion_m,
                                     double max_range_m)
    : initial_(initial_threshold_m), min_motion_(min_motion_m), max_range_(max_range_m) {}

void AdaptiveThreshold::addDeviation(const Pose& deviation, double range_m) {
  // A rotation by theta moves a point at range r by the chord 2 r sin(theta / 2).
  const double angle = Eigen::AngleAxisd(deviation.linear()).angle();
  const double range = std::min(range_m, max_range_);
  const double error =
      deviation.translation().norm() + 2.0 * range * std::sin(0.5 * std::abs(angle));
  if (!std::isfinite(error) || error <= min_motion_) return;
  sum_sq_ += error * error;
  ++samples_;
}

double AdaptiveThreshold::sigma() const {
  return samples_ == 0 ? initial_ : std::sqrt(sum_sq_ / static_cast<double>(samples_));
}

}  // namespace semsegmap
