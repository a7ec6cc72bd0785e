// The [fleet] experiment: the runs of one simulated world mapped as sessions, each on its own
// LiDAR odometry and so in its own frame, joined into one map (pipeline/session_merge.h), and
// judged against the simulator's ground truth:
// - where the merged map's entries are: each entry's true centroid is its centroid carried from
//   the pose its session's frame got in the map to that frame's true pose; after one rigid
//   alignment of the whole map to the world (its drift is the first session's odometry's), the
//   mean distance between the two;
// - what the merged map is worth to a robot: a further run localized against it and against the
//   first session's map alone, frames within 1 m counted in the world (through the alignment).
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/json.h"
#include "semsegmap/eval/experiment.h"
#include "semsegmap/localize/target_map.h"

namespace semsegmap {

struct FleetExperimentConfig {
  uint64_t world_seed = 1;
  std::string preset = "small";
  size_t max_frames = 0;  // per run; 0: all
  std::vector<std::string> sessions = {"S0", "S1", "S2", "S3"};
  // Runs localized against the merged map and the first session's: "S0,traffic=7" is run S0
  // with traffic seed 7 (more simulator keys after the run, as in a dataset spec).
  std::vector<std::string> queries = {"S0,traffic=7"};
  std::filesystem::path config;  // the pipeline configuration (its odometry: section too)
  double wrong_m = 5.0;          // a localization farther off is wrong
  ExperimentProgress progress;
  StopToken stop;
};

struct FleetSession {
  std::string run;
  bool aligned = false;  // the first always: it is the map's frame
  size_t frames = 0, ties = 0, entries = 0, same_segments = 0;
  double tie_residual_m = 0.0;
  // After the one alignment of the whole map to the world: its frames' and its entries' mean
  // distances from the truth.
  double trajectory_error_m = 0.0, centroid_error_m = 0.0;
};

struct FleetQuery {
  std::string run;
  size_t frames = 0;
  // Against the merged map, and against the first session's map alone.
  size_t localizations_merged = 0, within_1m_merged = 0, wrong_merged = 0;
  size_t localizations_first = 0, within_1m_first = 0, wrong_first = 0;
};

struct FleetExperiment {
  FleetExperimentConfig config;
  std::vector<FleetSession> sessions;
  size_t entries = 0, segments = 0;  // of the merged map
  double centroid_mean_m = 0.0, centroid_median_m = 0.0;
  Pose T_world_map = Pose::Identity();
  std::vector<FleetQuery> queries;
  TargetMap merged;
  // Per aligned session (in order): its frames' poses in the map, and their true poses.
  std::vector<std::vector<Pose>> trajectories, truths;
  bool interrupted = false;
};

FleetExperiment runFleetExperiment(const FleetExperimentConfig& config);

// The results as a Markdown table, and as JSON (fleet.json).
std::string fleetTable(const FleetExperiment& e);
nlohmann::ordered_json toJson(const FleetExperiment& e);

// fleet.json, fleet.map (the merged map), fleet.md (the table) and fleet.png (each session's
// trajectory in the world through the one alignment, over the truth in grey) into `dir`.
void writeFleetExperiment(const FleetExperiment& e, const std::filesystem::path& dir);

}  // namespace semsegmap
