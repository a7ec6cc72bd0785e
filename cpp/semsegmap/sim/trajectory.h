// The paper's runs on the road network (S0 whole map, S1 training run with revisits, S2 one
// small loop, S3 = S2 reversed) as ground-truth poses at the frame rate, and odometry with drift.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "semsegmap/core/pose.h"
#include "semsegmap/sim/world.h"

namespace semsegmap::sim {

enum class Run { S0, S1, S2, S3 };
Run parseRun(const std::string& name);  // throws std::invalid_argument
std::string runName(Run run);
// The condition the paper used for each run: S3 at sunrise, the others sunny.
std::string defaultCondition(Run run);

// Sequence of grid intersections (i, j) a run drives through; loops start and end at the same node.
std::vector<std::pair<int, int>> routeNodes(Run run, int grid_nodes);

struct TrajectoryConfig {
  double speed_mps = 5.0;
  double rate_hz = 5.0;
  double lane_variation_m = 0.3;  // slow weave inside the lane
  double corner_cut_m = 9.0;      // turns start this far before the intersection
  // The loop driven this many times without stopping (S2 and S3 only, the closed loops): a long
  // run for checking that memory stays flat over many kilometres.
  int laps = 1;
};

// Odometry drift: a constant scale error and yaw bias per run (signs drawn from the seed), plus
// small random-walk noise; defaults about 1 % of distance and 0.05 degrees per metre.
struct OdometryNoise {
  double scale_error = 0.01;
  double yaw_bias_deg_per_m = 0.05;
  double translation_noise_m_per_sqrt_m = 0.01;
  double yaw_noise_deg_per_sqrt_m = 0.02;
};

struct Trajectory {
  std::vector<double> timestamps_s;
  std::vector<Pose> T_world_base;
  std::vector<Pose> T_odom_base;
  double length_m = 0.0;
};

Trajectory makeTrajectory(const RoadNetwork& roads, Run run, const TrajectoryConfig& config,
                          const OdometryNoise& odometry, uint64_t seed);

// Odometry from ground truth: relative motions corrupted as OdometryNoise says, integrated
// from the first ground-truth pose.
std::vector<Pose> driftingOdometry(const std::vector<Pose>& gt, const OdometryNoise& noise,
                                   uint64_t seed);

}  // namespace semsegmap::sim
