#include "semsegmap/learn/augment.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "semsegmap/core/class_table.h"

namespace semsegmap {

namespace {

double uniform(std::mt19937& rng, double lo, double hi) {
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

Eigen::Vector3f position(const EnrichedPoint& p) {
  return {p.x, p.y, p.z};
}

void setPosition(EnrichedPoint& p, const Eigen::Vector3f& v) {
  p.x = v.x(), p.y = v.y(), p.z = v.z();
}

}  // namespace

Eigen::Vector3f centroidOf(const EnrichedCloud& cloud) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& p : cloud) sum += position(p).cast<double>();
  if (cloud.empty()) return Eigen::Vector3f::Zero();
  return (sum / static_cast<double>(cloud.size())).cast<float>();
}

EnrichedCloud rotateYaw(const EnrichedCloud& cloud, double yaw_rad) {
  const Eigen::Vector3f c = centroidOf(cloud);
  const float cy = static_cast<float>(std::cos(yaw_rad)),
              sy = static_cast<float>(std::sin(yaw_rad));
  EnrichedCloud out = cloud;
  for (auto& p : out) {
    const float dx = p.x - c.x(), dy = p.y - c.y();
    p.x = c.x() + cy * dx - sy * dy;
    p.y = c.y() + sy * dx + cy * dy;
  }
  return out;
}

EnrichedCloud scaleAboutCentroid(const EnrichedCloud& cloud, double scale) {
  const Eigen::Vector3f c = centroidOf(cloud);
  EnrichedCloud out = cloud;
  for (auto& p : out) setPosition(p, c + static_cast<float>(scale) * (position(p) - c));
  return out;
}

EnrichedCloud jitterPoints(const EnrichedCloud& cloud, double sigma_m, std::mt19937& rng) {
  std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma_m));
  EnrichedCloud out = cloud;
  if (sigma_m <= 0) return out;
  for (auto& p : out) {
    p.x += noise(rng);
    p.y += noise(rng);
    p.z += noise(rng);
  }
  return out;
}

EnrichedCloud dropPoints(const EnrichedCloud& cloud, double fraction, std::mt19937& rng) {
  std::bernoulli_distribution drop(std::clamp(fraction, 0.0, 1.0));
  EnrichedCloud out;
  out.reserve(cloud.size());
  for (const auto& p : cloud)
    if (!drop(rng)) out.push_back(p);
  if (out.empty() && !cloud.empty())
    out.push_back(cloud[std::uniform_int_distribution<size_t>(0, cloud.size() - 1)(rng)]);
  return out;
}

EnrichedCloud cutByPlane(const EnrichedCloud& cloud, const Eigen::Vector3f& normal,
                         double offset_m) {
  const Eigen::Vector3f c = centroidOf(cloud);
  EnrichedCloud out;
  out.reserve(cloud.size());
  for (const auto& p : cloud)
    if (normal.dot(position(p) - c) <= offset_m) out.push_back(p);
  return out;
}

namespace {

// Which points lie beyond the plane of normal n placed so that about `fraction` of them do; at
// least one point stays on the near side.
std::vector<bool> beyondPlane(const EnrichedCloud& cloud, Eigen::Vector3f n, double fraction) {
  if (n.norm() < 1e-6f) n = Eigen::Vector3f::UnitX();
  n.normalize();
  const Eigen::Vector3f c = centroidOf(cloud);
  std::vector<float> d(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) d[i] = n.dot(position(cloud[i]) - c);
  // The plane sits at the (1 - fraction) quantile of the projections; ties on it stay.
  const size_t keep = std::max<size_t>(
      1, cloud.size() - static_cast<size_t>(std::round(std::clamp(fraction, 0.0, 1.0) *
                                                       static_cast<double>(cloud.size()))));
  std::vector<float> sorted = d;
  std::nth_element(sorted.begin(), sorted.begin() + (keep - 1), sorted.end());
  const float offset = sorted[keep - 1];
  std::vector<bool> beyond(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i) beyond[i] = d[i] > offset;
  return beyond;
}

// The point as a sensor without that modality gives it.
void dropModalitiesOf(EnrichedPoint& p, bool drop_color, bool drop_classes) {
  if (drop_color) {
    p.h = p.s = p.v = 0;
    p.has_color = false;
  }
  if (drop_classes) {
    p.class_id = cls::kUnknown;
    p.has_class = false;
  }
}

// A plane of direction uniform on the sphere.
std::vector<bool> beyondRandomPlane(const EnrichedCloud& cloud, double fraction,
                                    std::mt19937& rng) {
  std::normal_distribution<float> g(0.0f, 1.0f);
  // Left as the shipped models drew it (argument order is the compiler's), so that their
  // recipe still reproduces them.
  const Eigen::Vector3f n(g(rng), g(rng), g(rng));
  return beyondPlane(cloud, n, fraction);
}

}  // namespace

EnrichedCloud cutSection(const EnrichedCloud& cloud, double fraction, std::mt19937& rng) {
  if (cloud.empty() || fraction <= 0) return cloud;
  const std::vector<bool> beyond = beyondRandomPlane(cloud, fraction, rng);
  EnrichedCloud out;
  out.reserve(cloud.size());
  for (size_t i = 0; i < cloud.size(); ++i)
    if (!beyond[i]) out.push_back(cloud[i]);
  return out;
}

