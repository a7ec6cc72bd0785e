// semsegmap slam: mapping on odometry with loop closure in a pose graph; writes the trajectory
// (TUM and KITTI formats), the loop closures, the error before and after, and a picture.
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/config.h"
#include "semsegmap/io/open_dataset.h"
#include "semsegmap/pipeline/slam.h"
#include "semsegmap/viz/trajectory_png.h"

namespace semsegmap::app {

namespace {

std::vector<Pose> posesOf(const std::vector<StampedPose>& t) {
  std::vector<Pose> out;
  for (const auto& p : t) out.push_back(p.T);
  return out;
}

void writeError(std::ostream& j, const char* name, const TrajectoryError& e) {
  j << "  \"" << name << "\": {\"rmse_m\": " << e.rmse_m << ", \"mean_m\": " << e.mean_m
    << ", \"max_m\": " << e.max_m << ", \"rotation_mean_deg\": " << e.rotation_mean_deg << "},\n";
}

}  // namespace

int runSlam(const std::vector<std::string>& args) {
  const CliArgs a(args, {"dataset", "config", "out", "max-frames"}, {});
  const PipelineConfig config = loadPipelineConfig(a.require("config"));
  const std::filesystem::path out = a.require("out");
  auto source = openDataset(a.require("dataset"));
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  auto describer = makeDescriber(config.descriptor);
  std::filesystem::create_directories(out);

  Progress progress("slam", 0);
  RunOptions options;
  options.max_frames = static_cast<size_t>(max_frames);
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  const SlamRun run = runSlam(*source, config, *describer, options);

  writeTum(out / "trajectory_tum.txt", run.trajectory);
  writeKitti(out / "trajectory_kitti.txt", run.trajectory);
  writeTum(out / "odometry_tum.txt", run.trajectory_odom);
  writeFileAtomically(out / "loops.csv", [&](std::ostream& o) {
    o << "frame,old_frame,inliers,correction_m\n";
    for (const LoopClosure& l : run.loops)
      o << l.frame_index << ',' << l.old_frame_index << ',' << l.inliers << ',' << l.correction_m
        << '\n';
  });
  std::ostringstream j;
  j << "{\n  \"dataset\": \"" << source->info().name << "\",\n  \"frames\": " << run.stats.frames
    << ",\n  \"loop_closures\": " << run.loops.size() << ",\n  \"map_segments\": " << run.map.size()
    << ",\n  \"fps\": " << run.stats.fps() << ",\n  \"graph_ms_total\": " << run.graph_ms << ",\n";
  const bool has_gt = run.trajectory_gt.size() == run.trajectory.size() && !run.trajectory.empty();
  if (has_gt) {
    const auto est = posesOf(run.trajectory), odo = posesOf(run.trajectory_odom);
    const TrajectoryError before = absoluteTrajectoryError(odo, run.trajectory_gt, false);
    const TrajectoryError after = absoluteTrajectoryError(est, run.trajectory_gt, false);
    const TrajectoryError before_aligned = absoluteTrajectoryError(odo, run.trajectory_gt, true);
    const TrajectoryError after_aligned = absoluteTrajectoryError(est, run.trajectory_gt, true);
    writeError(j, "ate_odometry", before);
    writeError(j, "ate_slam", after);
    writeError(j, "ate_odometry_aligned", before_aligned);
    writeError(j, "ate_slam_aligned", after_aligned);
    std::printf("ATE (RMSE) odometry %.2f m -> with loop closure %.2f m  (aligned: %.2f -> %.2f)\n",
                before.rmse_m, after.rmse_m, before_aligned.rmse_m, after_aligned.rmse_m);
  }
  j << "  \"has_ground_truth\": " << (has_gt ? "true" : "false") << "\n}\n";
  writeBytesAtomically(out / "summary.json", j.str());

  std::vector<viz::TrajectoryCurve> curves;
  if (has_gt) curves.push_back({"ground truth", 200, 200, 200, run.trajectory_gt});
  curves.push_back({"odometry", 230, 80, 80, posesOf(run.trajectory_odom)});
  curves.push_back({"loop-closed", 80, 220, 80, posesOf(run.trajectory)});
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> links;
  for (const LoopClosure& l : run.loops)
    links.emplace_back(run.trajectory.at(l.old_node).T.translation(),
                       run.trajectory.at(l.node).T.translation());
  viz::writeTrajectoriesPng(out / "slam.png", source->info().name + " - loop closure", curves,
                            links);
  std::printf("frames %zu  loop closures %zu  map segments %zu  %.1f Hz\n", run.stats.frames,
              run.loops.size(), run.map.size(), run.stats.fps());
  std::cout << "wrote " << (out / "trajectory_tum.txt").string()
            << ", trajectory_kitti.txt, odometry_tum.txt, loops.csv, summary.json, slam.png\n";
  return 0;
}

}  // namespace semsegmap::app
