#include "semsegmap/segment/semantic_distance.h"

#include <cmath>
#include <stdexcept>

namespace semsegmap {

float hueDifference(float h1, float h2) {
  const float d = std::abs(h1 - h2);
  return std::min(d, 1.0f - d);
}

SemanticDistance::SemanticDistance(const SegmentationConfig& c)
    : d2_(static_cast<float>(c.d_segment_m * c.d_segment_m)),
      t_h_(static_cast<float>(c.hue_threshold)),
      p_h2_(static_cast<float>(c.hue_penalty * c.hue_penalty)),
      p_c2_(static_cast<float>(c.class_penalty * c.class_penalty)) {
  if (!(c.d_segment_m > 0))
    throw std::invalid_argument("segmentation.d_segment_m must be positive");
  if (c.hue_penalty < 0 || c.class_penalty < 0)
    throw std::invalid_argument("segmentation penalties must not be negative");
}

float SemanticDistance::squared(const DistanceVoxel& a, const DistanceVoxel& b) const {
  float d2 = (a.position - b.position).squaredNorm();
  if (a.has_color && b.has_color && hueDifference(a.hue, b.hue) > t_h_) d2 += p_h2_;
  if (a.has_class && b.has_class && a.class_id != b.class_id && a.class_id != cls::kUnknown &&
      b.class_id != cls::kUnknown)
    d2 += p_c2_;
  return d2;
}

}  // namespace semsegmap
