// The files a localization or SLAM run leaves behind: one CSV row per localization and JSON
// summaries that evaluations across commits can compare.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "semsegmap/core/json.h"
#include "semsegmap/graph/trajectory.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/slam.h"

namespace semsegmap {

// frame, timestamp, T_map_base as x y z qx qy qz qw, inliers, and with ground truth the
// translation error in m and the rotation error in degrees.
void writeLocalizationsCsv(const std::filesystem::path& path, const LocalizationRun& run);

// The mean time per frame of each stage.
StageTimes meanStageTimes(const RunStats& stats);
// {"enrich", "local_map", "segment", "describe", "localize"} in ms, and "total" when asked.
nlohmann::ordered_json stageMsJson(const StageTimes& per_frame, bool with_total);

struct SummaryContext {
  std::string dataset, map, config, descriptor;
  size_t map_segments = 0;
  uint64_t map_bytes = 0;
};
// summary.json of a localization run: the text of the file (core/json.h's layout).
std::string localizationSummaryJson(const LocalizationRun& run, const SummaryContext& context);

// The absolute trajectory error of a SLAM run, odometry (before) and loop-closed (after), as is
// and after rigid alignment (graph/trajectory.h).
struct SlamErrors {
  TrajectoryError odometry, slam, odometry_aligned, slam_aligned;
};
// Empty without ground truth (one ground-truth pose per estimated pose).
std::optional<SlamErrors> slamErrors(const SlamRun& run);

// summary.json of a SLAM run: counts, speed and, with ground truth, the errors (slamErrors).
std::string slamSummaryJson(const SlamRun& run, const std::string& dataset);

}  // namespace semsegmap
