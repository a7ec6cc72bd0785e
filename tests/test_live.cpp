// The live core without ROS (pipeline/frame_assembly.h, pipeline/live_session.h): frames made of
// scans, pictures and odometry as they arrive (in order or not, late or never), a worker that
// falls behind and drops, and the same poses as the offline run when it never drops.
#include <gtest/gtest.h>
#include <omp.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <thread>

#include <Eigen/Geometry>

#include "build_options.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/io/folder_follower.h"
#include "semsegmap/pipeline/live_session.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/settings/config.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

ScanMessage scanAt(double t) {
  ScanMessage s;
  s.stamp_s = t;
  s.points = {{1.0f, 2.0f, 0.5f, static_cast<float>(t)}};
  return s;
}

// A picture that says which it is: its one pixel's value.
PictureMessage pictureAt(double t, uint8_t id) {
  PictureMessage p;
  p.stamp_s = t;
  p.rgb = Image(1, 1, 3);
  p.rgb.at(0, 0)[0] = id;
  return p;
}

StampedPose odometryAt(double t) {
  return {t, Pose(Eigen::Translation3d(10.0 * t, 0.0, 0.0))};  // 10 m/s along x
}

FrameAssemblyConfig twoCameras() {
  FrameAssemblyConfig c;
  c.cameras = 2;
  return c;
}

TEST(FrameAssembly, AScanGetsTheNearestPictureOfEachCameraAndItsOdometryInterpolated) {
  FrameAssembler a(twoCameras());
  for (int i = 0; i <= 30; ++i) a.addOdometry(odometryAt(0.01 * i));  // 100 Hz
  a.addPicture(0, pictureAt(0.08, 1));
  a.addPicture(0, pictureAt(0.11, 2));
  a.addScan(scanAt(0.1));
  EXPECT_TRUE(a.takeReady().empty()) << "camera 1 has sent nothing yet";
  a.addPicture(1, pictureAt(0.095, 3));
  EXPECT_TRUE(a.takeReady().empty()) << "a nearer picture of camera 1 may still come";
  a.addPicture(1, pictureAt(0.13, 4));
  const std::vector<Frame> frames = a.takeReady();
  ASSERT_EQ(frames.size(), 1u);
  const Frame& f = frames[0];
  EXPECT_EQ(f.index, 0u);
  EXPECT_DOUBLE_EQ(f.timestamp_s, 0.1);
  ASSERT_EQ(f.cameras.size(), 2u);
  EXPECT_EQ(f.cameras[0].rgb.at(0, 0)[0], 2) << "0.11 is nearer 0.1 than 0.08";
  EXPECT_EQ(f.cameras[1].rgb.at(0, 0)[0], 3);
  EXPECT_NEAR(f.T_odom_base.translation().x(), 1.0, 1e-9);
  EXPECT_EQ(a.stats().missing_pictures, 0u);
}

TEST(FrameAssembly, FramesComeInScanOrderAndAnOlderScanIsDropped) {
  FrameAssemblyConfig c;
  c.odometry = false;
  FrameAssembler a(c);
  a.addScan(scanAt(0.2));
  a.addScan(scanAt(0.1));  // came late, but before 0.2 was made: put in its place
  std::vector<Frame> frames = a.takeReady();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_DOUBLE_EQ(frames[0].timestamp_s, 0.1);
  EXPECT_DOUBLE_EQ(frames[1].timestamp_s, 0.2);
  EXPECT_EQ(frames[1].index, 1u);
  a.addScan(scanAt(0.15));  // older than a frame already made
  EXPECT_TRUE(a.takeReady().empty());
  EXPECT_EQ(a.stats().out_of_order, 1u);
  EXPECT_EQ(a.stats().scans, 3u);
  EXPECT_EQ(a.stats().frames, 2u);
}

