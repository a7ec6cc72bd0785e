#include "semsegmap/sim/simulator.h"

#include <algorithm>
#include <stdexcept>

#include <Eigen/Geometry>

#include "semsegmap/core/random.h"
#include "semsegmap/sim/camera_sim.h"
#include "semsegmap/sim/lidar_sim.h"

namespace semsegmap::sim {

namespace {

// Only the named cameras stay on the rig, in the rig's order; a name the rig lacks is refused.
void keepCameras(const std::vector<std::string>& names, SensorRig& rig) {
  if (names.empty()) return;
  std::string known;
  for (const Camera& c : rig.cameras) known += (known.empty() ? "" : ", ") + c.name;
  for (const std::string& n : names)
    if (std::none_of(rig.cameras.begin(), rig.cameras.end(),
                     [&](const Camera& c) { return c.name == n; }))
      throw std::invalid_argument("simulator: no camera '" + n + "' on the rig (" + known + ")");
  rig.cameras.erase(std::remove_if(rig.cameras.begin(), rig.cameras.end(),
                                   [&](const Camera& c) {
                                     return std::find(names.begin(), names.end(), c.name) ==
                                            names.end();
                                   }),
                    rig.cameras.end());
}

}  // namespace

Simulator::Simulator(const SimConfig& config)
    : config_(config),
      traffic_seed_(config.traffic_seed ? *config.traffic_seed
                                        : static_cast<uint64_t>(config.run) + 1),
      world_(std::make_unique<World>(generateWorld(config.world, traffic_seed_))),
      scene_(std::make_unique<RayScene>(*world_)),
      lighting_(
          lightingFor(config.condition.empty() ? defaultCondition(config.run) : config.condition)) {
  config_.rig.validate();
  config_.trajectory.rate_hz = config_.rig.rate_hz;
  trajectory_ = makeTrajectory(world_->roads, config.run, config_.trajectory, config_.odometry,
                               hashKeys(config.world.seed, static_cast<uint64_t>(config.run)));
  info_.name =
      "sim world " + std::to_string(config.world.seed) + " run " + runName(config.run) + " " +
      lighting_.name + " traffic " + std::to_string(traffic_seed_) +
      (config.label_noise > 0 ? " label noise " + std::to_string(config.label_noise) : "") +
      (config.point_classes ? "" : " no point classes");
  label_noise_ = labelNoiseOfLevel(config.label_noise);
  info_.rig = config_.rig;
  if (!config_.render_cameras) info_.rig.cameras.clear();
  keepCameras(config_.camera_names, info_.rig);
  info_.classes = ClassTable::Default();
  info_.has_ground_truth_poses = true;
  info_.has_odometry = true;  // the simulated drifting odometry
  info_.has_point_labels = true;
  info_.point_labels_have_classes = config_.point_classes;
  info_.first_transient_instance = kTrafficInstanceBase;
  info_.origin.kind = "sim";
  info_.origin.lidar = "rendered, " + std::to_string(info_.rig.lidar.columns) + " x " +
                       std::to_string(info_.rig.lidar.rows) + " beams";
  info_.origin.cameras.assign(info_.rig.cameras.size(), "rendered");
  info_.origin.odometry = "the simulator's drifting odometry";
  info_.origin.ground_truth = "the simulator's poses";
  if (!info_.rig.cameras.empty())
    info_.origin.label_images = config_.label_noise > 0 ? "rendered, with label noise" : "rendered";
  info_.origin.point_labels =
      config_.point_classes ? "the simulator's" : "the simulator's instances, no classes";
}

Simulator::~Simulator() = default;

size_t Simulator::size() const {
  const size_t n = trajectory_.T_world_base.size();
  return config_.max_frames > 0 ? std::min(n, config_.max_frames) : n;
}

namespace {

// The base's pose a time t after frame `index`, at the motion between it and the next frame (the
// one before it for the last frame): constant velocity over one frame, as the vehicle drives.
Pose baseAt(const Trajectory& trajectory, size_t index, double t) {
  const size_t n = trajectory.T_world_base.size();
  const size_t a = index + 1 < n ? index : (index > 0 ? index - 1 : index);
  const size_t b = std::min(a + 1, n - 1);
  const double period = trajectory.timestamps_s[b] - trajectory.timestamps_s[a];
  if (a == b || !(period > 0)) return trajectory.T_world_base[index];
  const Pose delta = trajectory.T_world_base[a].inverse() * trajectory.T_world_base[b];
  const double s = (trajectory.timestamps_s[index] + t - trajectory.timestamps_s[a]) / period;
  const Eigen::AngleAxisd rotation(delta.linear());
  Pose step = Pose::Identity();
  step.linear() = Eigen::AngleAxisd(rotation.angle() * s, rotation.axis()).toRotationMatrix();
  step.translation() = delta.translation() * s;
  return trajectory.T_world_base[a] * step;
}

}  // namespace

// The moving agents stay where they are at the frame's time during the sweep: only the
// vehicle's own motion distorts the scan.
LidarScan Simulator::sweepLidar(size_t index, uint64_t seed) const {
  const LidarModel& lidar = config_.rig.lidar;
  const double sweep_s = lidar.hfov_deg / 360.0 / config_.rig.rate_hz;
  std::vector<Pose> poses(static_cast<size_t>(lidar.columns));
  std::vector<float> times(poses.size());
  for (size_t c = 0; c < poses.size(); ++c) {
    times[c] = static_cast<float>(sweep_s * static_cast<double>(c) / lidar.columns);
    poses[c] = baseAt(trajectory_, index, times[c]) * config_.rig.T_base_lidar;
  }
  return simulateLidarSweep(*scene_, lidar, poses, times, seed);
}

double Simulator::frameTime(size_t index) {
  if (index >= size()) throwFrameOutOfRange(info_.name, index, size());
  return trajectory_.timestamps_s[index];
}

Frame Simulator::frame(size_t index) {
  if (index >= size()) throwFrameOutOfRange(info_.name, index, size());
  Frame f;
  f.index = index;
  f.timestamp_s = trajectory_.timestamps_s[index];
  f.T_world_base = trajectory_.T_world_base[index];
  f.T_odom_base = trajectory_.T_odom_base[index];
  const Pose& T_world_base = *f.T_world_base;
  scene_->setTime(f.timestamp_s, T_world_base.translation().head<2>(), config_.agent_clearance_m);

  const uint64_t seed =
      hashKeys(config_.world.seed, traffic_seed_, static_cast<uint64_t>(config_.run), index);
  const Pose T_world_lidar = T_world_base * config_.rig.T_base_lidar;
  LidarScan scan = config_.lidar_sweep
                       ? sweepLidar(index, seed)
                       : simulateLidar(*scene_, config_.rig.lidar, T_world_lidar, seed);
  f.points = std::move(scan.points);
  f.point_labels = std::move(scan.labels);
  if (!config_.point_classes)
    for (PointLabel& l : f.point_labels) l.class_id = cls::kUnknown;
  f.point_times = std::move(scan.times);
  for (size_t c = 0; c < info_.rig.cameras.size(); ++c) {
    const Camera& cam = info_.rig.cameras[c];
    CameraRender r = renderCamera(*scene_, cam, T_world_lidar * cam.T_camera_lidar.inverse(),
                                  lighting_, hashKeys(seed, c + 1));
    if (config_.label_noise > 0)
      r.label = applyLabelNoise(r.label, label_noise_, hashKeys(seed, c + 1, 0x6e6f697365));
    f.cameras.push_back({std::move(r.rgb), std::move(r.label), std::nullopt});
  }
  return f;
}

}  // namespace semsegmap::sim
