// LiDAR odometry (odometry/): registration of synthetic scans with known motion, deskewing of a
// swept scan, degenerate input, the KITTI relative error against hand-computed values, the
// odometry command's pipeline on a tiny simulated run, and the real KITTI sample.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "semsegmap/core/binary_io.h"
#include "semsegmap/datasets/lidar_odometry_source.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/eval/odometry_metrics.h"
#include "semsegmap/eval/odometry_run.h"
#include "semsegmap/io/kitti_calib.h"
#include "semsegmap/odometry/lidar_odometry.h"
#include "semsegmap/odometry/motion.h"
#include "semsegmap/settings/config.h"
#if SEMSEGMAP_TEST_PCL
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#endif

namespace semsegmap {
namespace {

// ---- a synthetic world: rectangles sampled at random, a new sample per scan ----

struct Rect {
  Eigen::Vector3d origin, u, v;  // the points origin + a u + b v, a and b in [0, 1]
};

// A street: ground, house fronts on both sides with gaps, poles and boxes that fix every
// direction of motion.
std::vector<Rect> streetWorld() {
  std::vector<Rect> w;
  w.push_back({{-60, -30, 0}, {160, 0, 0}, {0, 60, 0}});  // ground
  for (int k = -5; k < 9; ++k) {
    const double x = 11.0 * k;
    w.push_back({{x, 9, 0}, {7, 0, 0}, {0, 0, 6}});                               // left front
    w.push_back({{x + 3, -9, 0}, {6, 0, 0}, {0, 0, 5}});                          // right front
    w.push_back({{x + 7, 9, 0}, {0, 5, 0}, {0, 0, 6}});                           // side walls
    w.push_back({{x + 5, -1.5 - 0.1 * k, 0}, {0.3, 0, 0}, {0, 0, 3 + 0.1 * k}});  // pole
    w.push_back({{x + 5, -1.2 - 0.1 * k, 0}, {0, 0.3, 0}, {0, 0, 3 + 0.1 * k}});
  }
  return w;
}

// A straight corridor along x: floor and two walls, nothing else.
std::vector<Rect> corridorWorld() {
  return {{{-200, -2, 0}, {400, 0, 0}, {0, 4, 0}},
          {{-200, -2, 0}, {400, 0, 0}, {0, 0, 3}},
          {{-200, 2, 0}, {400, 0, 0}, {0, 0, 3}}};
}

// Points of the world within `range` of the sensor at T_world_sensor, in the sensor frame,
// about `density` points per square metre.
std::vector<LidarPoint> sampleScan(const std::vector<Rect>& world, const Pose& T_world_sensor,
                                   double range, double density, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<LidarPoint> out;
  const Pose T_sensor_world = T_world_sensor.inverse();
  for (const Rect& r : world) {
    const int n = static_cast<int>(density * r.u.cross(r.v).norm());
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p = T_sensor_world * (r.origin + unit(rng) * r.u + unit(rng) * r.v);
      if (p.norm() > range) continue;
      out.push_back(
          {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()), 0.5f});
    }
  }
  return out;
}

Pose motion(double dx, double dy, double yaw_deg) {
  return planarPose(dx, dy, 0.0, yaw_deg * M_PI / 180.0);
}

// ---- registration ----

// Without ground truth the summary's errors are null (as every summary's), and a trajectory
// with no 100 m stretch has no KITTI relative error: null, not 0 %.
TEST(OdometrySummary, UnknownErrorsAreNull) {
  OdometryRun run;
  run.dataset = "scans";
  for (int i = 0; i < 3; ++i) run.trajectory.push_back({0.1 * i, planarPose(i, 0, 0, 0)});
  run.frames.resize(3);
  EXPECT_FALSE(odometryErrors(run).has_value());
  const nlohmann::ordered_json j = toJson(run, odometryErrors(run));
  EXPECT_FALSE(j["has_ground_truth"].get<bool>());
  for (const char* key : {"kitti_relative_error", "ate", "ate_aligned"}) {
    ASSERT_TRUE(j.contains(key)) << key;  // written as null, not left out
    EXPECT_TRUE(j.at(key).is_null()) << key << ": " << j.at(key);
  }
  for (const Pose& T : posesOf(run.trajectory)) run.ground_truth.push_back(T);
  const std::optional<OdometryErrors> errors = odometryErrors(run);
  ASSERT_TRUE(errors.has_value());
  ASSERT_TRUE(errors->kitti.segments.empty());  // 2 m driven
  const nlohmann::ordered_json measured = toJson(run, errors);
  EXPECT_TRUE(measured["kitti_relative_error"]["translation_percent"].is_null());
  EXPECT_EQ(measured["kitti_relative_error"]["segments"], 0);
  EXPECT_NEAR(measured["ate"]["rmse_m"].get<double>(), 0.0, 1e-9);
}