TEST(FrameAssembly, ALatePictureIsWaitedForAndOneThatNeverComesIsGoneWithout) {
  FrameAssemblyConfig c = twoCameras();
  c.odometry = false;
  c.max_wait_s = 0.25;
  FrameAssembler a(c);
  a.addScan(scanAt(0.0));
  a.addPicture(0, pictureAt(0.01, 7));
  a.addScan(scanAt(0.1));
  a.addScan(scanAt(0.2));
  EXPECT_TRUE(a.takeReady().empty()) << "camera 1 is late, but within max_wait_s";
  a.addPicture(1, pictureAt(0.005, 8));  // arrives after two later scans
  std::vector<Frame> frames = a.takeReady();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].cameras[1].rgb.at(0, 0)[0], 8);
  // Camera 0 stops: scan 0.1 waits for it until a scan 0.25 s later has come.
  a.addScan(scanAt(0.3));
  EXPECT_TRUE(a.takeReady().empty());
  a.addScan(scanAt(0.35));
  frames = a.takeReady();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_DOUBLE_EQ(frames[0].timestamp_s, 0.1);
  EXPECT_TRUE(frames[0].cameras[0].rgb.empty()) << "0.01 is too far from 0.1";
  EXPECT_TRUE(frames[0].cameras[1].rgb.empty());
  EXPECT_EQ(a.stats().missing_pictures, 2u);
  // At the end every waiting scan goes, with what it has.
  EXPECT_EQ(a.flush().size(), 3u);
  EXPECT_THROW(a.addPicture(2, pictureAt(0.4, 1)), std::invalid_argument);
}

TEST(FrameAssembly, AScanWithoutOdometryAroundItIsSkippedNeverGivenAPose) {
  FrameAssemblyConfig c;
  c.max_odometry_gap_s = 0.15;
  c.max_wait_s = 0.25;
  FrameAssembler a(c);
  a.addScan(scanAt(0.0));  // before the first odometry message
  for (double t : {0.05, 0.1, 0.2, 0.5, 0.6}) a.addOdometry(odometryAt(t));  // 0.2..0.5 missing
  for (double t : {0.1, 0.3, 0.4, 0.55}) a.addScan(scanAt(t));
  std::vector<Frame> frames = a.takeReady();
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_DOUBLE_EQ(frames[0].timestamp_s, 0.1);
  EXPECT_DOUBLE_EQ(frames[1].timestamp_s, 0.55);
  EXPECT_NEAR(frames[1].T_odom_base.translation().x(), 5.5, 1e-9);
  EXPECT_EQ(a.stats().without_odometry, 3u) << "0.0, 0.3 and 0.4";
  // A scan after the newest odometry waits, and at the end is skipped, not extrapolated.
  a.addScan(scanAt(0.7));
  EXPECT_TRUE(a.takeReady().empty());
  EXPECT_TRUE(a.flush().empty());
  EXPECT_EQ(a.stats().without_odometry, 4u);
}

// Three points as KITTI's float32 x y z intensity.
void writeScan(const std::filesystem::path& path) {
  const float points[] = {1, 2, 3, 0.5f, 4, 5, 6, 0.5f, 7, 8, 9, 0.5f};
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(points), sizeof points);
}

// localize --follow's reader: a file is taken once, when it has its final name, in time order.
TEST(FolderFollower, TakesEachFileOnceWhenRenamedIntoPlaceInTimeOrder) {
  test_support::TempDir tmp;
  FolderFollower follower(tmp.path(), {});
  std::vector<FollowedScan> scans;
  std::vector<FollowedPicture> pictures;
  follower.poll(scans, pictures);
  EXPECT_TRUE(scans.empty());
  writeScan(tmp.path() / "1650000000.200000.bin");
  writeScan(tmp.path() / "1650000000.100000.bin");
  writeScan(tmp.path() / "1650000000.300000.bin.part");  // still being written
  writeScan(tmp.path() / ".1650000000.400000.bin");      // likewise
  follower.poll(scans, pictures);
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_DOUBLE_EQ(scans[0].stamp_s, 1650000000.1);
  EXPECT_DOUBLE_EQ(scans[1].stamp_s, 1650000000.2);
  scans.clear();
  follower.poll(scans, pictures);
  EXPECT_TRUE(scans.empty()) << "each file once";
  std::filesystem::rename(tmp.path() / "1650000000.300000.bin.part",
                          tmp.path() / "1650000000.300000.bin");
  follower.poll(scans, pictures);
  ASSERT_EQ(scans.size(), 1u);
  EXPECT_EQ(scans[0].path.filename(), "1650000000.300000.bin");
  writeScan(tmp.path() / "000042.bin");  // a frame number: no time a live run can use
  try {
    follower.poll(scans, pictures);
    ADD_FAILURE() << "a scan without a time in its name was taken";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("000042.bin"), std::string::npos) << e.what();
  }
}

