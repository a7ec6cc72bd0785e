#include "semsegmap/io/run_output.h"

#include <algorithm>
#include <cstdio>

#include "semsegmap/core/atomic_file.h"

namespace semsegmap {

void writeLocalizationsCsv(const std::filesystem::path& path, const LocalizationRun& run) {
  writeFileAtomically(path, [&](std::ostream& out) {
    // refinement_m: how far pose refinement moved the pose; empty where it was not applied.
    out << "frame,timestamp,x,y,z,qx,qy,qz,qw,inliers,translation_error_m,rotation_error_deg,"
           "refinement_m\n";
    char line[512];
    for (const LocalizationRecord& r : run.localizations) {
      const auto v = toXyzQuat(r.T_map_base);
      std::snprintf(line, sizeof(line), "%zu,%.6f,%.4f,%.4f,%.4f,%.6f,%.6f,%.6f,%.6f,%d",
                    r.frame_index, r.timestamp_s, v[0], v[1], v[2], v[3], v[4], v[5], v[6],
                    r.inliers);
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
      out << '\n';
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
  const LocalizationSummary s = summarize(run.localizations);
  nlohmann::ordered_json j;
  j["dataset"] = c.dataset;
  j["map"] = c.map;
  j["config"] = c.config;
  j["descriptor"] = c.descriptor;
  j["frames"] = run.stats.frames;
  j["distance_m"] = run.distance_m;
  j["has_ground_truth"] = !run.trajectory_gt.empty();
  j["n_localizations"] = s.localizations;
  j["n_error_below_1m"] = s.below_1m;
  j["n_error_below_5m"] = s.below_5m;
  j["n_refined"] = std::count_if(run.localizations.begin(), run.localizations.end(),
                                 [](const LocalizationRecord& r) { return r.refined; });
  j["mean_translation_error_m"] = s.mean_translation_error_m;
  j["mean_rotation_error_deg"] = s.mean_rotation_error_deg;
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
  j["loop_closures"] = run.loops.size();
  j["map_segments"] = run.map.size();
  j["fps"] = run.stats.fps();
  j["graph_ms_total"] = run.graph_ms;
  const std::optional<SlamErrors> errors = slamErrors(run);
  if (errors) {
    j["ate_odometry"] = errorJson(errors->odometry);
    j["ate_slam"] = errorJson(errors->slam);
    j["ate_odometry_aligned"] = errorJson(errors->odometry_aligned);
    j["ate_slam_aligned"] = errorJson(errors->slam_aligned);
  }
  j["has_ground_truth"] = errors.has_value();
  return jsonText(j);
}

}  // namespace semsegmap