TEST(Odometry, RegistrationRecoversAKnownRigidMotion) {
  const auto world = streetWorld();
  const Pose start = planarPose(0, 0, 1.8, 0);
  const Pose step = motion(0.9, 0.05, 1.5);
  LidarOdometry odom;
  odom.registerFrame(sampleScan(world, start, 60, 40, 1), {}, 0.0);
  const OdometryResult r = odom.registerFrame(sampleScan(world, start * step, 60, 40, 2), {}, 0.1);
  ASSERT_FALSE(r.usedPrediction()) << fallbackName(r.fallback);
  EXPECT_GT(r.correspondences, 500u);
  EXPECT_LT(translationError(r.T_odom_lidar, step), 0.02);
  EXPECT_LT(rotationErrorDeg(r.T_odom_lidar, step), 0.05);
  EXPECT_EQ(r.degenerate_directions, 0);
}

TEST(Odometry, PointToPointAlsoRecoversTheMotion) {
  const auto world = streetWorld();
  const Pose start = planarPose(0, 0, 1.8, 0);
  // Point-to-point needs a closer start than point-to-plane: a sampled map point is rarely
  // where the scan's point is, so its pull is weaker.
  const Pose step = motion(0.3, -0.1, -1.0);
  OdometryConfig config;
  config.icp.metric = IcpMetric::kPointToPoint;
  LidarOdometry odom(config);
  odom.registerFrame(sampleScan(world, start, 60, 40, 3), {}, 0.0);
  const OdometryResult r = odom.registerFrame(sampleScan(world, start * step, 60, 40, 4), {}, 0.1);
  ASSERT_FALSE(r.usedPrediction());
  // Most of the way from the (zero) prediction to the 0.32 m motion.
  EXPECT_LT(translationError(r.T_odom_lidar, step), 0.1);
  EXPECT_LT(rotationErrorDeg(r.T_odom_lidar, step), 0.3);
}

TEST(Odometry, ASequenceAtConstantSpeedStaysOnTrack) {
  const auto world = streetWorld();
  const Pose step = motion(1.0, 0.0, 0.8);
  Pose truth = planarPose(-20, 0, 1.8, 0);
  const Pose start = truth;
  LidarOdometry odom;
  for (int k = 0; k < 30; ++k) {
    const OdometryResult r =
        odom.registerFrame(sampleScan(world, truth, 60, 30, 10 + k), {}, k * 0.1);
    if (k > 0) {
      EXPECT_FALSE(r.usedPrediction()) << k;
    }
    truth = truth * step;
  }
  const Pose truth_last = start.inverse() * truth * step.inverse();
  EXPECT_LT(translationError(odom.pose(), truth_last), 0.15);
  EXPECT_LT(rotationErrorDeg(odom.pose(), truth_last), 0.3);
}

// ---- deskewing ----

TEST(Odometry, DeskewingUndoesAConstantVelocitySweep) {
  // The sensor moves by `sweep` over 0.1 s; a point seen at time t is in the sensor frame of t.
  const Pose sweep = motion(1.2, 0.1, 4.0);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coord(-30, 30), time(0, 0.1);
  std::vector<Eigen::Vector3d> world, seen;
  std::vector<double> times;
  for (int i = 0; i < 1000; ++i) {
    world.emplace_back(coord(rng), coord(rng), coord(rng) / 10);
    times.push_back(time(rng));
    seen.push_back(scaleMotion(sweep, times.back() / 0.1).inverse() * world.back());
  }
  const auto fixed = deskew(seen, times, sweep, 0.1);
  double worst = 0, worst_before = 0;
  for (size_t i = 0; i < world.size(); ++i) {
    worst = std::max(worst, (fixed[i] - world[i]).norm());
    worst_before = std::max(worst_before, (seen[i] - world[i]).norm());
  }
  EXPECT_LT(worst, 1e-9);
  EXPECT_GT(worst_before, 0.5);  // the test means something: the sweep did distort the points
}

