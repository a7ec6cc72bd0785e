#include "semsegmap/sim/lighting.h"

#include <cmath>
#include <stdexcept>

namespace semsegmap::sim {

namespace {
Eigen::Vector3f sunDirection(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * M_PI / 180.0, e = elevation_deg * M_PI / 180.0;
  return Eigen::Vector3f(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}
}  // namespace

Lighting lightingFor(const std::string& condition) {
  Lighting l;
  l.name = condition;
  if (condition == "sunny") {
    l.to_sun = sunDirection(-135.0, 58.0);
    l.sun_color = {1.0f, 0.98f, 0.95f};
    l.ambient = {0.26f, 0.28f, 0.32f};
    l.exposure = 1.0f;
    l.sky_horizon = {0.75f, 0.85f, 0.95f};
    l.sky_zenith = {0.25f, 0.45f, 0.85f};
    return l;
  }
  if (condition == "sunrise") {
    l.to_sun = sunDirection(20.0, 9.0);
    l.sun_color = {1.0f, 0.72f, 0.45f};
    l.ambient = {0.2f, 0.18f, 0.2f};
    l.exposure = 0.8f;
    l.sky_horizon = {0.95f, 0.7f, 0.5f};
    l.sky_zenith = {0.35f, 0.4f, 0.65f};
    return l;
  }
  throw std::invalid_argument("unknown condition '" + condition + "' (expected sunny or sunrise)");
}

}  // namespace semsegmap::sim
