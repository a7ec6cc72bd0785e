#include "semsegmap/eval/odometry_metrics.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

#include "semsegmap/eval/localization_metrics.h"

namespace semsegmap {

namespace {

// The devkit's lastFrameFromSegmentLength: the first frame beyond `length` from `first`, or
// none.
std::optional<size_t> lastFrame(const std::vector<double>& distances, size_t first, double length) {
  for (size_t i = first; i < distances.size(); ++i)
    if (distances[i] > distances[first] + length) return i;
  return std::nullopt;
}

// The devkit's rotationError: the angle of R from its trace, clamped against rounding.
double rotationAngle(const Pose& error) {
  const Eigen::Matrix3d& R = error.linear();
  const double d = 0.5 * (R(0, 0) + R(1, 1) + R(2, 2) - 1.0);
  return std::acos(std::clamp(d, -1.0, 1.0));
}

void summarise(KittiRelativeError& e, const std::vector<double>& lengths) {
  constexpr double kDegPer100mPerRadPerM = 100.0 * 180.0 / M_PI;
  for (const double length : lengths) {
    KittiLengthError l;
    l.length_m = length;
    for (const KittiSegment& s : e.segments) {
      if (s.length_m != length) continue;
      ++l.segments;
      l.translation_percent += 100.0 * s.translation_error;
      l.rotation_deg_per_100m += kDegPer100mPerRadPerM * s.rotation_error_rad_per_m;
    }
    if (l.segments == 0) continue;
    l.translation_percent /= static_cast<double>(l.segments);
    l.rotation_deg_per_100m /= static_cast<double>(l.segments);
    e.by_length.push_back(l);
  }
  for (const KittiSegment& s : e.segments) {
    e.translation_percent += 100.0 * s.translation_error;
    e.rotation_deg_per_100m += kDegPer100mPerRadPerM * s.rotation_error_rad_per_m;
  }
  if (e.segments.empty()) return;
  e.translation_percent /= static_cast<double>(e.segments.size());
  e.rotation_deg_per_100m /= static_cast<double>(e.segments.size());
}

}  // namespace

KittiRelativeError kittiRelativeError(const std::vector<Pose>& estimate,
                                      const std::vector<Pose>& ground_truth,
                                      const std::vector<double>& lengths_m, size_t step_frames) {
  if (estimate.size() != ground_truth.size())
    throw std::invalid_argument("kittiRelativeError: " + std::to_string(estimate.size()) +
                                " estimated poses but " + std::to_string(ground_truth.size()) +
                                " ground-truth poses");
  const std::vector<double> distances = travelledDistances(ground_truth);
  KittiRelativeError e;
  const size_t step = std::max<size_t>(1, step_frames);
  for (size_t first = 0; first < ground_truth.size(); first += step) {
    for (const double length : lengths_m) {
      const std::optional<size_t> last = lastFrame(distances, first, length);
      if (!last) continue;
      const Pose delta_gt = ground_truth[first].inverse() * ground_truth[*last];
      const Pose delta_est = estimate[first].inverse() * estimate[*last];
      const Pose error = delta_est.inverse() * delta_gt;
      e.segments.push_back({first, *last, length, error.translation().norm() / length,
                            rotationAngle(error) / length});
    }
  }
  summarise(e, lengths_m);
  return e;
}

nlohmann::ordered_json toJson(const KittiRelativeError& error) {
  nlohmann::ordered_json j;
  // A trajectory shorter than the shortest length has no segment: the error is unknown.
  const bool measured = !error.segments.empty();
  j["translation_percent"] = measured ? nlohmann::ordered_json(error.translation_percent)
                                      : nlohmann::ordered_json(nullptr);
  j["rotation_deg_per_100m"] = measured ? nlohmann::ordered_json(error.rotation_deg_per_100m)
                                        : nlohmann::ordered_json(nullptr);
  j["segments"] = error.segments.size();
  nlohmann::ordered_json lengths = nlohmann::ordered_json::array();
  for (const KittiLengthError& l : error.by_length)
    lengths.push_back({{"length_m", l.length_m},
                       {"segments", l.segments},
                       {"translation_percent", l.translation_percent},
                       {"rotation_deg_per_100m", l.rotation_deg_per_100m}});
  j["by_length"] = lengths;
  return j;
}

nlohmann::ordered_json toJson(const TrajectoryError& error) {
  return {{"rmse_m", error.rmse_m},
          {"mean_m", error.mean_m},
          {"max_m", error.max_m},
          {"rotation_mean_deg", error.rotation_mean_deg},
          {"poses", error.n}};
}

}  // namespace semsegmap