// A swept scan of the street: each point in the sensor frame of its own time; the sweep
// covers the frame period.
std::vector<LidarPoint> sweptScan(const std::vector<Rect>& world, const Pose& T_world_start,
                                  const Pose& per_frame, uint32_t seed, std::vector<float>* times) {
  const auto still = sampleScan(world, T_world_start, 60, 30, seed);
  std::vector<LidarPoint> out;
  times->clear();
  for (const LidarPoint& p : still) {
    // The azimuth decides when a spinning sensor looks at a point.
    const double t = 0.1 * (std::atan2(p.y, p.x) + M_PI) / (2 * M_PI);
    const Eigen::Vector3d q =
        scaleMotion(per_frame, t / 0.1).inverse() * Eigen::Vector3d(p.x, p.y, p.z);
    out.push_back({static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()),
                   p.intensity});
    times->push_back(static_cast<float>(t));
  }
  return out;
}

double sweepRunError(bool deskew) {
  const auto world = streetWorld();
  const Pose step = motion(2.0, 0.0, 3.0);  // 20 m/s and 30 deg/s: a strong distortion
  OdometryConfig config;
  config.deskew = deskew;
  LidarOdometry odom(config);
  Pose truth = planarPose(-20, 0, 1.8, 0);
  const Pose start = truth;
  std::vector<float> times;
  double error = 0;
  for (int k = 0; k < 12; ++k) {
    const auto scan = sweptScan(world, truth, step, 40 + k, &times);
    const OdometryResult r = odom.registerFrame(scan, times, 0.1 * k);
    error = translationError(r.T_odom_lidar, start.inverse() * truth);  // the last frame's
    truth = truth * step;
  }
  return error;
}

TEST(Odometry, DeskewingASweptScanImprovesTheOdometry) {
  const double with = sweepRunError(true), without = sweepRunError(false);
  EXPECT_LT(with, 0.1);
  EXPECT_LT(with, 0.5 * without) << "deskewed " << with << " m, not deskewed " << without << " m";
}

// ---- degenerate input ----

TEST(Odometry, AnEmptyScanContinuesThePrediction) {
  const auto world = streetWorld();
  LidarOdometry odom;
  const Pose step = motion(1.0, 0, 0);
  Pose truth = Pose::Identity();
  for (int k = 0; k < 3; ++k, truth = truth * step)
    odom.registerFrame(sampleScan(world, truth, 60, 30, k), {}, 0.1 * k);
  const OdometryResult empty = odom.registerFrame({}, {}, 0.3);
  EXPECT_EQ(empty.fallback, OdometryFallback::kTooFewPoints);
  EXPECT_TRUE(empty.T_odom_lidar.matrix().allFinite());
  EXPECT_LT(translationError(empty.T_odom_lidar, truth), 0.05);  // where the robot should be
  std::vector<LidarPoint> few(10, LidarPoint{5, 1, 0, 0});
  EXPECT_EQ(odom.registerFrame(few, {}, 0.4).fallback, OdometryFallback::kTooFewPoints);
  // The run goes on: the next full scan registers again.
  truth = truth * step * step;
  const OdometryResult back = odom.registerFrame(sampleScan(world, truth, 60, 30, 9), {}, 0.5);
  EXPECT_FALSE(back.usedPrediction());
  EXPECT_LT(translationError(back.T_odom_lidar, truth), 0.05);
}

TEST(Odometry, NanPointsAreSkippedAndCounted) {
  const auto world = streetWorld();
  auto scan = sampleScan(world, Pose::Identity(), 60, 30, 1);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  scan.push_back({nan, 1, 1, 0});
  scan.push_back({1, std::numeric_limits<float>::infinity(), 1, 0});
  LidarOdometry odom;
  odom.registerFrame(scan, {}, 0.0);
  const OdometryResult r = odom.registerFrame(scan, {}, 0.1);
  EXPECT_EQ(r.skipped_nonfinite, 2u);
  EXPECT_TRUE(r.T_odom_lidar.matrix().allFinite());
  EXPECT_LT(r.T_odom_lidar.translation().norm(), 0.01);
}

