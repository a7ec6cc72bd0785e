// Lighting conditions: where the sun is, its colour, the ambient sky light and the camera
// exposure. The same wall gets different RGB under two conditions but a similar hue.
#pragma once

#include <string>

#include <Eigen/Core>

namespace semsegmap::sim {

struct Lighting {
  std::string name;
  Eigen::Vector3f to_sun{0, 0, 1};  // unit vector towards the sun
  Eigen::Vector3f sun_color{1, 1, 1};
  Eigen::Vector3f ambient{0.3f, 0.3f, 0.3f};
  float exposure = 1.0f;
  Eigen::Vector3f sky_horizon{0.75f, 0.85f, 0.95f};
  Eigen::Vector3f sky_zenith{0.3f, 0.5f, 0.85f};
};

// "sunny" (high sun, white light, hard shadows) or "sunrise" (low sun from another side, warm
// tint, long shadows, lower exposure). Throws std::invalid_argument for anything else.
Lighting lightingFor(const std::string& condition);

}  // namespace semsegmap::sim
