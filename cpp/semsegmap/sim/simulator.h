// The built-in simulator as a streaming FrameSource: frames are rendered on demand (LiDAR with
// ground truth, three cameras with label images, ground-truth and odometry poses), so the
// pipeline can consume simulated data without writing it to disk.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/sim/lighting.h"
#include "semsegmap/sim/ray_scene.h"
#include "semsegmap/sim/trajectory.h"
#include "semsegmap/sim/world.h"

namespace semsegmap::sim {

struct SimConfig {
  WorldConfig world;
  Run run = Run::S2;
  std::string condition;                 // empty: the run's default (S3 sunrise, others sunny)
  std::optional<uint64_t> traffic_seed;  // empty: one per run, so runs see different cars
  size_t max_frames = 0;                 // 0: the whole run
  SensorRig rig = defaultSimRig();
  TrajectoryConfig trajectory;
  OdometryNoise odometry;
  bool render_cameras = true;
  double agent_clearance_m = 6.0;
};

class Simulator : public FrameSource {
 public:
  explicit Simulator(const SimConfig& config);
  ~Simulator() override;

  const DatasetInfo& info() const override { return info_; }
  size_t size() const override;
  Frame frame(size_t index) override;

  const World& world() const { return *world_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const Lighting& lighting() const { return lighting_; }
  uint64_t trafficSeed() const { return traffic_seed_; }
  const RayScene& scene() const { return *scene_; }

 private:
  SimConfig config_;
  uint64_t traffic_seed_;
  std::unique_ptr<World> world_;
  std::unique_ptr<RayScene> scene_;
  Trajectory trajectory_;
  Lighting lighting_;
  DatasetInfo info_;
};

}  // namespace semsegmap::sim