TEST(Odometry, StandingStillStaysPut) {
  const auto world = streetWorld();
  LidarOdometry odom;
  for (int k = 0; k < 10; ++k) {
    const OdometryResult r =
        odom.registerFrame(sampleScan(world, Pose::Identity(), 60, 30, k), {}, 0.1 * k);
    if (k > 0) {
      EXPECT_FALSE(r.usedPrediction());
    }
  }
  // Each scan samples the surfaces anew: the pose wanders by that noise only.
  EXPECT_LT(odom.pose().translation().norm(), 0.02);
  EXPECT_LT(rotationErrorDeg(odom.pose(), Pose::Identity()), 0.03);
}

TEST(Odometry, ACorridorIsDegenerateAlongItAndKeepsThePrediction) {
  const auto world = corridorWorld();
  LidarOdometry odom;
  const Pose step = motion(1.0, 0, 0);
  Pose truth = planarPose(0, 0.3, 1.0, 0);
  const Pose start = truth;
  OdometryResult r;
  for (int k = 0; k < 6; ++k, truth = truth * step) {
    r = odom.registerFrame(sampleScan(world, truth, 40, 40, 20 + k), {}, 0.1 * k);
    ASSERT_TRUE(r.T_odom_lidar.matrix().allFinite());
  }
  EXPECT_GE(r.degenerate_directions, 1);
  // Across the corridor, height and rotation are observed; along it the scans say nothing, so
  // the pose stays about where the (zero) first prediction put it, 5 m behind the truth, rather
  // than running off.
  const Pose truth_last = start.inverse() * truth * step.inverse();
  EXPECT_LT(std::abs(r.T_odom_lidar.translation().y() - truth_last.translation().y()), 0.03);
  EXPECT_LT(std::abs(r.T_odom_lidar.translation().z()), 0.03);
  EXPECT_LT(rotationErrorDeg(r.T_odom_lidar, truth_last), 0.2);
  EXPECT_LT(std::abs(r.T_odom_lidar.translation().x()), 1.0);
}

// ---- the KITTI relative error, against values worked out by hand ----

// 201 poses one metre apart along x.
std::vector<Pose> straightLine() {
  std::vector<Pose> poses;
  for (int i = 0; i <= 200; ++i) poses.push_back(planarPose(i, 0, 0, 0));
  return poses;
}

TEST(KittiError, AScaleErrorIsItsPercentage) {
  const auto gt = straightLine();
  std::vector<Pose> est;
  for (const Pose& p : gt) est.push_back(planarPose(1.01 * p.translation().x(), 0, 0, 0));
  const KittiRelativeError e = kittiRelativeError(est, gt);
  // 100 m segments end at the first frame more than 100 m on: frame f + 101, so they start at
  // 0, 10, ..., 90 (10 segments); no 200 m segment fits. Each has 101 m of truth against
  // 102.01 m estimated: 1.01 m over 100 m.
  ASSERT_EQ(e.segments.size(), 10u);
  EXPECT_EQ(e.segments.front().last_frame, 101u);
  EXPECT_EQ(e.segments.back().first_frame, 90u);
  EXPECT_NEAR(e.translation_percent, 1.01, 1e-9);
  EXPECT_NEAR(e.rotation_deg_per_100m, 0.0, 1e-6);
  ASSERT_EQ(e.by_length.size(), 1u);
  EXPECT_EQ(e.by_length[0].length_m, 100.0);
}

TEST(KittiError, AYawDriftIsItsAnglePerLength) {
  const auto gt = straightLine();
  const double eps = 1e-4;  // radians of yaw error per frame
  std::vector<Pose> est;
  for (size_t i = 0; i < gt.size(); ++i)
    est.push_back(gt[i] * planarPose(0, 0, 0, eps * static_cast<double>(i)));
  const KittiRelativeError e = kittiRelativeError(est, gt);
  // Over a segment of 101 frames the estimate turns by 101 eps more than the truth: 101e-4 rad
  // over 100 m = 0.5787 deg / 100 m.
  EXPECT_NEAR(e.rotation_deg_per_100m, 101e-4 / 100.0 * 180.0 / M_PI * 100.0, 1e-6);
}

TEST(KittiError, ATrajectoryShorterThanTheShortestSegmentHasNone) {
  std::vector<Pose> gt(50, Pose::Identity());
  for (size_t i = 0; i < gt.size(); ++i) gt[i].translation().x() = static_cast<double>(i);
  const KittiRelativeError e = kittiRelativeError(gt, gt);
  EXPECT_TRUE(e.segments.empty());
  EXPECT_EQ(e.translation_percent, 0.0);
  EXPECT_THROW(kittiRelativeError(gt, {}), std::invalid_argument);
}

