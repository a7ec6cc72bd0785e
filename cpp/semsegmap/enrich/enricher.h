// Semantic enrichment (paper section III-A): every LiDAR point takes the colour and class of the
// camera pixel it projects into, through each camera's intrinsics and LiDAR-to-camera extrinsics.
#pragma once

#include "semsegmap/core/enriched_point.h"
#include "semsegmap/core/frame.h"
#include "semsegmap/core/sensor_rig.h"

namespace semsegmap {

struct EnrichmentConfig {
  // Z-buffer occlusion test against the camera/LiDAR parallax: a point is not coloured by a
  // camera when a nearer point projects within `occlusion_radius_px` of its pixel, is nearer by
  // more than occlusion_tolerance_m + occlusion_tolerance_rel * depth, and the parallax has moved
  // it towards the point by at least a pixel (so that a road seen at a grazing angle, whose
  // LiDAR rings land a few pixels apart, does not hide itself).
  int occlusion_radius_px = 2;
  double occlusion_tolerance_m = 0.3;
  double occlusion_tolerance_rel = 0.02;
};

// Points come back in the LiDAR frame, in the frame's order. Points behind every camera or
// outside every image are unobserved: no colour and no class (has_color and has_class false); a
// point seen by two cameras takes the one whose image centre it is nearer to. Frames without
// camera labels but with per-point classes (SemanticKITTI) take the class from the point labels.
// Ground-truth instances are copied from the point labels when present.
// Throws std::invalid_argument naming the camera when the frame's images do not match the rig
// (count, width x height, channels).
EnrichedCloud enrichFrame(const Frame& frame, const SensorRig& rig, const EnrichmentConfig& config);

// 8-bit RGB to HSV with hue in [0, 1).
void rgbToHsv(uint8_t r, uint8_t g, uint8_t b, float& h, float& s, float& v);

}  // namespace semsegmap
