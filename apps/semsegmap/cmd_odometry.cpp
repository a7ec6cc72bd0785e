// semsegmap odometry: LiDAR odometry over a dataset, from its scans alone; writes the trajectory
// (TUM and KITTI formats, KITTI alone when the data has no frame times; trajectory.csv with the
// dataset's frame numbers and times), summary.json and, with ground truth, the KITTI relative
// error, the ATE and trajectory.png.
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/eval/odometry_run.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

namespace {

int runOdometryCommand(const CliArgs& a) {
  const OdometryConfig config =
      a.has("config") ? loadOdometryConfig(a.get("config")) : OdometryConfig{};
  const std::filesystem::path out = a.get("out");
  auto source = openDatasetArg(a);
  Progress progress("odometry", 0);
  const OdometryRun run = runLidarOdometry(
      *source, config, a.frameLimit(),
      [&](size_t done, size_t total) { progress.update(done, total); }, stopToken());
  const size_t total = framesToRead(*source, a.frameLimit());
  // Stopped before its first frame: nothing worth writing (main removes what the run made).
  if (run.interrupted && run.frames.empty()) return interruptedRun("odometry", 0, total, "");
  writeOdometryFiles(out, run);
  const std::optional<OdometryErrors> errors = odometryErrors(run);
  size_t predicted = 0;
  for (const OdometryResult& r : run.frames) predicted += r.usedPrediction();
  std::printf("frames %zu  %.1f ms/frame  prediction used %zu\n", run.frames.size(),
              run.frames.empty() ? 0.0 : 1e3 * run.seconds / run.frames.size(), predicted);
  if (errors && errors->kitti.segments.empty())  // shorter than KITTI's shortest length
    std::printf("KITTI relative error unknown (no 100 m stretch)  ATE %.2f m (aligned %.2f m)\n",
                errors->ate.rmse_m, errors->ate_aligned.rmse_m);
  else if (errors)
    std::printf(
        "KITTI relative error %.2f %%  %.3f deg/100 m (%zu segments)  ATE %.2f m "
        "(aligned %.2f m)\n",
        errors->kitti.translation_percent, errors->kitti.rotation_deg_per_100m,
        errors->kitti.segments.size(), errors->ate.rmse_m, errors->ate_aligned.rmse_m);
  else
    std::printf("no ground truth: errors unknown\n");
  // A TUM file needs the data's times: without them one made up from the rate would pair the
  // poses with the wrong data, so only the KITTI file is written (odometry_run.h).
  if (!run.has_frame_times)
    note(
        "the data has no frame times: no trajectory_tum.txt (its times would be made up); "
        "trajectory_kitti.txt holds the poses, line i for frame i of the run, and "
        "trajectory.csv the dataset's frame numbers");
  std::cout << "wrote " << (run.has_frame_times ? "trajectory_tum.txt, " : "")
            << "trajectory_kitti.txt, trajectory.csv, summary.json"
            << (errors ? ", trajectory.png" : "") << " to " << out.string() << "\n";
  if (run.interrupted) return interruptedRun("odometry", run.frames.size(), total, out.string());
  return 0;
}

}  // namespace

const CommandSpec& odometryCommand() {
  static const CommandSpec command{
      "odometry",
      "LiDAR odometry from the scans alone -> trajectories, summary.json, trajectory.png",
      datasetOptions("the run whose scans to register",
                     {
                         {"out", Value::kText, "DIR", "", "output folder", kRequired},
                         {"config", Value::kText, "FILE", "",
                          "a config whose odometry: section to use (default: built-in defaults)"},
                         maxFramesOption(),
                     },
                     /*odometry_option=*/false, /*labels_option=*/false),
      kDatasetNotes,
      runOdometryCommand,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