// ---- the odometry: section of a config ----

TEST(OdometryConfig, IsReadFromItsSectionAndTyposFail) {
  const auto dir = std::filesystem::temp_directory_path() / "semsegmap_odometry_config";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "good.yaml") << "odometry:\n  voxel_size_m: 0.5\n  deskew: false\n"
                                   << "  icp:\n    metric: point_to_point\n";
  const OdometryConfig c = loadOdometryConfig(dir / "good.yaml");
  EXPECT_EQ(c.voxel_size_m, 0.5);
  EXPECT_FALSE(c.deskew);
  EXPECT_EQ(c.icp.metric, IcpMetric::kPointToPoint);
  EXPECT_EQ(c.max_range_m, OdometryConfig{}.max_range_m);  // untouched keys keep the default
  std::ofstream(dir / "typo.yaml") << "odometry:\n  voxel_size: 0.5\n";
  EXPECT_THROW(loadPipelineConfig(dir / "typo.yaml"), std::runtime_error);
  std::ofstream(dir / "bad.yaml") << "odometry:\n  icp:\n    metric: point_to_line\n";
  EXPECT_THROW(loadOdometryConfig(dir / "bad.yaml"), std::runtime_error);
  std::filesystem::remove_all(dir);
}

// ---- a dataset with poses from its own scans ----

// Frames of the synthetic street, driven at 1 m a frame, with a LiDAR mounted 1.8 m up and
// 0.5 m forward on the base.
class StreetSource : public FrameSource {
 public:
  StreetSource() {
    info_.name = "street";
    info_.rig.T_base_lidar = planarPose(0.5, 0, 1.8, 0);
    info_.has_ground_truth_poses = true;
  }
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return 12; }
  Frame frame(size_t index) override {
    ++reads;
    Frame f;
    f.index = index;
    f.timestamp_s = 0.2 * static_cast<double>(index);
    f.T_world_base = planarPose(-10 + static_cast<double>(index), 0.5, 0, 0.03 * index);
    f.points = sampleScan(world_, *f.T_world_base * info_.rig.T_base_lidar, 60, 30,
                          static_cast<uint32_t>(index));
    return f;
  }
  int reads = 0;

 private:
  DatasetInfo info_;
  std::vector<Rect> world_ = streetWorld();
};

TEST(LidarOdometrySource, FramesGetTheBasePoseFromTheScans) {
  auto owned = std::make_unique<StreetSource>();
  StreetSource* street = owned.get();
  StreetSource truth;
  auto source = withLidarOdometry(std::move(owned), OdometryConfig{});
  EXPECT_TRUE(source->info().has_odometry);
  EXPECT_EQ(source->size(), 12u);
  const Frame f5 = source->frame(5);  // registers frames 0..5
  EXPECT_EQ(street->reads, 6);
  const Pose gt0 = *truth.frame(0).T_world_base;
  const Pose expected5 = gt0.inverse() * *truth.frame(5).T_world_base;
  EXPECT_LT(translationError(f5.T_odom_base, expected5), 0.05);
  EXPECT_LT(rotationErrorDeg(f5.T_odom_base, expected5), 0.1);
  // An earlier frame is read again and keeps its pose; nothing is registered twice.
  const Frame f2 = source->frame(2);
  EXPECT_EQ(street->reads, 7);
  const Pose expected2 = gt0.inverse() * *truth.frame(2).T_world_base;
  EXPECT_LT(translationError(f2.T_odom_base, expected2), 0.05);
  EXPECT_EQ(source->frame(0).T_odom_base.matrix(), Pose::Identity().matrix());
  EXPECT_THROW(source->frame(12), std::out_of_range);
}

// ---- the simulator's sweep, and the odometry over a simulated run ----

#if SEMSEGMAP_WITH_SIM
uint64_t scanHash(const Frame& f) {
  const uint64_t h = fnv1a64(f.points.data(), f.points.size() * sizeof(LidarPoint));
  return fnv1a64(f.point_labels.data(), f.point_labels.size() * sizeof(PointLabel), h);
}