EnrichedCloud confuseSection(const EnrichedCloud& cloud, double fraction, std::mt19937& rng) {
  if (cloud.empty() || fraction <= 0) return cloud;
  const std::vector<bool> beyond = beyondRandomPlane(cloud, fraction, rng);
  const bool pick = std::bernoulli_distribution(0.5)(rng);
  EnrichedCloud out = cloud;
  for (size_t i = 0; i < out.size(); ++i) {
    if (!beyond[i]) continue;
    const ClassId c = out[i].class_id;
    out[i].class_id = cls::isThin(c) ? (pick ? cls::kBuilding : cls::kVegetation)
                                     : cls::confusionPartner(c, pick);
  }
  return out;
}

EnrichedCloud unobserveSection(const EnrichedCloud& cloud, double fraction, std::mt19937& rng) {
  if (cloud.empty() || fraction <= 0) return cloud;
  // A camera's frustum edge is a plane through its centre and the vertical: horizontal normal.
  const double angle =
      std::uniform_real_distribution<double>(0.0, 2.0 * 3.14159265358979323846)(rng);
  const Eigen::Vector3f n(static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle)),
                          0.0f);
  const std::vector<bool> beyond = beyondPlane(cloud, n, fraction);
  EnrichedCloud out = cloud;
  for (size_t i = 0; i < out.size(); ++i)
    if (beyond[i]) dropModalitiesOf(out[i], true, true);
  return out;
}

EnrichedCloud shiftColor(const EnrichedCloud& cloud, double hue_shift, double saturation_scale,
                         double value_scale) {
  EnrichedCloud out = cloud;
  for (auto& p : out) {
    if (!p.has_color) continue;
    double h = std::fmod(static_cast<double>(p.h) + hue_shift, 1.0);
    if (h < 0) h += 1.0;
    p.h = static_cast<float>(h >= 1.0 ? 0.0 : h);
    p.s = static_cast<float>(std::clamp(p.s * saturation_scale, 0.0, 1.0));
    p.v = static_cast<float>(std::clamp(p.v * value_scale, 0.0, 1.0));
  }
  return out;
}

EnrichedCloud relabelPoints(const EnrichedCloud& cloud, double fraction, int num_classes,
                            std::mt19937& rng) {
  if (num_classes < 3) throw std::invalid_argument("relabelPoints: num_classes must be at least 3");
  std::bernoulli_distribution wrong(std::clamp(fraction, 0.0, 1.0));
  // A known class is replaced by one of the num_classes - 2 others in 1..num_classes-1 (so that
  // every draw really changes it); an unknown or out-of-range one by any of them.
  std::uniform_int_distribution<int> other(1, num_classes - 2), any(1, num_classes - 1);
  EnrichedCloud out = cloud;
  for (auto& p : out) {
    if (!wrong(rng)) continue;
    const bool known = p.class_id >= 1 && p.class_id < num_classes;
    int c = known ? other(rng) : any(rng);
    if (known && c >= p.class_id) ++c;
    p.class_id = static_cast<ClassId>(c);
  }
  return out;
}

EnrichedCloud dropModalities(const EnrichedCloud& cloud, bool drop_color, bool drop_classes) {
  EnrichedCloud out = cloud;
  for (EnrichedPoint& p : out) dropModalitiesOf(p, drop_color, drop_classes);
  return out;
}

EnrichedCloud augment(const EnrichedCloud& cloud, const AugmentConfig& config, std::mt19937& rng) {
  EnrichedCloud out = cloud;
  if (std::bernoulli_distribution(config.section_cut_probability)(rng))
    out = cutSection(out, uniform(rng, 0.0, config.max_cut_fraction), rng);
  out = dropPoints(out, uniform(rng, 0.0, config.max_drop_fraction), rng);
  out = rotateYaw(out, uniform(rng, -config.max_yaw_rad, config.max_yaw_rad));
  out =
      scaleAboutCentroid(out, 1.0 + uniform(rng, -config.max_scale_shift, config.max_scale_shift));
  out = jitterPoints(out, config.jitter_sigma_m, rng);
  out = shiftColor(out, uniform(rng, -config.max_hue_shift, config.max_hue_shift),
                   1.0 + uniform(rng, -config.max_sv_scale_shift, config.max_sv_scale_shift),
                   1.0 + uniform(rng, -config.max_sv_scale_shift, config.max_sv_scale_shift));
  out = relabelPoints(out, uniform(rng, 0.0, config.max_wrong_class_fraction), config.num_classes,
                      rng);
  // Drawn last and only when enabled, so that the draws above are the same as without it.
  if (config.confused_section_probability > 0 &&
      std::bernoulli_distribution(config.confused_section_probability)(rng))
    out = confuseSection(out, uniform(rng, 0.0, config.max_confused_fraction), rng);
  if (config.modality_dropout_probability > 0) {
    std::bernoulli_distribution dropped(config.modality_dropout_probability);
    const bool drop_color = dropped(rng);  // drawn first: argument order is unspecified
    out = dropModalities(out, drop_color, dropped(rng));
  }
  if (config.partial_coverage_probability > 0 &&
      std::bernoulli_distribution(config.partial_coverage_probability)(rng))
    out = unobserveSection(out, uniform(rng, 0.0, config.max_unobserved_fraction), rng);
  return out;
}

}  // namespace semsegmap