// A process that takes 20 ms a frame and remembers what it saw.
struct SlowProcess {
  std::vector<double> seen;
  LiveSession::Process process() {
    return [this](const Frame& f) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      seen.push_back(f.timestamp_s);
      std::vector<LivePose> poses(1);
      poses[0].record.frame_index = f.index;
      return poses;
    };
  }
};

LiveConfig noOdometry(size_t queue) {
  LiveConfig c;
  c.assembly.odometry = false;
  c.assembly.max_wait_s = 0.0;
  c.max_queued_frames = queue;
  return c;
}

TEST(LiveSession, FallingBehindDropsTheOldestFramesAndNeverGrowsTheQueue) {
  SlowProcess slow;
  LiveSession live(noOdometry(2), slow.process());
  for (int i = 0; i < 40; ++i) live.addScan(scanAt(0.1 * i));  // far faster than 50 Hz
  live.finish();
  const LiveStats s = live.stats();
  EXPECT_EQ(s.assembly.frames, 40u);
  EXPECT_GT(s.dropped, 20u);
  EXPECT_EQ(s.processed + s.dropped, 40u);
  EXPECT_LE(s.max_queued, 2u);
  EXPECT_EQ(live.poll().size(), s.processed);
  EXPECT_TRUE(std::is_sorted(slow.seen.begin(), slow.seen.end()));
  EXPECT_DOUBLE_EQ(slow.seen.back(), 3.9) << "the newest frame is never the one dropped";
  EXPECT_GE(s.max_latency_ms, 20.0);
}

TEST(LiveSession, OfflineNothingIsDroppedAndTheOrderIsKept) {
  SlowProcess slow;
  LiveConfig c = noOdometry(2);
  c.never_drop = true;
  LiveSession live(c, slow.process());
  for (int i = 0; i < 15; ++i) live.addScan(scanAt(0.1 * i));
  live.finish();
  EXPECT_EQ(live.stats().dropped, 0u);
  ASSERT_EQ(slow.seen.size(), 15u);
  for (size_t i = 0; i < slow.seen.size(); ++i) EXPECT_DOUBLE_EQ(slow.seen[i], 0.1 * i);
  const std::vector<LivePose> poses = live.poll();
  ASSERT_EQ(poses.size(), 15u);
  EXPECT_EQ(poses.back().record.frame_index, 14u);
  EXPECT_TRUE(live.poll().empty()) << "each pose is handed out once";
}

TEST(LiveSession, AFrameTheWorkerCannotWorkOnIsTheCallersError) {
  LiveSession live(noOdometry(2), [](const Frame& f) -> std::vector<LivePose> {
    if (f.index == 1) throw std::runtime_error("scan 1: NaN point");
    return {};
  });
  live.addScan(scanAt(0.0));
  live.addScan(scanAt(0.1));
  EXPECT_THROW(live.finish(), std::runtime_error);
}

// Offline the caller waits for room in the queue; once the worker has failed there will be none,
// and the caller gets the worker's error instead of waiting for ever.
TEST(LiveSession, OfflineACallerWaitingForRoomGetsTheWorkersError) {
  LiveConfig c = noOdometry(1);
  c.never_drop = true;
  LiveSession live(c, [](const Frame& f) -> std::vector<LivePose> {
    if (f.index == 0) throw std::runtime_error("scan 0: NaN point");
    return {};
  });
  EXPECT_THROW(
      {
        for (int i = 0; i < 10; ++i) live.addScan(scanAt(0.1 * i));
      },
      std::runtime_error);
}

