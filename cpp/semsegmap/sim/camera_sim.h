// Renders one pinhole camera: shaded RGB (albedo x (ambient + diffuse x shadow-ray visibility)
// x light colour x exposure), the class-label image, and optionally depth, all from the same
// sample at each pixel centre so that labels and colours agree exactly.
#pragma once

#include <cstdint>
#include <vector>

#include "semsegmap/core/image.h"
#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/sim/lighting.h"
#include "semsegmap/sim/ray_scene.h"

namespace semsegmap::sim {

struct CameraRender {
  Image rgb;
  Image label;
  std::vector<float> depth;  // z in the camera frame, 0 where the sky is seen; only on request
};

CameraRender renderCamera(const RayScene& scene, const Camera& camera, const Pose& T_world_camera,
                          const Lighting& lighting, uint64_t noise_seed, bool with_depth = false);

}  // namespace semsegmap::sim
