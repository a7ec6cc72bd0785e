// The built-in simulator as a streaming FrameSource: frames are rendered on demand (LiDAR with
// ground truth, three cameras with label images, ground-truth and odometry poses), so the
// pipeline can consume simulated data without writing it to disk.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/sim/label_noise.h"
#include "semsegmap/sim/lidar_sim.h"
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
  // The rig's cameras to keep by name (left, front, right); empty: all. One front camera on a
  // 360-degree LiDAR (lidar hdl64) is the commonest real rig: a quarter of each scan in view.
  std::vector<std::string> camera_names;
  // Motion distortion: the LiDAR sweeps its columns over the frame period (hfov / 360 of it,
  // one turn per frame) while the vehicle drives on, each point in the LiDAR frame of its own
  // time, Frame::point_times filled. Off: every column at the frame's pose, as before.
  bool lidar_sweep = false;
  // Imperfect camera labels (sim/label_noise.h): 0 perfect, up to 3 worse than a good Cityscapes
  // model. The LiDAR points' ground truth stays exact.
  int label_noise = 0;
  // Off: the points' labels keep their instance ids but say class unknown, so that with
  // render_cameras off a frame is what a LiDAR without a camera gives, while the instance ground
  // truth that training needs is still there.
  bool point_classes = true;
  double agent_clearance_m = 6.0;
};

class Simulator : public FrameSource {
 public:
  explicit Simulator(const SimConfig& config);
  ~Simulator() override;

  const DatasetInfo& info() const override { return info_; }
  size_t size() const override;
  Frame frame(size_t index) override;
  double frameTime(size_t index) override;  // from the trajectory, without rendering

  const World& world() const { return *world_; }
  const Trajectory& trajectory() const { return trajectory_; }
  const Lighting& lighting() const { return lighting_; }
  uint64_t trafficSeed() const { return traffic_seed_; }
  const RayScene& scene() const { return *scene_; }

 private:
  LidarScan sweepLidar(size_t index, uint64_t seed) const;

  SimConfig config_;
  uint64_t traffic_seed_;
  std::unique_ptr<World> world_;
  std::unique_ptr<RayScene> scene_;
  Trajectory trajectory_;
  Lighting lighting_;
  DatasetInfo info_;
  LabelNoise label_noise_;
};

}  // namespace semsegmap::sim
