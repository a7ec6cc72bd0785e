#include "semsegmap/eval/odometry_run.h"

#include <chrono>
#include <map>
#include <string>

#include "semsegmap/core/json.h"
#include "semsegmap/io/trajectory_file.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/viz/trajectory_png.h"

namespace semsegmap {

OdometryRun runLidarOdometry(FrameSource& source, const OdometryConfig& config, size_t max_frames,
                             const std::function<void(size_t, size_t)>& progress,
                             const StopToken& stop) {
  OdometryRun run;
  run.dataset = source.info().name;
  run.has_frame_times = source.info().has_frame_times;
  const Pose T_base_lidar = source.info().rig.T_base_lidar;
  LidarOdometry odometry(config);
  const size_t n = framesToRead(source, max_frames);
  bool all_ground_truth = true;
  for (size_t i = 0; i < n; ++i) {
    if (stop.stopRequested()) {
      run.interrupted = true;
      break;
    }
    const Frame f = source.frame(i);
    const auto start = std::chrono::steady_clock::now();
    const OdometryResult r = odometry.registerFrame(f.points, f.point_times, f.timestamp_s);
    run.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.frames.push_back(r);
    run.stamps.push_back(stampOf(f, run.has_frame_times));
    run.trajectory.push_back({f.timestamp_s, baseOdometryFromLidar(r.T_odom_lidar, T_base_lidar)});
    all_ground_truth = all_ground_truth && f.T_world_base.has_value();
    if (f.T_world_base) run.ground_truth.push_back(*f.T_world_base);
    if (progress) progress(i + 1, n);
  }
  if (!all_ground_truth) run.ground_truth.clear();
  return run;
}

std::optional<OdometryErrors> odometryErrors(const OdometryRun& run) {
  if (run.ground_truth.empty() || run.ground_truth.size() != run.trajectory.size())
    return std::nullopt;
  OdometryErrors e;
  const std::vector<Pose> estimate = posesOf(run.trajectory);
  e.kitti = kittiRelativeError(estimate, run.ground_truth);
  // The odometry frame is the base at frame 0: put it where the ground truth has the base then.
  std::vector<Pose> anchored;
  const Pose T_world_odom = run.ground_truth.front() * estimate.front().inverse();
  for (const Pose& T : estimate) anchored.push_back(T_world_odom * T);
  e.ate = absoluteTrajectoryError(anchored, run.ground_truth, false);
  e.ate_aligned = absoluteTrajectoryError(estimate, run.ground_truth, true);
  return e;
}

namespace {

nlohmann::ordered_json fallbackCounts(const std::vector<OdometryResult>& frames) {
  nlohmann::ordered_json j;
  size_t degenerate = 0, deskewed = 0, nonfinite = 0;
  std::map<std::string, size_t> fallbacks;
  for (const OdometryResult& r : frames) {
    if (r.usedPrediction()) ++fallbacks[fallbackName(r.fallback)];
    degenerate += r.degenerate_directions > 0;
    deskewed += r.deskewed;
    nonfinite += r.skipped_nonfinite;
  }
  j["prediction_used"] = fallbacks;
  j["frames_degenerate"] = degenerate;
  j["frames_deskewed"] = deskewed;
  j["nonfinite_points_skipped"] = nonfinite;
  return j;
}

}  // namespace

nlohmann::ordered_json toJson(const OdometryRun& run, const std::optional<OdometryErrors>& errors) {
  nlohmann::ordered_json j;
  j["dataset"] = run.dataset;
  j["frames"] = run.frames.size();
  j["interrupted"] = run.interrupted;  // `frames` are those done before Ctrl-C
  j["seconds"] = run.seconds;
  j["ms_per_frame"] = run.frames.empty()
                          ? nlohmann::ordered_json(nullptr)
                          : nlohmann::ordered_json(1e3 * run.seconds / run.frames.size());
  j["diagnostics"] = fallbackCounts(run.frames);
  // Without ground truth the errors are unknown: null, as in every summary.
  using Json = nlohmann::ordered_json;
  j["has_ground_truth"] = errors.has_value();
  // false: no trajectory_tum.txt, its times would be made up (trajectory_kitti.txt has the poses).
  j["has_frame_times"] = run.has_frame_times;
  j["kitti_relative_error"] = errors ? toJson(errors->kitti) : Json(nullptr);
  j["ate"] = errors ? toJson(errors->ate) : Json(nullptr);
  j["ate_aligned"] = errors ? toJson(errors->ate_aligned) : Json(nullptr);
  return j;
}

void writeOdometryFiles(const std::filesystem::path& out, const OdometryRun& run) {
  std::filesystem::create_directories(out);
  if (run.has_frame_times) writeTum(out / "trajectory_tum.txt", run.trajectory);
  writeKitti(out / "trajectory_kitti.txt", run.trajectory);
  // The frames as the dataset names them, beside the estimate (and the ground truth, if any).
  writeTrajectoryCsv(out / "trajectory.csv", run.stamps,
                     {{"odom", posesOf(run.trajectory)}, {"gt", run.ground_truth}});
  const std::optional<OdometryErrors> errors = odometryErrors(run);
  writeJsonAtomically(out / "summary.json", toJson(run, errors));
  if (!errors) return;
  // Both in the world frame, the estimate anchored at the first ground-truth pose.
  const Pose T_world_odom = run.ground_truth.front() * run.trajectory.front().T.inverse();
  std::vector<Pose> estimate;
  for (const StampedPose& p : run.trajectory) estimate.push_back(T_world_odom * p.T);
  viz::writeTrajectoriesPng(out / "trajectory.png", run.dataset + " - LiDAR odometry",
                            {{"ground truth", 200, 200, 200, run.ground_truth},
                             {"LiDAR odometry", 80, 220, 80, estimate}},
                            {});
}

}  // namespace semsegmap
