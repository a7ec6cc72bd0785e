// Procedural brightness variation on surfaces (grass, asphalt, foliage), a smooth value noise
// of the world position, so that the same place looks the same from every viewpoint.
#pragma once

#include <Eigen/Core>

namespace semsegmap::sim {

// Smooth noise in [0, 1] with features about 1/frequency metres across.
float valueNoise(const Eigen::Vector3f& p, float frequency);

}  // namespace semsegmap::sim
