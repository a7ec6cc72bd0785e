#include "semsegmap/sim/texture.h"

#include <cmath>

#include <cstdint>

namespace semsegmap::sim {

namespace {
// One multiply-xorshift round is plenty for texture and eight of these run per shaded pixel.
float lattice(int x, int y, int z) {
  uint32_t h = static_cast<uint32_t>(x) * 0x8da6b343u ^ static_cast<uint32_t>(y) * 0xd8163841u ^
               static_cast<uint32_t>(z) * 0xcb1ab31fu;
  h ^= h >> 15;
  h *= 0x2c1b3c6du;
  h ^= h >> 12;
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}
float smooth(float t) {
  return t * t * (3.0f - 2.0f * t);
}
}  // namespace

float valueNoise(const Eigen::Vector3f& p, float frequency) {
  const Eigen::Vector3f q = p * frequency;
  const int x0 = static_cast<int>(std::floor(q.x()));
  const int y0 = static_cast<int>(std::floor(q.y()));
  const int z0 = static_cast<int>(std::floor(q.z()));
  const float fx = smooth(q.x() - x0), fy = smooth(q.y() - y0), fz = smooth(q.z() - z0);
  float v = 0.0f;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const float w = (dx ? fx : 1 - fx) * (dy ? fy : 1 - fy) * (dz ? fz : 1 - fz);
        v += w * lattice(x0 + dx, y0 + dy, z0 + dz);
      }
  return v;
}

}  // namespace semsegmap::sim
