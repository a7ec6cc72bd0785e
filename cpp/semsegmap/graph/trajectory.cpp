#include "semsegmap/graph/trajectory.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace semsegmap {

TrajectoryError absoluteTrajectoryError(const std::vector<Pose>& estimate,
                                        const std::vector<Pose>& ground_truth, bool align) {
  if (estimate.size() != ground_truth.size())
    throw std::invalid_argument("absoluteTrajectoryError: " + std::to_string(estimate.size()) +
                                " estimated poses but " + std::to_string(ground_truth.size()) +
                                " ground-truth poses");
  if (estimate.empty()) throw std::invalid_argument("absoluteTrajectoryError: no poses");
  const Eigen::Index n = static_cast<Eigen::Index>(estimate.size());

  Pose T_gt_est = Pose::Identity();
  if (align) {
    Eigen::Matrix3Xd est(3, n), gt(3, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      est.col(i) = estimate[i].translation();
      gt.col(i) = ground_truth[i].translation();
    }
    T_gt_est.matrix() = Eigen::umeyama(est, gt, /*with_scaling=*/false);
  }

  TrajectoryError e;
  e.n = estimate.size();
  double sum_sq = 0.0, sum = 0.0, sum_rot = 0.0;
  for (size_t i = 0; i < estimate.size(); ++i) {
    const Pose aligned = T_gt_est * estimate[i];
    const double d = translationError(aligned, ground_truth[i]);
    sum_sq += d * d;
    sum += d;
    e.max_m = std::max(e.max_m, d);
    sum_rot += rotationErrorDeg(aligned, ground_truth[i]);
  }
  const double count = static_cast<double>(e.n);
  e.rmse_m = std::sqrt(sum_sq / count);
  e.mean_m = sum / count;
  e.rotation_mean_deg = sum_rot / count;
  return e;
}

}  // namespace semsegmap
