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

CameraRender renderCamera(const RayScene& scene, const Camera& camera, const Pose& T_world_camera,
                          const Lighting& lighting, uint64_t noise_seed, bool with_depth) {
  CameraRender out;
  out.rgb = Image(camera.width, camera.height, 3);
  out.label = Image(camera.width, camera.height, 1);
  if (with_depth) out.depth.assign(static_cast<size_t>(camera.width) * camera.height, 0.0f);
  const Eigen::Matrix3f R = T_world_camera.linear().cast<float>();
  const Eigen::Vector3f origin = T_world_camera.translation().cast<float>();

  constexpr int P = RayScene::kPacket;
#pragma omp parallel for schedule(dynamic, 4)
  for (int v = 0; v < camera.height; ++v) {
    for (int u0 = 0; u0 < camera.width; u0 += P) {
      // Eight neighbouring pixels of a row share one packet for the view rays and one for the
      // shadow rays.
      bool active[P], lit_candidate[P], shadowed[P];
      Eigen::Vector3f origins[P], dirs[P], rays_cam[P], points[P];
      RayHit hits[P];
      for (int k = 0; k < P; ++k) {
        active[k] = u0 + k < camera.width;
        rays_cam[k] = camera.pixelRay(u0 + k + 0.5, v + 0.5).cast<float>();
        dirs[k] = R * rays_cam[k];
        origins[k] = origin;
      }
      scene.intersect8(active, origins, dirs, 0.05f, 1e4f, hits);
      for (int k = 0; k < P; ++k) {
        lit_candidate[k] = hits[k].hit && hits[k].normal.dot(lighting.to_sun) > 0;
        if (hits[k].hit) {
          points[k] = origin + dirs[k] * hits[k].t;
          origins[k] = points[k] + hits[k].normal * 0.01f;
        }
      }
      scene.occluded8(lit_candidate, origins, lighting.to_sun, 0.0f, 1e4f, shadowed);

      for (int k = 0; k < P && u0 + k < camera.width; ++k) {
        const int u = u0 + k;
        const RayHit& hit = hits[k];
        Eigen::Vector3f color;
        ClassId label = cls::kSky;
        if (!hit.hit) {
          const float up = std::clamp(dirs[k].z(), 0.0f, 1.0f);
          color = (1 - up) * lighting.sky_horizon + up * lighting.sky_zenith;
        } else {
          const Surface& s = *hit.surface;
          label = s.class_id;
          float tex = 1.0f;
          if (s.texture > 0) tex = 1.0f + s.texture * (2.0f * valueNoise(points[k], 1.7f) - 1.0f);
          const float direct =
              lit_candidate[k] && !shadowed[k] ? hit.normal.dot(lighting.to_sun) : 0.0f;
          const Eigen::Vector3f light = lighting.ambient + lighting.sun_color * direct;
          color = (s.albedo * tex).cwiseProduct(light) * lighting.exposure;
          if (with_depth)
            out.depth[static_cast<size_t>(v) * camera.width + u] = hit.t * rays_cam[k].z();
        }
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
  }
  return out;
}

}  // namespace semsegmap::sim
