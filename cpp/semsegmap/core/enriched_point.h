// The paper's enriched point {x, y, z, h, s, v, c}: a LiDAR point with the colour (HSV) and
// semantic class of the camera pixel it projects into.
#pragma once

#include <cstdint>
#include <vector>

#include "semsegmap/core/class_table.h"

namespace semsegmap {

struct EnrichedPoint {
  float x = 0, y = 0, z = 0;
  float h = 0, s = 0, v = 0;  // hue in [0, 1) (cyclic), saturation and value in [0, 1]
  ClassId class_id = cls::kUnknown;
  bool has_color = false;  // false: seen by no camera (or occluded in every camera)
  // false: unobserved, no label image and no point label gave the point a class, and class_id
  // means nothing. That is not the class unknown, which a network (or a label file) gave to what
  // it could not name: a 360-degree LiDAR under one front camera is three quarters unobserved,
  // and those points keep their geometry (docs/unobserved.md says what each stage does).
  bool has_class = false;
  uint16_t instance_id = 0;  // ground-truth instance when the dataset has one (simulation),
                             // carried for evaluation and training only; 0 otherwise
};

using EnrichedCloud = std::vector<EnrichedPoint>;

}  // namespace semsegmap
