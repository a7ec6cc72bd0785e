#include "semsegmap/sim/camera_sim.h"

#include <algorithm>
#include <cmath>

#include "semsegmap/core/random.h"
#include "semsegmap/sim/texture.h"

namespace semsegmap::sim {

namespace {

// Display gamma, so that images look like a camera's and HSV behaves as on real images; a table
// because three pow() per pixel cost more than the shading.
struct GammaTable {
  static constexpr int kSize = 4096;
  uint8_t value[kSize + 1];
  GammaTable() {
    for (int k = 0; k <= kSize; ++k)
      value[k] = static_cast<uint8_t>(
          std::lround(std::pow(static_cast<float>(k) / kSize, 1.0f / 2.2f) * 255.0f));
  }
};

uint8_t toByte(float linear) {
  static const GammaTable table;
  const float x = std::clamp(linear, 0.0f, 1.0f);
  return table.value[static_cast<int>(x * GammaTable::kSize + 0.5f)];
}

}  // namespace

CameraRender renderCamera(const RayScene& scene, const PinholeCamera& camera,
                          const Pose& T_world_camera, const Lighting& lighting, uint64_t noise_seed,
                          bool with_depth) {
  CameraRender out;
  out.rgb = Image(camera.width, camera.height, 3);
  out.label = Image(camera.width, camera.height, 1);
  if (with_depth) out.depth.assign(static_cast<size_t>(camera.width) * camera.height, 0.0f);
  const Eigen::Matrix3f R = T_world_camera.linear().cast<float>();
  const Eigen::Vector3f origin = T_world_camera.translation().cast<float>();

#pragma omp parallel for schedule(dynamic, 4)
  for (int v = 0; v < camera.height; ++v) {
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3f ray_cam = camera.pixelRay(u + 0.5, v + 0.5).cast<float>();
      const Eigen::Vector3f dir = R * ray_cam;
      const RayHit hit = scene.intersect(origin, dir, 0.05f, 1e4f);
      Eigen::Vector3f color;
      ClassId label = cls::kSky;
      if (!hit.hit) {
        const float up = std::clamp(dir.z(), 0.0f, 1.0f);
        color = (1 - up) * lighting.sky_horizon + up * lighting.sky_zenith;
      } else {
        const Surface& s = *hit.surface;
        label = s.class_id;
        const Eigen::Vector3f p = origin + dir * hit.t;
        float tex = 1.0f;
        if (s.texture > 0) tex = 1.0f + s.texture * (2.0f * valueNoise(p, 1.7f) - 1.0f);
        const float cos_sun = hit.normal.dot(lighting.to_sun);
        float direct = 0.0f;
        if (cos_sun > 0 && !scene.occluded(p + hit.normal * 0.01f, lighting.to_sun, 0.0f, 1e4f))
          direct = cos_sun;
        const Eigen::Vector3f light = lighting.ambient + lighting.sun_color * direct;
        color = (s.albedo * tex).cwiseProduct(light) * lighting.exposure;
        if (with_depth) out.depth[static_cast<size_t>(v) * camera.width + u] = hit.t * ray_cam.z();
      }
      // A little sensor noise, a pure function of the seed and the pixel.
      const uint64_t h =
          hashMix(noise_seed ^ (static_cast<uint64_t>(v) << 32 | static_cast<uint64_t>(u)));
      // Triangular noise (sum of two uniforms): close enough to Gaussian, far cheaper.
      const float n =
          0.006f * static_cast<float>(uniformFromHash(h) + uniformFromHash(hashMix(h)) - 1.0);
      uint8_t* px = out.rgb.at(u, v);
      for (int c = 0; c < 3; ++c) px[c] = toByte(color[c] + n);
      *out.label.at(u, v) = static_cast<uint8_t>(label);
    }
  }
  return out;
}

}  // namespace semsegmap::sim
