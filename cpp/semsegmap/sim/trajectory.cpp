#include "semsegmap/sim/trajectory.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "semsegmap/core/random.h"
#include "semsegmap/sim/polyline.h"

namespace semsegmap::sim {

Run parseRun(const std::string& name) {
  if (name == "S0") return Run::S0;
  if (name == "S1") return Run::S1;
  if (name == "S2") return Run::S2;
  if (name == "S3") return Run::S3;
  throw std::invalid_argument("unknown run '" + name + "' (expected S0, S1, S2 or S3)");
}

std::string runName(Run run) {
  const char* names[] = {"S0", "S1", "S2", "S3"};
  return names[static_cast<int>(run)];
}

std::string defaultCondition(Run run) {
  return run == Run::S3 ? "sunrise" : "sunny";
}

std::vector<std::pair<int, int>> routeNodes(Run run, int n) {
  // S2 circles the block just below and left of the centre; S0 drives the outer ring, then
  // that block in the same direction; S1 circles and crosses the 2 x 2 blocks in the upper
  // right, revisiting streets in both directions.
  const int b = std::max(0, n / 2 - 1);
  const std::vector<std::pair<int, int>> block = {
      {b, b}, {b + 1, b}, {b + 1, b + 1}, {b, b + 1}, {b, b}};
  switch (run) {
    case Run::S2:
      return block;
    case Run::S3:
      return {block.rbegin(), block.rend()};
    case Run::S0: {
      // Starts on the west street at the block's row, so no turn is a U-turn.
      std::vector<std::pair<int, int>> r;
      for (int j = b; j > 0; --j) r.emplace_back(0, j);
      for (int i = 0; i < n; ++i) r.emplace_back(i, 0);
      for (int j = 1; j < n; ++j) r.emplace_back(n - 1, j);
      for (int i = n - 2; i >= 0; --i) r.emplace_back(i, n - 1);
      for (int j = n - 2; j > b; --j) r.emplace_back(0, j);
      for (int i = 0; i < b; ++i) r.emplace_back(i, b);
      r.insert(r.end(), block.begin(), block.end());
      return r;
    }
    case Run::S1: {
      const int c = n - 3;
      return {{c, c},         {c + 1, c},     {c + 2, c},     {c + 2, c + 1}, {c + 2, c + 2},
              {c + 1, c + 2}, {c, c + 2},     {c, c + 1},     {c, c},         {c + 1, c},
              {c + 1, c + 1}, {c + 1, c + 2}, {c + 2, c + 2}, {c + 2, c + 1}, {c + 1, c + 1},
              {c, c + 1},     {c, c}};
    }
  }
  return {};
}

std::vector<Pose> driftingOdometry(const std::vector<Pose>& gt, const OdometryNoise& noise,
                                   uint64_t seed) {
  std::vector<Pose> odom;
  if (gt.empty()) return odom;
  SeededRng rng(hashKeys(seed, 0x0d0));
  const double scale = 1.0 + (rng.chance(0.5) ? 1 : -1) * noise.scale_error;
  const double yaw_bias = (rng.chance(0.5) ? 1 : -1) * noise.yaw_bias_deg_per_m * M_PI / 180.0;
  odom.push_back(gt.front());
  for (size_t k = 1; k < gt.size(); ++k) {
    const Pose delta = gt[k - 1].inverse() * gt[k];
    const double dist = delta.translation().norm();
    Pose noisy = delta;
    const double sq = std::sqrt(dist);
    noisy.translation() =
        delta.translation() * scale +
        Eigen::Vector3d(rng.gaussian(noise.translation_noise_m_per_sqrt_m * sq),
                        rng.gaussian(noise.translation_noise_m_per_sqrt_m * sq), 0.0);
    const double dyaw =
        yaw_bias * dist + rng.gaussian(noise.yaw_noise_deg_per_sqrt_m * M_PI / 180.0 * sq);
    noisy.linear() =
        delta.linear() * Eigen::AngleAxisd(dyaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    odom.push_back(odom.back() * noisy);
  }
  return odom;
}

Trajectory makeTrajectory(const RoadNetwork& roads, Run run, const TrajectoryConfig& config,
                          const OdometryNoise& odometry, uint64_t seed) {
  // S3 is S2's centre line driven backwards (so it starts where S2 ends), in the other lane.
  const auto nodes = routeNodes(run == Run::S3 ? Run::S2 : run, roads.grid_nodes);
  Polyline center;
  for (const auto& [i, j] : nodes) center.push_back(roads.nodes[roads.node(i, j)]);
  const bool loop = run == Run::S2 || run == Run::S3;
  if (loop) {
    // Start and finish halfway along the first street, so every corner is a smooth turn.
    const Eigen::Vector2d mid = 0.5 * (center[0] + center[1]);
    center.front() = mid;
    center.insert(center.end() - 1,
                  roads.nodes[roads.node(nodes.front().first, nodes.front().second)]);
    center.back() = mid;
    // center is now: mid, n1, ..., n_{k-1}, n0, mid
  }
  if (run == Run::S3) std::reverse(center.begin(), center.end());
  // Right-hand traffic: drive a quarter of the road width right of the centre line.
  const Polyline lane = roundCorners(offsetPolyline(center, -0.25 * roads.road_width_m, false),
                                     config.corner_cut_m, 0.25);
  const double lap = polylineLength(lane, false);
  if (config.laps < 1 || (config.laps > 1 && !loop))
    throw std::invalid_argument("run " + runName(run) + ": laps=" + std::to_string(config.laps) +
                                " (more than one lap needs a closed loop: S2 or S3)");
  const double length = lap * config.laps;
  SeededRng rng(hashKeys(seed, 0x7a1));
  const double phase = rng.uniform(0.0, 2.0 * M_PI);
  // The loop's lane ends where it starts, so a position past the lap wraps onto the next one.
  auto positionAt = [&](double s) {
    const PolylinePoint p = pointAt(lane, s <= lap ? s : std::fmod(s, lap), false);
    const Eigen::Vector2d left(-std::sin(p.heading), std::cos(p.heading));
    return (p.position + left * (config.lane_variation_m * std::sin(2.0 * M_PI * s / 70.0 + phase)))
        .eval();
  };

  Trajectory traj;
  traj.length_m = length;
  const double step = config.speed_mps / config.rate_hz;
  for (size_t k = 0;; ++k) {
    const double s = k * step;
    if (s > length) break;
    const Eigen::Vector2d p = positionAt(s);
    const Eigen::Vector2d d =
        positionAt(std::min(s + 0.5, length)) - positionAt(std::max(s - 0.5, 0.0));
    traj.timestamps_s.push_back(k / config.rate_hz);
    traj.T_world_base.push_back(planarPose(p.x(), p.y(), 0.0, std::atan2(d.y(), d.x())));
  }
  traj.T_odom_base = driftingOdometry(traj.T_world_base, odometry, seed);
  return traj;
}

}  // namespace semsegmap::sim
