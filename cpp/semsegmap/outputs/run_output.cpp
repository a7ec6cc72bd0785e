#include "semsegmap/outputs/run_output.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <system_error>

#include "semsegmap/core/atomic_file.h"

namespace semsegmap {

std::string frameStampFields(const std::optional<size_t>& number,
                             const std::optional<double>& time_s) {
  char text[64];
  std::snprintf(text, sizeof(text), ",%s,", number ? std::to_string(*number).c_str() : "");
  std::string fields = text;
  if (time_s) {
    std::snprintf(text, sizeof(text), "%.6f", *time_s);
    fields += text;
  }
  return fields;
}

namespace {

// ",x,y,z,qx,qy,qz,qw" with the precision of localizations.csv; commas alone without a pose.
std::string poseFields(const std::optional<Pose>& T) {
  if (!T) return ",,,,,,,";
  const auto v = toXyzQuat(*T);
  char s[160];
  std::snprintf(s, sizeof(s), ",%.4f,%.4f,%.4f,%.6f,%.6f,%.6f,%.6f", v[0], v[1], v[2], v[3], v[4],
                v[5], v[6]);
  return s;
}

}  // namespace

void writeTrajectoryCsv(const std::filesystem::path& path, const std::vector<FrameStamp>& frames,
                        const std::vector<TrajectoryColumns>& columns) {
  const size_t rows = columns.empty() ? 0 : columns.front().poses.size();
  const bool named = frames.size() == rows;
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "frame,dataset_frame,timestamp";
    for (const TrajectoryColumns& c : columns)
      for (const char* f : {"x", "y", "z", "qx", "qy", "qz", "qw"})
        out << ',' << c.prefix << '_' << f;
    out << '\n';
    for (size_t i = 0; i < rows; ++i) {
      out << i << (named ? frameStampFields(frames[i].number, frames[i].time_s) : ",,");
      for (const TrajectoryColumns& c : columns)
        out << poseFields(c.poses.size() == rows ? std::optional<Pose>(c.poses[i]) : std::nullopt);
      out << '\n';
    }
  });
}

void writeTrajectoryCsv(const std::filesystem::path& path, const SlamRun& run) {
  writeTrajectoryCsv(path, run.frames,
                     {{"slam", posesOf(run.trajectory)},
                      {"odom", posesOf(run.trajectory_odom)},
                      {"gt", run.trajectory_gt}});
}

namespace {

// The localizations and the ambiguous relocalizations, in the order of their frames.
std::vector<const LocalizationRecord*> rowsOf(const LocalizationRun& run) {
  std::vector<const LocalizationRecord*> rows;
  for (const LocalizationRecord& r : run.localizations) rows.push_back(&r);
  for (const LocalizationRecord& r : run.ambiguous) rows.push_back(&r);
  std::stable_sort(rows.begin(), rows.end(),
                   [](const LocalizationRecord* a, const LocalizationRecord* b) {
                     return a->frame_index < b->frame_index;
                   });
  return rows;
}

// ",sigma_x_m,...,sigma_yaw_deg,status" of a row.
std::string uncertaintyFields(const LocalizationRecord& r) {
  const Eigen::Matrix<double, 6, 1> s = sigmasOf(r.covariance);
  char line[256];
  std::snprintf(line, sizeof(line), ",%.4f,%.4f,%.4f,%.3f,%.3f,%.3f,%s", s[0], s[1], s[2], s[3],
                s[4], s[5], r.ambiguous ? "ambiguous" : "localized");
  return line;
}

}  // namespace

