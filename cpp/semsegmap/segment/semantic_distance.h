// The paper's segmentation distance (section III-B, equation 1):
//   d^2 = dx^2 + dy^2 + dz^2 + f_h(|h1 - h2|)^2 + f_c(c1, c2)^2
// with f_h = p_h when the cyclic hue difference exceeds t_h, and f_c = p_c when the classes
// differ. Penalties below d_segment make them soft constraints. With both penalties zero this is
// SegMap's Euclidean distance.
#pragma once

#include <Eigen/Core>

#include "semsegmap/core/class_table.h"

namespace semsegmap {

struct SegmentationConfig {
  double d_segment_m = 0.3;
  double hue_threshold = 0.1;         // t_h, on hue in [0, 1)
  double hue_penalty = 0.05;          // p_h
  double class_penalty = 0.15;        // p_c
  size_t min_segment_points = 100;    // smaller segments are not reported
  size_t max_segment_points = 15000;  // larger segments are dropped for good
  double observation_growth = 0.1;    // a new observation when grown by 10 % in points
  // Keep the points of every observation (training data), not only of the latest one.
  bool keep_all_observation_points = false;
};

// What the distance needs to know about a voxel.
struct DistanceVoxel {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  float hue = 0.0f;
  bool has_color = false;
  bool has_class = false;  // false: unobserved, class_id means nothing
  ClassId class_id = cls::kUnknown;
};

// Cyclic hue difference in [0, 0.5].
float hueDifference(float h1, float h2);

class SemanticDistance {
 public:
  explicit SemanticDistance(const SegmentationConfig& config);
  // A voxel without colour, unobserved or of class unknown carries no evidence for a penalty:
  // only what two voxels both know can keep them apart.
  float squared(const DistanceVoxel& a, const DistanceVoxel& b) const;
  // Region growing asks this for every neighbour of every new voxel: inline, and most pairs are
  // decided by their positions alone.
  bool connected(const DistanceVoxel& a, const DistanceVoxel& b) const {
    const float d2 = (a.position - b.position).squaredNorm();
    return d2 <= d2_ && squared(a, b) <= d2_;
  }

 private:
  float d2_, t_h_, p_h2_, p_c2_;
};

}  // namespace semsegmap
