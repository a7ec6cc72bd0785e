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
};

LidarScan simulateLidar(const RayScene& scene, const LidarModel& lidar, const Pose& T_world_lidar,
                        uint64_t noise_seed);

}  // namespace semsegmap::sim