void writeLocalizationsCsv(const std::filesystem::path& path, const LocalizationRun& run) {
  writeFileAtomically(path, [&](std::ostream& out) {
    // The columns of schema semsegmap.localization/4 (summary.json; docs/commands.md), read by
    // name: dataset_frame and an empty timestamp are what version 1 lacked, path and fitness
    // what version 2 lacked (its latest_scan column is path = latest-scan), the sigmas and
    // status what version 3 lacked.
    // refinement_m: how far pose refinement moved the pose; empty where it was not applied.
    // path: which segments localized (local-map, latest-scan, relocalization); fitness: a
    // relocalization's registration check, empty for the other paths.
    out << "frame,dataset_frame,timestamp,x,y,z,qx,qy,qz,qw,inliers,translation_error_m,"
           "rotation_error_deg,refinement_m,path,fitness,runner_up_fitness,sigma_x_m,sigma_y_m,"
           "sigma_z_m,"
           "sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,status\n";
    char line[512];
    for (const LocalizationRecord* row : rowsOf(run)) {
      const LocalizationRecord& r = *row;
      const auto v = toXyzQuat(r.T_map_base);
      out << r.frame_index << frameStampFields(r.frame_number, r.timestamp_s);
      std::snprintf(line, sizeof(line), ",%.4f,%.4f,%.4f,%.6f,%.6f,%.6f,%.6f,%d", v[0], v[1], v[2],
                    v[3], v[4], v[5], v[6], r.inliers);
      out << line;
      if (r.T_world_base) {
        std::snprintf(line, sizeof(line), ",%.4f,%.4f", r.translation_error_m,
                      r.rotation_error_deg);
        out << line;
      } else {
        out << ",,";
      }
      if (r.refined) {
        std::snprintf(line, sizeof(line), ",%.4f", r.refinement_correction_m);
        out << line;
      } else {
        out << ',';
      }
      out << ',' << localizationPathName(r.path) << ',';
      if (r.registration_fitness) {
        std::snprintf(line, sizeof(line), "%.3f", *r.registration_fitness);
        out << line;
      }
      out << ',';
      if (r.runner_up_fitness) {
        std::snprintf(line, sizeof(line), "%.3f", *r.runner_up_fitness);
        out << line;
      }
      out << uncertaintyFields(r) << '\n';
    }
  });
}

StageTimes meanStageTimes(const RunStats& stats) {
  const double n = std::max<double>(1.0, static_cast<double>(stats.frames));
  const StageTimes& t = stats.total;
  return {t.enrich_ms / n, t.local_map_ms / n, t.segment_ms / n, t.describe_ms / n,
          t.localize_ms / n};
}

nlohmann::ordered_json stageMsJson(const StageTimes& t, bool with_total) {
  nlohmann::ordered_json j = {{"enrich", t.enrich_ms},
                              {"local_map", t.local_map_ms},
                              {"segment", t.segment_ms},
                              {"describe", t.describe_ms},
                              {"localize", t.localize_ms}};
  if (with_total) j["total"] = t.total();
  return j;
}

std::string localizationSummaryJson(const LocalizationRun& run, const SummaryContext& c) {
  const LocalizationSummary s = summarize(run);
  nlohmann::ordered_json j;
  // The layout of this file and of localizations.csv beside it (docs/commands.md).
  j["schema"] = kLocalizationSchema;
  j["dataset"] = c.dataset;
  j["map"] = c.map;
  j["config"] = c.config;
  j["descriptor"] = c.descriptor;
  j["frames"] = run.stats.frames;
  // Ctrl-C ended the run early: `frames` are those done, every file of them whole.
  j["interrupted"] = run.stats.interrupted;
  j["distance_m"] = run.distance_m;
  j["has_ground_truth"] = !run.trajectory_gt.empty();
  // The errors below measured against the very poses the local map was built on.
  j["odometry_is_ground_truth"] = run.odometry_is_ground_truth;
  j["n_localizations"] = s.localizations;
  j["n_with_ground_truth"] = s.with_ground_truth;
  // Without ground truth (or without a localization) the errors are unknown: null, not zero.
  j["n_error_below_1m"] = orNull(s.below_1m);
  j["n_error_below_5m"] = orNull(s.below_5m);
  j["n_refined"] = std::count_if(run.localizations.begin(), run.localizations.end(),
                                 [](const LocalizationRecord& r) { return r.refined; });
  nlohmann::ordered_json by_path;
  for (LocalizationPath p : {LocalizationPath::kLocalMap, LocalizationPath::kLatestScan,
                             LocalizationPath::kRelocalization, LocalizationPath::kScanContext})
    by_path[localizationPathName(p)] =
        std::count_if(run.localizations.begin(), run.localizations.end(),
                      [p](const LocalizationRecord& r) { return r.path == p; });
  j["n_by_path"] = by_path;
  // Relocalizations that fit another place as well: in localizations.csv, counted nowhere else.
  j["n_ambiguous"] = run.ambiguous.size();
  j["mean_translation_error_m"] = orNull(s.mean_translation_error_m);
  j["mean_rotation_error_deg"] = orNull(s.mean_rotation_error_deg);
  // The covariances against the errors (LocalizationSummary): null without ground truth.
  j["covariance_calibration"] = {
      {"share_mahalanobis_within_3", orNull(s.share_mahalanobis_within_3)},
      {"mean_nees", orNull(s.mean_nees)},
      {"median_sigma_m", orNull(s.median_sigma_m)}};
  j["fps"] = run.stats.fps();
  j["stage_ms"] = stageMsJson(meanStageTimes(run.stats), true);
  j["map_segments"] = c.map_segments;
  j["map_bytes"] = c.map_bytes;
  return jsonText(j);
}

