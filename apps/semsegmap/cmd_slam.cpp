// semsegmap slam: mapping on odometry with loop closure in a pose graph; writes the trajectory
// (TUM and KITTI formats, KITTI alone when the data has no frame times; trajectory.csv with the
// dataset's frame numbers and times), the loop closures, the error before and after, and a
// picture.
#include <filesystem>
#include <iostream>
#include <optional>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/io/trajectory_file.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/pipeline/slam.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/viz/trajectory_png.h"

namespace semsegmap::app {

namespace {

// The loop-closed and the odometry trajectory; the names of the files written. TUM files carry
// times, and a time made up from the frame rate would pair the poses with the wrong data in evo
// or with another sensor's log: without the data's times only KITTI files (one line per frame
// of the run, in order) are written, and a note says so. trajectory.csv names each frame as the
// dataset does (its number and time, empty where it has none), as localize's does.
std::string writeTrajectories(const std::filesystem::path& out, const SlamRun& run) {
  writeTrajectoryCsv(out / "trajectory.csv", run);
  writeKitti(out / "trajectory_kitti.txt", run.trajectory);
  if (!run.has_frame_times) {
    writeKitti(out / "odometry_kitti.txt", run.trajectory_odom);
    note(
        "the data has no frame times: no trajectory_tum.txt or odometry_tum.txt (their times "
        "would be made up); trajectory_kitti.txt and odometry_kitti.txt hold the poses, line i "
        "for frame i of the run, and trajectory.csv the dataset's frame numbers");
    return "trajectory.csv, trajectory_kitti.txt, odometry_kitti.txt";
  }
  writeTum(out / "trajectory_tum.txt", run.trajectory);
  writeTum(out / "odometry_tum.txt", run.trajectory_odom);
  return "trajectory.csv, trajectory_tum.txt, trajectory_kitti.txt, odometry_tum.txt";
}

int runSlamCommand(const CliArgs& a) {
  const PipelineConfig config = loadPipelineConfig(a.get("config"));
  const std::filesystem::path out = a.get("out");
  requireDescriberBuilt(config.descriptor);  // a part this build lacks, before the data
  // The network and LiDAR odometry, when asked for, run inside the pipeline.
  DatasetWithStages data = openDatasetForPipelineArg(a);
  std::unique_ptr<FrameSource>& source = data.source;
  std::shared_ptr<Describer> describer = describerFor(config.descriptor, *source);

  Progress progress("slam", 0);
  RunOptions options;
  options.max_frames = a.frameLimit();
  options.progress = [&](size_t done, size_t total) { progress.update(done, total); };
  options.stop = stopToken();
  options.stages = data.stages;
  const SlamRun run = runSlam(*source, config, describer, options);
  // Stopped before its first frame: nothing worth writing (main removes what the run made).
  if (run.stats.interrupted && run.stats.frames == 0)
    return interruptedRun("slam", 0, options.frameCount(*source), out.string());

  const std::string trajectories = writeTrajectories(out, run);
  writeFileAtomically(out / "loops.csv", [&](std::ostream& o) {
    o << "frame,old_frame,inliers,correction_m\n";
    for (const LoopClosure& l : run.loops)
      o << l.frame_index << ',' << l.old_frame_index << ',' << l.inliers << ',' << l.correction_m
        << '\n';
  });
  const std::optional<SlamErrors> errors = slamErrors(run);
  const bool has_gt = errors.has_value();
  if (errors)
    std::printf(
        "ATE (RMSE) odometry %.2f m -> with loop closure %.2f m  (aligned: %.2f -> %.2f)%s\n",
        errors->odometry.rmse_m, errors->slam.rmse_m, errors->odometry_aligned.rmse_m,
        errors->slam_aligned.rmse_m,
        run.odometry_is_ground_truth ? "  [odometry is the ground truth]" : "");

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
  // Last: a summary says the run completed. Counts, speed and (with ground truth) the trajectory
  // error before and after loop closure.
  writeBytesAtomically(out / "summary.json", slamSummaryJson(run, source->info().name));
  std::printf("frames %zu  loop closures %zu  map segments %zu  %.1f Hz\n", run.stats.frames,
              run.loops.size(), run.map.size(), run.stats.fps());
  std::cout << "wrote " << trajectories << ", loops.csv, summary.json, slam.png to " << out.string()
            << "\n";
  if (run.stats.interrupted)
    return interruptedRun("slam", run.stats.frames, options.frameCount(*source), out.string());
  return 0;
}

}  // namespace

const CommandSpec& slamCommand() {
  static const CommandSpec command{
      "slam",
      "mapping with loop closure on odometry -> trajectories, loops.csv, slam.png",
      datasetOptions("the run to map",
                     {
                         {"config", Value::kText, "FILE", "",
                          "pipeline configuration, config/*.yaml", kRequired},
                         {"out", Value::kText, "DIR", "", "output folder", kRequired},
                         maxFramesOption(),
                     }),
      kDatasetNotes,
      runSlamCommand,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
