// LiDAR points drawn over a camera image: the picture that shows whether enrichment's projection
// lines up with the scene (dots of the car class on the cars, road dots on the road).
#pragma once

#include <string>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/enriched_point.h"
#include "semsegmap/core/image.h"
#include "semsegmap/core/sensor_rig.h"

namespace semsegmap::viz {

enum class DotColour {
  kClass,  // the class table's display colour of the point's enriched class
  kDepth,  // depth along the optical axis, near red to far blue (datasets without labels);
           // points that enrichment left without colour (occluded) are black
};

struct EnrichOverlayStyle {
  DotColour colour = DotColour::kClass;
  int dot_radius_px = 1;              // 0: single pixels
  double near_m = 3.0, far_m = 60.0;  // depth colour scale (logarithmic between the two)
  int max_width = 0;                  // > 0: a wider picture is shrunk to this width once drawn
};

// `rgb` is `camera`'s image; every point of `cloud` in front of the camera and inside the image
// is drawn, far ones first so that near ones stay on top. `legend` is written in the top-left
// corner, one line per '\n'; in class mode, the classes that appear get swatches at the bottom.
// Throws std::invalid_argument when rgb's size is not the camera's.
Image drawEnrichOverlay(const Image& rgb, const Camera& camera, const EnrichedCloud& cloud,
                        const ClassTable& classes, const std::string& legend,
                        const EnrichOverlayStyle& style = {});

}  // namespace semsegmap::viz