std::optional<SlamErrors> slamErrors(const SlamRun& run) {
  if (run.trajectory.empty() || run.trajectory_gt.size() != run.trajectory.size())
    return std::nullopt;
  const std::vector<Pose> est = posesOf(run.trajectory), odo = posesOf(run.trajectory_odom);
  SlamErrors e;
  e.odometry = absoluteTrajectoryError(odo, run.trajectory_gt, false);
  e.slam = absoluteTrajectoryError(est, run.trajectory_gt, false);
  e.odometry_aligned = absoluteTrajectoryError(odo, run.trajectory_gt, true);
  e.slam_aligned = absoluteTrajectoryError(est, run.trajectory_gt, true);
  return e;
}

namespace {

nlohmann::ordered_json errorJson(const TrajectoryError& e) {
  return {{"rmse_m", e.rmse_m},
          {"mean_m", e.mean_m},
          {"max_m", e.max_m},
          {"rotation_mean_deg", e.rotation_mean_deg}};
}

}  // namespace

std::string slamSummaryJson(const SlamRun& run, const std::string& dataset) {
  nlohmann::ordered_json j;
  j["dataset"] = dataset;
  j["frames"] = run.stats.frames;
  j["interrupted"] = run.stats.interrupted;  // `frames` are those done before Ctrl-C
  j["loop_closures"] = run.loops.size();
  j["map_segments"] = run.map.size();
  j["fps"] = run.stats.fps();
  j["graph_ms_total"] = run.graph_ms;
  const std::optional<SlamErrors> errors = slamErrors(run);
  // Without ground truth the errors are unknown: null, as in every summary.
  const auto ate = [&](const TrajectoryError SlamErrors::*which) {
    return errors ? errorJson((*errors).*which) : nlohmann::ordered_json(nullptr);
  };
  j["ate_odometry"] = ate(&SlamErrors::odometry);
  j["ate_slam"] = ate(&SlamErrors::slam);
  j["ate_odometry_aligned"] = ate(&SlamErrors::odometry_aligned);
  j["ate_slam_aligned"] = ate(&SlamErrors::slam_aligned);
  j["has_ground_truth"] = errors.has_value();
  j["odometry_is_ground_truth"] = run.odometry_is_ground_truth;
  // false: the data has no frame times, so no TUM file was written (KITTI files alone).
  j["has_frame_times"] = run.has_frame_times;
  return jsonText(j);
}

// ---------------------------------------------------------------------------------------------
// RunOutputs

namespace {
namespace fs = std::filesystem;

// A folder with more entries than this is not listed (an output folder of /tmp): its new
// subfolders are then left in place, and only the run's files are removed.
constexpr size_t kMaxListedFolders = 20000;

[[noreturn]] void refuse(const fs::path& path, const std::string& what, const std::string& why) {
  throw std::runtime_error(path.string() + ": " + what + " " + why);
}

// access(2), not a trial write: nothing is written before the command starts; it also says
// EROFS for a read-only file system. Root passes it for permissions, as it passes a write.
void requireWritableDirectory(const fs::path& dir, const fs::path& path, const std::string& what) {
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    refuse(path, what, "cannot be written: " + dir.string() + ": " + std::strerror(errno));
}

// The nearest ancestor of `path` that exists (`path` itself when it does).
fs::path nearestExisting(const fs::path& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  std::error_code ec;
  while (!fs::exists(p, ec) && p.has_relative_path()) p = p.parent_path();
  return p;
}

bool inside(const fs::path& path, const fs::path& dir) {
  const fs::path rel = path.lexically_relative(dir);
  return !rel.empty() && rel != "." && *rel.begin() != "..";
}

// Absolute, without a trailing separator ("out/" is the folder out, whose parent is ".").
fs::path normalized(const fs::path& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (p.filename().empty() && p.has_relative_path()) p = p.parent_path();
  return p;
}

// The folder an output goes into as the user wrote it ("maps" for maps/s0.map), or absolute
// when they wrote none.
fs::path shownParent(const fs::path& shown, const fs::path& full) {
  fs::path p = shown;
  if (p.filename().empty()) p = p.parent_path();
  return p.has_parent_path() ? p.parent_path() : full.parent_path();
}

}  // namespace