TEST(SimSweep, WithoutTheOptionFramesAreAsBefore) {
  // Without the option the simulator takes the path it took before sweeps existed (commit
  // 0cae890: 111407 points in frame 0). Exact hashes of those points are not compared: Embree's
  // ray tracing rounds differently on CPUs with other vector units (an AMD and an Intel machine
  // of the same kind gave other bits for the same count), so the test compares runs here.
  auto source = openDataset("sim:world=1,preset=tiny,cameras=0");
  auto explicit_off = openDataset("sim:world=1,preset=tiny,cameras=0,sweep=0");
  const Frame f0 = source->frame(0), f3 = source->frame(3);
  EXPECT_EQ(f0.points.size(), 111407u);
  EXPECT_EQ(scanHash(f0), scanHash(explicit_off->frame(0)));
  EXPECT_EQ(scanHash(f3), scanHash(explicit_off->frame(3)));
  EXPECT_NE(scanHash(f0), scanHash(f3));
  EXPECT_TRUE(f0.point_times.empty());
}

TEST(SimSweep, ASweepTimesEveryPointAndDistortsTheScan) {
  auto still = openDataset("sim:world=1,preset=tiny,cameras=0,frames=4");
  auto swept = openDataset("sim:world=1,preset=tiny,cameras=0,frames=4,sweep=1");
  const Frame a = still->frame(2), b = swept->frame(2);
  ASSERT_EQ(b.point_times.size(), b.points.size());
  const double period = 1.0 / swept->info().rig.rate_hz;
  const double sweep = period * swept->info().rig.lidar.hfov_deg / 360.0;
  float lo = 1e9f, hi = -1e9f;
  for (const float t : b.point_times) lo = std::min(lo, t), hi = std::max(hi, t);
  EXPECT_GE(lo, 0.0f);
  EXPECT_LT(hi, sweep);
  EXPECT_GT(hi, 0.9 * sweep);  // the columns span the sweep
  EXPECT_NE(scanHash(a), scanHash(b));
  // The first column is measured at the frame's time: its points are where the still scan has
  // them.
  EXPECT_EQ(a.points.front().x, b.points.front().x);
}

// The odometry as `semsegmap odometry` runs it, on a short simulated drive.
OdometryRun simulatedRun(const std::string& spec, const std::filesystem::path& out) {
  auto source = openDataset(spec);
  OdometryRun run = runLidarOdometry(*source, OdometryConfig{}, 0);
  writeOdometryFiles(out, run);
  return run;
}

void expectGoodRun(const OdometryRun& run, const std::filesystem::path& out) {
  for (const char* file :
       {"trajectory_tum.txt", "trajectory_kitti.txt", "summary.json", "trajectory.png"})
    EXPECT_TRUE(std::filesystem::exists(out / file)) << file;
  const auto errors = odometryErrors(run);
  ASSERT_TRUE(errors.has_value());
  size_t predicted = 0;
  for (const OdometryResult& r : run.frames) predicted += r.usedPrediction();
  EXPECT_EQ(predicted, 1u);  // the first frame only
  // 40 frames of 1 m: the loose bound of a run that worked.
  EXPECT_LT(errors->ate.rmse_m, 0.5);
  EXPECT_LT(errors->ate.rotation_mean_deg, 1.0);
}

TEST(OdometryRun, ATinySimulatedRunEndToEnd) {
  const auto out = std::filesystem::temp_directory_path() / "semsegmap_odometry_e2e";
  std::filesystem::remove_all(out);
  expectGoodRun(simulatedRun("sim:world=1,preset=tiny,cameras=0,frames=40", out), out);
  std::filesystem::remove_all(out);
}

TEST(OdometryRun, ATinySimulatedRunWithMotionDistortion) {
  const auto out = std::filesystem::temp_directory_path() / "semsegmap_odometry_e2e_sweep";
  std::filesystem::remove_all(out);
  const OdometryRun run = simulatedRun("sim:world=1,preset=tiny,cameras=0,frames=40,sweep=1", out);
  expectGoodRun(run, out);
  EXPECT_TRUE(run.frames.back().deskewed);
  std::filesystem::remove_all(out);
}
#endif

// ---- the real KITTI samples ----

const std::filesystem::path kKittiSparse =
    std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti_odometry_00_sparse";

