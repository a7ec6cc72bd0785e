// Segments and their observations: a segment accumulates points as the robot sees it from new
// viewpoints, like a tracked keypoint; each time it has grown enough an observation is taken, and
// the last one before it leaves the local map is the most complete.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/enriched_point.h"

namespace semsegmap {

using SegmentId = int64_t;

struct SegmentObservation {
  size_t frame_index = 0;
  double timestamp_s = 0.0;
  size_t n_points = 0;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // map frame
  ClassId majority_class = cls::kUnknown;
  uint16_t gt_instance = 0;  // majority ground-truth instance of the points (0: unknown)
  float gt_purity = 0.0f;    // share of the points that belong to it
  EnrichedCloud points;      // map frame; empty for older observations unless kept
};

struct Segment {
  SegmentId id = 0;
  std::vector<SegmentObservation> observations;
  size_t first_frame = 0;
  size_t last_frame = 0;

  const SegmentObservation& last() const { return observations.back(); }
  // Completeness of observation k: its points over the most complete observation so far.
  double completeness(size_t k) const;
};

}  // namespace semsegmap