RunOutputs::RunOutputs() = default;

RunOutputs::~RunOutputs() {
  watches_.clear();  // first: no write reports to this object once it is being torn down
  if (!committed_) removeCreated();
}

void RunOutputs::watch(const fs::path& scope) {
  watches_.push_back(std::make_unique<NewFileWatch>(scope, [this](const fs::path& path) {
    const std::lock_guard<std::mutex> lock(mutex_);
    written_.push_back(normalized(path));
  }));
}

// The folder an output goes into must be there: a mistyped path (`--out /nonexistent/dir/x`)
// would otherwise make a tree of folders in the wrong place without a word.
void RunOutputs::requireParent(const fs::path& full, const fs::path& shown,
                               const std::string& what) {
  const fs::path parent = full.parent_path();
  std::error_code ec;
  if (fs::is_directory(parent, ec)) {
    requireWritableDirectory(parent, shown, what);
    return;
  }
  const fs::path ancestor = nearestExisting(parent);
  if (!fs::is_directory(ancestor, ec))
    refuse(shown, what, "cannot be created: " + ancestor.string() + " is not a directory");
  refuse(shown, what,
         "cannot be written: its folder " + shownParent(shown, full).string() +
             " does not exist (create it first, or choose another)");
}

size_t RunOutputs::folder(const fs::path& dir, const std::string& what) {
  const fs::path full = normalized(dir);
  std::error_code ec;
  if (fs::exists(full, ec) && !fs::is_directory(full, ec))
    refuse(dir, what, "exists and is not a directory");
  if (!fs::exists(full, ec)) {
    requireParent(full, dir, what);
    fs::create_directory(full, ec);
    if (ec) refuse(dir, what, "cannot be created: " + ec.message());
    created_.push_back(full);
    watch(full);  // claims its files from a RunOutputs whose folder holds it
    return 0;
  }
  requireWritableDirectory(full, dir, what);
  existing_.push_back(full);
  watch(full);
  size_t listed = 0, entries = 0;
  for (auto it = fs::recursive_directory_iterator(full, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    entries += it.depth() == 0;
    if (++listed > kMaxListedFolders) {
      listed_all_ = false;
      break;
    }
    if (it->is_directory(ec)) old_dirs_.push_back(normalized(it->path()));
  }
  return entries;
}

bool RunOutputs::file(const fs::path& file, const std::string& what) {
  const fs::path full = normalized(file);
  std::error_code ec;
  if (fs::is_directory(full, ec)) refuse(file, what, "is a directory, expected a file");
  requireParent(full, file, what);
  if (fs::exists(full, ec)) return true;
  files_.push_back(full);
  watch(full);
  return false;
}

void RunOutputs::keptFile(const fs::path& file, const std::string& what) {
  std::error_code ec;
  if (fs::is_directory(normalized(file), ec)) refuse(file, what, "is a directory, expected a file");
  requireParent(normalized(file), file, what);
}

bool RunOutputs::newFolder(const fs::path& dir) const {
  if (!listed_all_ || std::find(old_dirs_.begin(), old_dirs_.end(), dir) != old_dirs_.end())
    return false;
  for (const fs::path& d : existing_)
    if (inside(dir, d)) return true;
  return false;
}

bool RunOutputs::owns(const fs::path& path) const {
  for (const fs::path& f : files_)
    if (path == f) return true;
  for (const fs::path& d : existing_)
    if (path == d || inside(path, d)) return true;
  return false;
}

void RunOutputs::removeCreated() noexcept {
  std::error_code ec;
  const std::lock_guard<std::mutex> lock(mutex_);
  for (const fs::path& f : written_) {
    if (!owns(f)) continue;  // a file outside the outputs (a training cache) is kept
    fs::remove(f, ec);
    // Up to the declared folder: subfolders that the run made and that are empty now.
    for (fs::path d = f.parent_path(); newFolder(d); d = d.parent_path())
      if (!fs::remove(d, ec)) break;  // not empty: something else lives there
  }
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) fs::remove_all(*it, ec);
}

}  // namespace semsegmap
