// What a localization run leaves beside localizations.csv for looking at it afterwards
// (`semsegmap view`), and reading such a folder back:
// - matches.csv: frame, local_x/y/z (a matched local segment's centroid carried into the map by
//   the localization's pose), target_x/y/z (the target map segment's centroid it matched), one
//   row per inlier match: a few dozen bytes per match, about 20 matches per localization;
// - trajectory.csv: frame, dataset_frame and timestamp (as in localizations.csv, empty where
//   the data has none), odom_x/y/z/qx/qy/qz/qw (T_odom_base, the robot's own estimate, on
//   which the local map was built) and gt_x/.../gt_qw (T_world_base, empty without ground
//   truth), one row per frame run: between two localizations the robot's pose in the map is its
//   odometry carried by the last localization.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"
#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

// matches.csv and trajectory.csv of `run` in `dir` (atomic writes).
void writeLocalizationDetails(const std::filesystem::path& dir, const LocalizationRun& run);

struct LocalizationRow {                // a line of localizations.csv
  size_t frame = 0;                     // the run's index
  std::optional<size_t> dataset_frame;  // the dataset's own number (version 2, when it has one)
  std::optional<double> timestamp_s;    // the data's time (version 1 made one up when none)
  Pose T_map_base = Pose::Identity();
  int inliers = 0;
  std::optional<double> translation_error_m, rotation_error_deg;  // with ground truth
  std::optional<double> refinement_m;                             // when pose refinement moved it
};

struct MatchRow {
  size_t frame = 0;
  Eigen::Vector3f local = Eigen::Vector3f::Zero(), target = Eigen::Vector3f::Zero();
};

struct TrajectoryRow {
  size_t frame = 0;
  std::optional<size_t> dataset_frame;  // as in LocalizationRow; older files have neither
  std::optional<double> timestamp_s;
  Pose T_odom_base = Pose::Identity();
  std::optional<Pose> T_world_base;
};

// A folder written by `semsegmap localize` or an experiment (eval, demo).
struct LocalizationFolder {
  std::filesystem::path dir;
  std::vector<LocalizationRow> localizations;
  std::vector<MatchRow> matches;
  std::vector<TrajectoryRow> trajectory;
  bool has_matches = false, has_trajectory = false;  // older folders have neither file
  std::string dataset, map, config;                  // from summary.json, when there
  std::string schema;  // summary.json's, "semsegmap.localization/1" for files that do not say
};

// Throws std::runtime_error "<dir>: ..." for a folder that is missing or has no
// localizations.csv, and the CsvTable errors ("<file>:<line>: ...") for a malformed file.
LocalizationFolder readLocalizationFolder(const std::filesystem::path& dir);

}  // namespace semsegmap