// The target (3 cm and 0.1 deg a frame) where the sample's scans and ground truth agree: the two
// consecutive pairs of the sparse set driven at cruising speed, frames 94-95 and 198-199, each
// registered from a standing start (no velocity to predict from). At the start of the sequence
// (frames 0-9, the test below) the scans and poses.txt disagree by 0.14-0.18 m a frame.
TEST(OdometryOnRealScans, Kitti00ConsecutivePairsMeetTheTarget) {
  if (!std::filesystem::exists(kKittiSparse / "poses.txt"))
    GTEST_SKIP() << "no real KITTI sample (" << kKittiSparse.string()
                 << "): ../shared/data is not beside this checkout";
  const Pose Tr = KittiCalibFile(kKittiSparse / "calib.txt").transform3x4("Tr");
  const std::vector<Pose> gt = kittiLidarPoses(readKittiPoses(kKittiSparse / "poses.txt"), Tr);
  double t_sum = 0, r_sum = 0;
  for (size_t first : {94, 198}) {
    LidarOdometry odom;
    std::vector<Pose> est;
    for (size_t i : {first, first + 1}) {
      char name[24];
      std::snprintf(name, sizeof(name), "velodyne/%06zu.bin", i);
      const Frame scan = kittiScanFrame(i, 0.1 * i, kKittiSparse / name);
      est.push_back(odom.registerFrame(scan.points, {}, scan.timestamp_s).T_odom_lidar);
    }
    const Pose d_gt = gt[first].inverse() * gt[first + 1];
    const Pose d_est = est[0].inverse() * est[1];
    std::printf("KITTI 00 frames %zu-%zu: %.4f m, %.4f deg (moved %.3f m)\n", first, first + 1,
                translationError(d_est, d_gt), rotationErrorDeg(d_est, d_gt),
                d_gt.translation().norm());
    t_sum += translationError(d_est, d_gt) / 2;
    r_sum += rotationErrorDeg(d_est, d_gt) / 2;
  }
  EXPECT_LT(t_sum, 0.03);
  EXPECT_LT(r_sum, 0.1);
}

#if SEMSEGMAP_TEST_PCL
const std::filesystem::path kKitti =
    std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti00_first10_pcd";

std::vector<LidarPoint> loadKittiScan(int index) {
  char name[16];
  std::snprintf(name, sizeof(name), "%06d.pcd", index);
  pcl::PointCloud<pcl::PointXYZ> cloud;
  if (pcl::io::loadPCDFile((kKitti / name).string(), cloud) != 0)
    throw std::runtime_error((kKitti / name).string() + ": cannot read the PCD");
  std::vector<LidarPoint> points;
  points.reserve(cloud.size());
  for (const auto& p : cloud.points) points.push_back({p.x, p.y, p.z, 0.0f});
  return points;
}

// The target was 3 cm and 0.1 deg. These scans do not allow it against this ground
// truth: scan to scan, PCL's GICP finds 0.64 m from scan 0 to 1 and 2.11 m from 0 to 3 where
// poses.txt has 0.86 m and 2.58 m (docs/odometry.md), and this odometry finds the same 0.68 m
// to 0.80 m a frame. The bound is what the odometry achieves, so that a regression shows.
TEST(OdometryOnRealScans, Kitti00FrameToFrameError) {
  if (!std::filesystem::exists(kKitti / "poses.txt"))
    GTEST_SKIP() << "no real KITTI sample (" << kKitti.string()
                 << "): ../shared/data is not beside this checkout";
  const Pose Tr = KittiCalibFile(kKitti / "calib.txt").transform3x4("Tr");
  const std::vector<Pose> gt = kittiLidarPoses(readKittiPoses(kKitti / "poses.txt"), Tr);
  ASSERT_EQ(gt.size(), 10u);
  LidarOdometry odom;
  std::vector<Pose> est;
  for (int i = 0; i < 10; ++i) {
    const OdometryResult r = odom.registerFrame(loadKittiScan(i), {}, 0.1 * i);
    if (i > 0) {
      EXPECT_FALSE(r.usedPrediction()) << "frame " << i << ": " << fallbackName(r.fallback);
    }
    est.push_back(r.T_odom_lidar);
  }
  double t_sum = 0, r_sum = 0;
  for (int i = 1; i < 10; ++i) {
    const Pose d_est = est[i - 1].inverse() * est[i], d_gt = gt[i - 1].inverse() * gt[i];
    t_sum += translationError(d_est, d_gt);
    r_sum += rotationErrorDeg(d_est, d_gt);
  }
  std::printf("KITTI 00 frames 0-9: mean frame-to-frame error %.4f m, %.4f deg\n", t_sum / 9,
              r_sum / 9);
  EXPECT_LT(t_sum / 9, 0.13);
  EXPECT_LT(r_sum / 9, 0.2);
}
#endif

}  // namespace
}  // namespace semsegmap