// The worker is a fresh thread, and a thread's first use of torch set its OpenMP count to one:
// the enrichment in the worker then ran on one core. The worker keeps its count.
TEST(LiveSession, TheWorkersOpenMpLoopsKeepEveryCoreAfterDescribing) {
  SEMSEGMAP_SKIP_WITHOUT_TORCH();
  DescriptorConfig config;
  config.kind = "semsegmap-net";
  config.model = std::string(SEMSEGMAP_SOURCE_DIR) + "/models/semsegmap-net.model";
  const std::shared_ptr<Describer> describer = makeDescriber(config);
  EnrichedCloud points(64);
  for (size_t i = 0; i < points.size(); ++i) {
    points[i].x = 0.1f * static_cast<float>(i % 8);
    points[i].y = 0.1f * static_cast<float>(i / 8);
    points[i].z = 0.05f * static_cast<float>(i % 3);
  }
  const int cores = omp_get_max_threads();
  int in_worker = 0;
  LiveSession live(noOdometry(2), [&](const Frame&) {
    describer->describe({DescriptorInput{&points}});
    in_worker = omp_get_max_threads();
    return std::vector<LivePose>{};
  });
  live.addScan(scanAt(0.0));
  live.finish();
  EXPECT_EQ(in_worker, cores);
}

// The live path gives the offline run's poses: the simulator's frames split into messages
// (pictures and odometry at their own times, in another order than the scans) and fed through a
// live session that never drops.
TEST(LiveSession, LocalizesAsTheOfflineRunFromTheSameMessages) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  PipelineConfig config =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/segmap.yaml");
  config.descriptor.kind = "eigen";
  const auto describer = std::shared_ptr<Describer>(makeDescriber(config.descriptor));
  auto mapping = openDataset("sim:world=1,run=S2,preset=tiny,frames=50");
  const auto map = std::make_shared<const TargetMap>(
      runMapping(*mapping, config, PoseSource::kGroundTruth, describer).map);
  const std::string query = "sim:world=1,run=S2,preset=tiny,frames=50,condition=sunrise";
  auto offline_source = openDataset(query);
  const LocalizationRun offline = runLocalization(*offline_source, config, map, describer);
  ASSERT_GT(offline.localizations.size(), 5u);

  auto source = openDataset(query);
  LocalizationSession session(config, source->info(), map, describer);
  session.keepHistory(false);  // as the node: the poses go out, the session keeps the latest
  LiveConfig c;
  c.assembly.cameras = source->info().rig.cameras.size();
  c.never_drop = true;
  LiveSession live(c, localizingProcess(session));
  for (size_t i = 0; i < source->size(); ++i) {
    const Frame f = source->frame(i);
    live.addOdometry({f.timestamp_s, f.T_odom_base});
    ScanMessage scan;
    scan.stamp_s = f.timestamp_s;
    scan.points = f.points;
    live.addScan(std::move(scan));  // before its pictures: it waits for them
    for (size_t k = 0; k < f.cameras.size(); ++k)
      live.addPicture(k, {f.timestamp_s + 0.01, f.cameras[k].rgb, f.cameras[k].label});
  }
  live.finish();
  const std::vector<LivePose> poses = live.poll();
  ASSERT_EQ(poses.size(), offline.localizations.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    const LocalizationRecord& o = offline.localizations[i];
    EXPECT_EQ(poses[i].record.frame_index, o.frame_index);
    EXPECT_LT(translationError(poses[i].record.T_map_base, o.T_map_base), 1e-6);
    const Pose composed = poses[i].T_map_odom * offline.trajectory_odom[o.frame_index];
    EXPECT_LT(translationError(composed, o.T_map_base), 1e-6) << "map -> odom -> base";
  }
  EXPECT_EQ(live.stats().dropped, 0u);
  EXPECT_EQ(live.stats().assembly.missing_pictures, 0u);
  // No history: the latest frame and localization alone; the counts and the distance cover the
  // run.
  const LocalizationRun& kept = session.run();
  EXPECT_EQ(kept.trajectory_odom.size(), 1u);
  EXPECT_EQ(kept.frames.size(), 1u);
  ASSERT_EQ(kept.localizations.size(), 1u);
  EXPECT_EQ(kept.localizations[0].frame_index, offline.localizations.back().frame_index);
  EXPECT_EQ(kept.stats.frames, offline.stats.frames);
  EXPECT_NEAR(kept.distance_m, offline.distance_m, 1e-9);
}

}  // namespace
}  // namespace semsegmap
