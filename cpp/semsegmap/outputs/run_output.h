// The files a localization or SLAM run leaves behind: one CSV row per localization and JSON
// summaries that evaluations across commits can compare; and RunOutputs, which checks a
// command's outputs before it starts and removes them when it fails.
#pragma once

#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/json.h"
#include "semsegmap/graph/trajectory.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/pipeline/slam.h"

namespace semsegmap {

// The version of localizations.csv and summary.json, named in summary.json: 2 added the
// dataset's own frame number and left a time the data does not have empty (1 made one up), and
// writes null for every error or count the run does not know; 3 says which path localized
// (local-map, latest-scan, relocalization) and a relocalization's fitness, and counts them.
inline constexpr const char* kLocalizationSchema = "semsegmap.localization/4";

// frame (the run's index), dataset_frame (the dataset's own number, empty when it has none),
// timestamp (the data's, empty when it has none), T_map_base as x y z qx qy qz qw, inliers, with
// ground truth the translation error in m and the rotation error in degrees, refinement_m, path
// and fitness.
void writeLocalizationsCsv(const std::filesystem::path& path, const LocalizationRun& run);

// ",NUMBER,TIME" with either field empty when unknown: the dataset's name of a frame as the
// per-frame CSV files write it after the run's index.
std::string frameStampFields(const std::optional<size_t>& number,
                             const std::optional<double>& time_s);

// One group of pose columns of trajectory.csv: <prefix>_x/y/z/qx/qy/qz/qw, one pose per frame
// run, or empty fields on every row when `poses` is empty (a run without ground truth).
struct TrajectoryColumns {
  std::string prefix;  // "odom", "gt", "slam"
  std::vector<Pose> poses;
};
// trajectory.csv, one row per pose of the first group: frame (the run's index), dataset_frame
// and timestamp (frameStampFields: the data's own name and time, empty where it has none, and on
// every row unless `frames` has one per row), then each group's columns. The one layout of
// localize's, slam's and odometry's (an atomic write).
void writeTrajectoryCsv(const std::filesystem::path& path, const std::vector<FrameStamp>& frames,
                        const std::vector<TrajectoryColumns>& columns);
// slam's: slam_* (loop-closed T_map_base), odom_* (T_odom_base) and gt_* (T_world_base).
void writeTrajectoryCsv(const std::filesystem::path& path, const SlamRun& run);

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

// The outputs of one command. Declared before any work, each is checked at once: the folder an
// output goes into must exist and be writable (a missing one is refused, never made: a mistyped
// path would grow a tree of folders in the wrong place), an output folder may itself be new (it
// is created then) or an existing writable directory, an output file must not be a directory.
// Unless commit() is called (the command succeeded), the destructor removes what the command
// created: the output folders that did not exist, and the files written atomically
// (core/atomic_file.h) into a folder that did, with the subfolders that held only them. Nothing
// that existed before is removed (a file the run replaced keeps its new content), so a failed run
// leaves no summary of its own behind. Each watches only its own outputs (NewFileWatch, one per
// declared folder and file), so several may be alive at once, even nested: a file belongs to the
// one that declared the innermost output holding it.
class RunOutputs {
 public:
  RunOutputs();
  ~RunOutputs();
  RunOutputs(const RunOutputs&) = delete;
  RunOutputs& operator=(const RunOutputs&) = delete;

  // Throw std::runtime_error "<path>: <what is wrong>" (`what` names the option, e.g. "--out").
  // folder(): how many entries the folder held before (0 for a new one); file(): whether the
  // file was there before. What the run writes replaces what has the same name.
  size_t folder(const std::filesystem::path& dir, const std::string& what = "output folder");
  bool file(const std::filesystem::path& file, const std::string& what = "output file");
  // A file the command writes and keeps even when it fails (a cache of work done): checked as
  // file() checks, never removed.
  void keptFile(const std::filesystem::path& file, const std::string& what);
  void commit() { committed_ = true; }

 private:
  // Refuses `full` unless its folder exists and is writable; errors name `shown`, the output
  // as given.
  static void requireParent(const std::filesystem::path& full, const std::filesystem::path& shown,
                            const std::string& what);
  bool owns(const std::filesystem::path& path) const;
  // Inside an existing output folder and made by this run.
  bool newFolder(const std::filesystem::path& dir) const;
  void removeCreated() noexcept;
  // Records the new files written under `scope` (an output folder or file) into written_.
  void watch(const std::filesystem::path& scope);

  std::vector<std::filesystem::path> created_;   // the output folders this run made
  std::vector<std::filesystem::path> existing_;  // declared folders that were there before
  std::vector<std::filesystem::path> files_;     // declared files that were not
  std::vector<std::filesystem::path> written_;   // new files the run wrote (the observer)
  std::vector<std::filesystem::path> old_dirs_;  // folders inside existing_, before the run
  bool listed_all_ = true;                       // old_dirs_ is complete
  std::mutex mutex_;
  std::vector<std::unique_ptr<NewFileWatch>> watches_;  // after mutex_: they lock it
  bool committed_ = false;
};

}  // namespace semsegmap
