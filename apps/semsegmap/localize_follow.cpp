#include "localize_follow.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <thread>

#include <Eigen/Geometry>

#include "dataset_args.h"
#include "interrupt.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/io/folder_follower.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/point_cloud_file.h"
#include "semsegmap/pipeline/live_session.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

namespace {

// How often the folder is listed: a tenth of a 10 Hz LiDAR's period keeps the latency a scan
// waits to be seen small beside the frame's work, and a listing costs microseconds.
constexpr auto kPollPeriod = std::chrono::milliseconds(10);

FolderFollower openFollower(const CliArgs& a) {
  const std::string spec = a.get("dataset");  // folder:..., checked by runLocalize
  const std::string prefix = "folder:";
  FolderOptions options;
  if (a.has("rig")) options.rig = a.get("rig");
  const std::filesystem::path dir = parseFolderSpec(spec, spec.substr(prefix.size()), options);
  return FolderFollower(dir, options);
}

void printPose(const LivePose& p) {
  const Pose& T = p.record.T_map_base;
  const double yaw = std::atan2(T.linear()(1, 0), T.linear()(0, 0)) * 180.0 / M_PI;
  std::printf("pose t=%.6f  x %.3f  y %.3f  z %.3f  yaw %.2f deg  (%s, %.0f ms after the scan)\n",
              p.record.timestamp_s.value_or(0.0), T.translation().x(), T.translation().y(),
              T.translation().z(), yaw, localizationPathName(p.record.path), p.latency_ms);
  std::fflush(stdout);
}

// Hands what appeared in the folder to the live session: pictures first, so that a scan finds
// the pictures that came with it.
bool feedNewFiles(FolderFollower& follower, LiveSession& live) {
  std::vector<FollowedScan> scans;
  std::vector<FollowedPicture> pictures;
  follower.poll(scans, pictures);
  for (const FollowedPicture& p : pictures)
    live.addPicture(p.camera, {p.stamp_s, readColorImage(p.path), {}});
  for (const FollowedScan& s : scans) {
    DecodedPoints points = readPointCloudFile(s.path);
    live.addScan(
        {s.stamp_s, std::move(points.points), relativePointTimes(points.times, s.stamp_s)});
  }
  return !scans.empty();
}

}  // namespace

FollowedRun followFolder(const CliArgs& a, const PipelineConfig& config,
                         std::shared_ptr<const TargetMap> map, MapSettingsCheck settings,
                         const std::optional<RelocalizationPrior>& prior,
                         std::shared_ptr<MapTileSource> tiles) {
  FolderFollower follower = openFollower(a);
  // A growing folder has no odometry to read: the LiDAR's, on the scans as they come.
  FrontEndStages stages;
  stages.lidar_odometry = loadOdometryConfig(a.get("config"));
  note("following " + follower.info().name + ": poses from LiDAR odometry on its scans");
  const std::shared_ptr<Describer> describer = describerFor(config.descriptor, follower.info());
  LocalizationSession session(config, follower.info(), map, describer, settings, stages);
  session.setPrior(prior);
  session.followTiles(std::move(tiles));
  LiveConfig live_config;
  live_config.assembly.cameras = follower.info().rig.cameras.size();
  live_config.assembly.odometry = false;
  LiveSession live(live_config, localizingProcess(session));
  const double idle_s = a.has("follow-idle") ? a.getNumber("follow-idle") : 0.0;
  const StopToken stop = stopToken();
  auto last_scan = std::chrono::steady_clock::now();
  while (!stop.stopRequested()) {
    if (feedNewFiles(follower, live)) last_scan = std::chrono::steady_clock::now();
    for (const LivePose& p : live.poll()) printPose(p);
    const std::chrono::duration<double> idle = std::chrono::steady_clock::now() - last_scan;
    if (idle_s > 0 && idle.count() >= idle_s) break;
    std::this_thread::sleep_for(kPollPeriod);
  }
  live.finish();
  for (const LivePose& p : live.poll()) printPose(p);
  const LiveStats s = live.stats();
  std::printf(
      "followed %zu scans: %zu worked on, %zu dropped (the robot outran the pipeline), "
      "latency %.0f ms on average, %.0f at most\n",
      s.assembly.scans, s.processed, s.dropped, s.mean_latency_ms, s.max_latency_ms);
  return {session.take(), follower.info().name};
}

}  // namespace semsegmap::app
