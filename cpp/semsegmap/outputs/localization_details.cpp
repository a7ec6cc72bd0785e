#include "semsegmap/outputs/localization_details.h"

#include <array>
#include <cstdio>
#include <stdexcept>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/json.h"
#include "semsegmap/io/csv_table.h"
#include "semsegmap/outputs/run_output.h"

namespace semsegmap {

namespace {

void writeMatchesCsv(const std::filesystem::path& path, const LocalizationRun& run) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "frame,local_x,local_y,local_z,target_x,target_y,target_z\n";
    char line[160];
    for (const LocalizationRecord& r : run.localizations)
      for (const auto& [local, target] : r.matches) {
        std::snprintf(line, sizeof(line), "%zu,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f\n", r.frame_index,
                      local.x(), local.y(), local.z(), target.x(), target.y(), target.z());
        out << line;
      }
  });
}

// The columns of a pose, "<prefix>x" ... "<prefix>qw", looked up before any row is read so
// that a file without them fails even when it has no rows.
std::array<size_t, 7> poseColumns(const CsvTable& t, const std::string& prefix) {
  std::array<size_t, 7> c{};
  const char* fields[] = {"x", "y", "z", "qx", "qy", "qz", "qw"};
  for (size_t k = 0; k < 7; ++k) c[k] = t.column(prefix + fields[k]);
  return c;
}

Pose poseFrom(const CsvTable& t, size_t row, const std::array<size_t, 7>& columns) {
  std::array<double, 7> v{};
  for (size_t k = 0; k < 7; ++k) v[k] = t.number(row, columns[k]);
  return fromXyzQuat(v);
}

// A whole number >= 0 in an optional column; nothing when the column or the field is empty.
std::optional<size_t> optionalCount(const CsvTable& t, size_t row, const char* name) {
  if (!t.has(name) || t.text(row, t.column(name)).empty()) return std::nullopt;
  return t.count(row, t.column(name));
}

std::vector<LocalizationRow> readLocalizations(const std::filesystem::path& path) {
  const CsvTable t = CsvTable::read(path);
  const size_t frame = t.column("frame"), inliers = t.column("inliers");
  const auto pose = poseColumns(t, "");
  // Older files have no refinement_m or dataset_frame; a run without ground truth leaves the
  // errors empty, a dataset without times (from version 2) the timestamp.
  const auto optional = [&](size_t row, const char* name) -> std::optional<double> {
    return t.has(name) ? t.optionalNumber(row, t.column(name)) : std::nullopt;
  };
  std::vector<LocalizationRow> rows(t.rows());
  for (size_t i = 0; i < t.rows(); ++i) {
    LocalizationRow& r = rows[i];
    r.frame = t.count(i, frame);
    r.dataset_frame = optionalCount(t, i, "dataset_frame");
    r.timestamp_s = optional(i, "timestamp");
    r.T_map_base = poseFrom(t, i, pose);
    r.inliers = static_cast<int>(t.count(i, inliers));
    r.translation_error_m = optional(i, "translation_error_m");
    r.rotation_error_deg = optional(i, "rotation_error_deg");
    r.refinement_m = optional(i, "refinement_m");
  }
  return rows;
}

std::vector<MatchRow> readMatches(const std::filesystem::path& path) {
  const CsvTable t = CsvTable::read(path);
  const size_t frame = t.column("frame");
  std::array<size_t, 6> c{};
  const char* names[] = {"local_x", "local_y", "local_z", "target_x", "target_y", "target_z"};
  for (size_t k = 0; k < 6; ++k) c[k] = t.column(names[k]);
  const auto vec = [&](size_t row, size_t first) {
    return Eigen::Vector3f(t.number(row, c[first]), t.number(row, c[first + 1]),
                           t.number(row, c[first + 2]));
  };
  std::vector<MatchRow> rows(t.rows());
  for (size_t i = 0; i < t.rows(); ++i) rows[i] = {t.count(i, frame), vec(i, 0), vec(i, 3)};
  return rows;
}

std::vector<TrajectoryRow> readTrajectory(const std::filesystem::path& path) {
  const CsvTable t = CsvTable::read(path);
  const size_t frame = t.column("frame");
  const auto odom = poseColumns(t, "odom_"), gt = poseColumns(t, "gt_");
  std::vector<TrajectoryRow> rows(t.rows());
  for (size_t i = 0; i < t.rows(); ++i) {
    rows[i].frame = t.count(i, frame);
    rows[i].dataset_frame = optionalCount(t, i, "dataset_frame");
    rows[i].timestamp_s =
        t.has("timestamp") ? t.optionalNumber(i, t.column("timestamp")) : std::nullopt;
    rows[i].T_odom_base = poseFrom(t, i, odom);
    if (!t.text(i, gt[0]).empty()) rows[i].T_world_base = poseFrom(t, i, gt);
  }
  return rows;
}

void readSummary(const std::filesystem::path& path, LocalizationFolder& f) {
  try {
    const nlohmann::json j = nlohmann::json::parse(readFileBytes(path));
    f.dataset = j.value("dataset", "");
    f.map = j.value("map", "");
    f.config = j.value("config", "");
    f.schema = j.value("schema", "semsegmap.localization/1");  // older files do not say
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path.string() + ": not a run's summary (" + e.what() + ")");
  }
}

}  // namespace

void writeLocalizationDetails(const std::filesystem::path& dir, const LocalizationRun& run) {
  writeMatchesCsv(dir / "matches.csv", run);
  // Frames are numbered from 0 in the order they are run (the localization records carry the
  // same numbers), so row i is frame i; beside it the dataset's own number and time, as in
  // localizations.csv.
  writeTrajectoryCsv(dir / "trajectory.csv", run.frames,
                     {{"odom", run.trajectory_odom}, {"gt", run.trajectory_gt}});
}

LocalizationFolder readLocalizationFolder(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir))
    throw std::runtime_error(dir.string() + ": no such folder (a localization run's output)");
  if (!std::filesystem::exists(dir / "localizations.csv"))
    throw std::runtime_error(dir.string() +
                             ": no localizations.csv (not the output of semsegmap localize, "
                             "eval or demo)");
  LocalizationFolder f;
  f.dir = dir;
  f.localizations = readLocalizations(dir / "localizations.csv");
  f.has_matches = std::filesystem::exists(dir / "matches.csv");
  if (f.has_matches) f.matches = readMatches(dir / "matches.csv");
  f.has_trajectory = std::filesystem::exists(dir / "trajectory.csv");
  if (f.has_trajectory) f.trajectory = readTrajectory(dir / "trajectory.csv");
  if (std::filesystem::exists(dir / "summary.json")) readSummary(dir / "summary.json", f);
  return f;
}

}  // namespace semsegmap
