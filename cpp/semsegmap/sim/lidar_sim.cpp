#include "semsegmap/sim/lidar_sim.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "semsegmap/core/random.h"

namespace semsegmap::sim {

namespace {

// Every beam of the scan; column c is cast from poses[c], or from poses[0] when there is one
// pose (a scan without motion, computed exactly as before sweeps existed). With column_times,
// each point gets its column's time.
LidarScan castBeams(const RayScene& scene, const LidarModel& lidar, const std::vector<Pose>& poses,
                    const std::vector<float>* column_times, uint64_t noise_seed) {
  const int n = lidar.columns * lidar.rows;
  // Every beam writes its own slot; compacting afterwards in beam order keeps the output
  // independent of thread scheduling.
  std::vector<LidarPoint> slots(n);
  std::vector<PointLabel> slot_labels(n);
  std::vector<uint8_t> valid(n, 0);

#pragma omp parallel for schedule(dynamic, 16)
  for (int col = 0; col < lidar.columns; ++col) {
    const Pose& T_world_lidar = poses[poses.size() == 1 ? 0 : static_cast<size_t>(col)];
    const Eigen::Matrix3f R = T_world_lidar.linear().cast<float>();
    const Eigen::Vector3f origin = T_world_lidar.translation().cast<float>();
    for (int row = 0; row < lidar.rows; ++row) {
      const int k = col * lidar.rows + row;
      const uint64_t h = hashKeys(noise_seed, static_cast<uint64_t>(k));
      if (uniformFromHash(h) < lidar.dropout) continue;
      const Eigen::Vector3f d_lidar = lidar.beamDirection(row, col).cast<float>();
      const RayHit hit = scene.intersect(origin, R * d_lidar, static_cast<float>(lidar.min_range_m),
                                         static_cast<float>(lidar.max_range_m));
      if (!hit.hit) continue;
      const double range = hit.t + lidar.range_noise_m * gaussianFromHash(hashMix(h));
      if (range < lidar.min_range_m || range > lidar.max_range_m) continue;
      const Eigen::Vector3f p = d_lidar * static_cast<float>(range);
      // Intensity: a Lambertian return of the surface's brightness.
      const float cos_inc = std::abs(hit.normal.dot(R * d_lidar));
      const float reflect = hit.surface->albedo.mean();
      slots[k] = {p.x(), p.y(), p.z(), std::clamp(reflect * (0.3f + 0.7f * cos_inc), 0.0f, 1.0f)};
      slot_labels[k] = {hit.surface->class_id, hit.surface->instance_id};
      valid[k] = 1;
    }
  }
  LidarScan scan;
  scan.points.reserve(n);
  scan.labels.reserve(n);
  for (int k = 0; k < n; ++k) {
    if (!valid[k]) continue;
    scan.points.push_back(slots[k]);
    scan.labels.push_back(slot_labels[k]);
    if (column_times) scan.times.push_back((*column_times)[static_cast<size_t>(k / lidar.rows)]);
  }
  return scan;
}

}  // namespace

LidarScan simulateLidar(const RayScene& scene, const LidarModel& lidar, const Pose& T_world_lidar,
                        uint64_t noise_seed) {
  return castBeams(scene, lidar, {T_world_lidar}, nullptr, noise_seed);
}

LidarScan simulateLidarSweep(const RayScene& scene, const LidarModel& lidar,
                             const std::vector<Pose>& T_world_lidar_columns,
                             const std::vector<float>& column_times, uint64_t noise_seed) {
  const size_t columns = static_cast<size_t>(lidar.columns);
  if (T_world_lidar_columns.size() != columns || column_times.size() != columns)
    throw std::invalid_argument("simulateLidarSweep: " + std::to_string(columns) + " columns but " +
                                std::to_string(T_world_lidar_columns.size()) + " poses and " +
                                std::to_string(column_times.size()) + " times");
  return castBeams(scene, lidar, T_world_lidar_columns, &column_times, noise_seed);
}

}  // namespace semsegmap::sim
