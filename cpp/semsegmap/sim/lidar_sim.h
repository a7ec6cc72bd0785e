// Simulates one LiDAR sweep: a ray per beam, Gaussian range noise and random dropouts, with the
// ground-truth class and instance of what each beam hit.
#pragma once

#include <cstdint>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/sim/ray_scene.h"

namespace semsegmap::sim {

struct LidarScan {
  std::vector<LidarPoint> points;  // LiDAR frame, ordered by column then row
  std::vector<PointLabel> labels;  // one per point
  std::vector<float> times;        // a sweep's: one per point (the column's); else empty
};

LidarScan simulateLidar(const RayScene& scene, const LidarModel& lidar, const Pose& T_world_lidar,
                        uint64_t noise_seed);

// A sweep while the sensor moves, as a spinning LiDAR measures: column c is measured at
// column_times[c] from T_world_lidar_columns[c], and its points are in the LiDAR frame of that
// moment. Both vectors have one entry per column.
LidarScan simulateLidarSweep(const RayScene& scene, const LidarModel& lidar,
                             const std::vector<Pose>& T_world_lidar_columns,
                             const std::vector<float>& column_times, uint64_t noise_seed);

}  // namespace semsegmap::sim
