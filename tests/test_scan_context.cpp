// Scan Context (localize/scan_context.h): the yaw between two scans of one place, the distance
// that tells a place from another, scans without a usable point, and the database of mapped
// scans on a synthetic world and on the simulator's.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "build_options.h"
#include "error_text.h"
#include "semsegmap/core/random.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/eval/scan_context_localizer.h"
#include "semsegmap/localize/scan_context.h"

namespace semsegmap {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kSectorDeg = 6.0;  // 360 / the default 60 sectors

// A flat ground and the walls of boxes of random size and height scattered over x in [-60, 140]
// and y in [-100, 60]: every place looks different, and no place looks like itself turned.
std::vector<Eigen::Vector3d> boxWorld(uint64_t seed) {
  SeededRng rng(seed);
  std::vector<Eigen::Vector3d> w;
  for (int i = 0; i < 60000; ++i) w.emplace_back(rng.uniform(-60, 140), rng.uniform(-100, 60), 0);
  for (int b = 0; b < 160; ++b) {
    const Eigen::Vector3d corner(rng.uniform(-60, 140), rng.uniform(-100, 60), 0);
    const Eigen::Vector3d size(rng.uniform(0.5, 8), rng.uniform(0.5, 8), rng.uniform(0.5, 12));
    for (int i = 0; i < 600; ++i) {
      Eigen::Vector3d p(rng.uniform(0, size.x()), rng.uniform(0, size.y()),
                        rng.uniform(0, size.z()));
      const int wall = rng.integer(0, 3);  // onto one of the four walls
      if (wall < 2)
        p.x() = wall == 0 ? 0.0 : size.x();
      else
        p.y() = wall == 2 ? 0.0 : size.y();
      w.push_back(corner + p);
    }
  }
  return w;
}

// What a LiDAR 1.8 m above the ground at (x, y), turned by yaw_deg, sees of the world within
// 70 m (no occlusion: the scan context keeps each bin's highest point anyway).
Pose lidarAt(double x, double y, double yaw_deg) {
  return Eigen::Translation3d(x, y, 1.8) *
         Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitZ());
}

std::vector<LidarPoint> scanAt(const std::vector<Eigen::Vector3d>& world,
                               const Pose& T_world_lidar) {
  std::vector<LidarPoint> scan;
  const Pose T_lidar_world = T_world_lidar.inverse();
  for (const Eigen::Vector3d& p : world) {
    if ((p - T_world_lidar.translation()).head<2>().norm() > 70.0) continue;
    const Eigen::Vector3f q = (T_lidar_world * p).cast<float>();
    scan.push_back({q.x(), q.y(), q.z(), 0.f});
  }
  return scan;
}

double wrappedDeg(double a) {
  return std::remainder(a, 360.0);
}

double yawOf(const Pose& T) {
  return std::atan2(T.linear()(1, 0), T.linear()(0, 0)) / kDeg;
}

TEST(ScanContext, BinsKeepTheHighestPointAndTheRingKeyTheOccupancy) {
  ScanContextConfig c;
  // Ring 0 (0-4 m), sector 0 (0-6 degrees): two points, the higher one counts. Ring 2 (8-12 m),
  // sector 15 (90-96 degrees): one point below the offset still occupies its bin.
  const std::vector<LidarPoint> points = {
      {1.0f, 0.05f, -1.5f, 0.f}, {2.0f, 0.1f, 0.5f, 0.f}, {-0.01f, 10.0f, -2.5f, 0.f}};
  const ScanContext sc = makeScanContext(points, c);
  ASSERT_EQ(sc.bins.rows(), 20);
  ASSERT_EQ(sc.bins.cols(), 60);
  EXPECT_FLOAT_EQ(sc.bins(0, 0), 2.5f);
  EXPECT_GT(sc.bins(2, 15), 0.f);
  EXPECT_EQ(sc.occupied, 2u);
  EXPECT_FLOAT_EQ(sc.ring_key(0), 1.f / 60);
  EXPECT_FLOAT_EQ(sc.ring_key(1), 0.f);
  EXPECT_FLOAT_EQ(sc.ring_key(2), 1.f / 60);
}

// The same place seen turned by a known yaw, both ways round and not only by whole sectors: the
// comparison finds the yaw within one sector, with the sign of T_candidate_query = Rz(yaw).
TEST(ScanContext, YawRecoversAKnownRotationWithinOneSector) {
  const std::vector<Eigen::Vector3d> world = boxWorld(1);
  const ScanContextConfig c;
  const Pose candidate_pose = lidarAt(20, -10, 35);
  const ScanContext candidate = makeScanContext(scanAt(world, candidate_pose), c);
  for (const double yaw : {-172.0, -95.0, -33.0, -8.0, -3.0, 0.0, 2.5, 12.0, 47.0, 90.0, 178.0}) {
    const Pose truth = candidate_pose * Eigen::AngleAxisd(yaw * kDeg, Eigen::Vector3d::UnitZ());
    const ScanContext query = makeScanContext(scanAt(world, truth), c);
    const ScanContextDistance d = scanContextDistance(query, candidate);
    EXPECT_LE(std::abs(wrappedDeg(d.yaw_rad / kDeg - yaw)), kSectorDeg) << "yaw " << yaw;
    EXPECT_GT(d.yaw_rad, -M_PI);
    EXPECT_LE(d.yaw_rad, M_PI);
    // The match's pose turns the candidate's the same way.
    const ScanContextMatch m{0, d, candidate_pose};
    EXPECT_LE(std::abs(wrappedDeg(yawOf(m.T_world_query()) - yawOf(truth))), kSectorDeg)
        << "yaw " << yaw;
    EXPECT_LT(d.distance, c.max_distance) << "yaw " << yaw;
  }
  // By whole sectors the bins are the candidate's, shifted: the distance vanishes.
  const Pose turned = candidate_pose * Eigen::AngleAxisd(-42 * kDeg, Eigen::Vector3d::UnitZ());
  const ScanContextDistance d =
      scanContextDistance(makeScanContext(scanAt(world, turned), c), candidate);
  EXPECT_NEAR(d.yaw_rad / kDeg, -42.0, 1e-6);
  EXPECT_EQ(d.shift, 53u);  // 60 - 7 sectors
  EXPECT_LT(d.distance, 1e-3);
}

TEST(ScanContext, TheSamePlaceIsNearerThanAnotherPlace) {
  const std::vector<Eigen::Vector3d> world = boxWorld(2);
  const ScanContextConfig c;
  const ScanContext here = makeScanContext(scanAt(world, lidarAt(0, 0, 0)), c);
  const ScanContext near_here = makeScanContext(scanAt(world, lidarAt(1.0, 0.5, 30)), c);
  const ScanContext elsewhere = makeScanContext(scanAt(world, lidarAt(80, -40, 30)), c);
  const double same = scanContextDistance(near_here, here).distance;
  const double other = scanContextDistance(near_here, elsewhere).distance;
  EXPECT_LT(same, other);
  EXPECT_LT(same, c.max_distance);
  EXPECT_GT(other, c.max_distance);
}

// Points a driver marks as missing (NaN, inf) are left out; a scan with none left is empty, is
// as far as can be from anything, and neither matches nor is matched.
TEST(ScanContext, ScansWithoutUsablePointsNeverMatch) {
  const std::vector<Eigen::Vector3d> world = boxWorld(3);
  const ScanContextConfig c;
  std::vector<LidarPoint> scan = scanAt(world, lidarAt(0, 0, 0));
  const ScanContext clean = makeScanContext(scan, c);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<LidarPoint> missing = {
      {nan, nan, nan, 0.f}, {inf, 1.f, 0.f, 0.f}, {1.f, -inf, 0.f, 0.f}, {1.f, 2.f, nan, 0.f}};
  scan.insert(scan.end(), missing.begin(), missing.end());
  EXPECT_EQ(makeScanContext(scan, c).bins, clean.bins) << "a NaN or inf point changed a bin";
  const ScanContext none = makeScanContext(missing, c);
  const ScanContext empty = makeScanContext({}, c);
  EXPECT_TRUE(none.empty());
  EXPECT_TRUE(empty.empty());
  EXPECT_DOUBLE_EQ(scanContextDistance(none, clean).distance, 1.0);
  EXPECT_DOUBLE_EQ(scanContextDistance(clean, empty).distance, 1.0);

  ScanContextDatabase db(c);
  EXPECT_FALSE(db.best(clean).has_value()) << "an empty database";
  EXPECT_EQ(db.add(none, lidarAt(0, 0, 0)), 0u);
  EXPECT_FALSE(db.best(clean).has_value()) << "only an empty mapped scan";
  db.add(clean, lidarAt(0, 0, 0));
  EXPECT_FALSE(db.query(none).has_value());
  EXPECT_FALSE(db.best(empty).has_value());
  ASSERT_TRUE(db.query(clean).has_value());
  EXPECT_EQ(db.query(clean)->index, 1u);
}

TEST(ScanContext, RefusesMismatchedGridsInOneLine) {
  ScanContextConfig small;
  small.rings = 10;
  const std::vector<LidarPoint> scan = {{3.f, 1.f, 0.f, 0.f}};
  const ScanContext a = makeScanContext(scan, small), b = makeScanContext(scan, {});
  std::string e = test_support::errorOf([&] { scanContextDistance(a, b); });
  EXPECT_MENTIONS(e, "10 x 60");
  EXPECT_ONE_LINE(e);
  ScanContextDatabase db;
  e = test_support::errorOf([&] { db.add(a, Pose::Identity()); });
  EXPECT_MENTIONS(e, "20 x 60");
  EXPECT_ONE_LINE(e);
  ScanContextConfig none;
  none.sectors = 0;
  EXPECT_THROW(makeScanContext(scan, none), std::invalid_argument);
  EXPECT_THROW(ScanContextDatabase{none}, std::invalid_argument);
}

// Mapped scans every 5 m along a street of the box world; a query 0.9 m from one of them, turned
// round, finds it and the yaw. (Scan Context changes quickly with the place: 2 m from the mapped
// scan and turned by 100 degrees this query scores 0.25, above the threshold.)
TEST(ScanContextDatabase, FindsTheMappedScanNearTheQueryInABoxWorld) {
  const std::vector<Eigen::Vector3d> world = boxWorld(4);
  ScanContextDatabase db;
  for (double x = 0; x <= 100; x += 5)
    db.add(makeScanContext(scanAt(world, lidarAt(x, 0, 0)), {}), lidarAt(x, 0, 0));
  const Pose truth = lidarAt(60.8, 0.4, 150);
  const auto m = db.query(makeScanContext(scanAt(world, truth), {}));
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->index, 12u) << "the scan at x = 60";
  EXPECT_LE(std::abs(wrappedDeg(m->distance.yaw_rad / kDeg - 150)), kSectorDeg);
}

// nearest(): the n mapped scans nearest by scan context, nearest first, the first of them best()'s;
// a scan context rebuilt from its bins (a map file's) compares as the original.
TEST(ScanContextDatabase, NearestListsTheClosestFirstAndBinsRebuildTheScanContext) {
  const std::vector<Eigen::Vector3d> world = boxWorld(4);
  ScanContextDatabase db;
  for (double x = 0; x <= 100; x += 5)
    db.add(makeScanContext(scanAt(world, lidarAt(x, 0, 0)), {}), lidarAt(x, 0, 0));
  const ScanContext query = makeScanContext(scanAt(world, lidarAt(60.8, 0.4, 150)), {});
  const std::vector<ScanContextMatch> near = db.nearest(query, db.size(), 3);
  ASSERT_EQ(near.size(), 3u);
  EXPECT_EQ(near[0].index, db.best(query)->index);
  EXPECT_LE(near[0].distance.distance, near[1].distance.distance);
  EXPECT_LE(near[1].distance.distance, near[2].distance.distance);
  EXPECT_EQ(db.nearest(query, 1, 5).size(), 1u) << "only the ring keys' nearest is compared";
  const ScanContext rebuilt = scanContextOfBins(query.bins);
  EXPECT_EQ(rebuilt.ring_key, query.ring_key);
  EXPECT_EQ(rebuilt.occupied, query.occupied);
  EXPECT_EQ(scanContextDistance(rebuilt, db.scans()[12].context).distance,
            scanContextDistance(query, db.scans()[12].context).distance);
}

// The scan context's frame: the LiDAR's position, the base's orientation.
TEST(ScanContext, ItsFrameIsTheLidarPositionTurnedAsTheBase) {
  const Pose T_world_base = lidarAt(3, 4, 30);
  const Pose T_base_lidar =
      Eigen::Translation3d(0.5, 0, 1.7) * Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX());
  const Pose T = scanContextFrame(T_world_base, T_base_lidar);
  EXPECT_TRUE(T.linear().isApprox(T_world_base.linear()));
  EXPECT_TRUE(T.translation().isApprox((T_world_base * T_base_lidar).translation()));
}

// On the simulator: S1 of the tiny world drives the street of its first 60 frames again from
// frame 395 on. Each query frame there that passes within 2 m of a mapped frame finds a mapped
// scan within a few metres of it, turned by the right yaw.
TEST(ScanContextDatabase, FindsTheMappedScanNearASimulatedRevisit) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  auto source = openDataset("sim:world=1,run=S1,preset=tiny");
  const Pose T_base_lidar = source->info().rig.T_base_lidar;
  ScanContextDatabase db;
  std::vector<Pose> mapped;
  for (size_t i = 0; i < 60; ++i) {
    const Frame f = source->frame(i);
    mapped.push_back(*f.T_world_base * T_base_lidar);
    db.add(makeScanContext(f.points, db.config()), mapped.back());
  }
  size_t near = 0;
  for (size_t i = 400; i <= 440; i += 5) {
    const Frame f = source->frame(i);
    const Pose truth = *f.T_world_base * T_base_lidar;
    double nearest = 1e9;
    for (const Pose& p : mapped)
      nearest = std::min(nearest, (p.translation() - truth.translation()).norm());
    if (nearest > 2.0) continue;
    ++near;
    const auto m = db.query(makeScanContext(f.points, db.config()));
    ASSERT_TRUE(m.has_value()) << "frame " << i;
    EXPECT_LT((m->T_world_candidate.translation() - truth.translation()).norm(), 4.0)
        << "frame " << i << " matched mapped frame " << m->index;
    EXPECT_LE(std::abs(wrappedDeg(yawOf(m->T_world_query()) - yawOf(truth))), 2 * kSectorDeg)
        << "frame " << i;
  }
  EXPECT_GE(near, 5u) << "the revisit passes the mapped frames";
}

// The pose from a match: the candidate's turned by the yaw, registered to the mapped scans near
// it. A query 1.1 m from a mapped scan and turned by 102 degrees lands within centimetres, also
// from a LiDAR mounted upside down (the rig levels its scans); a place nothing was mapped near,
// and a scan of no point, give no pose.
TEST(ScanContextLocalizer, RegistersTheQueryFromTheMatch) {
  const std::vector<Eigen::Vector3d> world = boxWorld(5);
  for (const bool upside_down : {false, true}) {
    Pose T_base_lidar = Pose::Identity();
    if (upside_down)
      T_base_lidar.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).matrix();
    ScanContextLocalizer localizer({}, T_base_lidar);
    for (double x = 0; x <= 100; x += 5) {
      const Pose T_world_lidar = lidarAt(x, 0, 0) * T_base_lidar;
      localizer.addMapped(scanAt(world, T_world_lidar), T_world_lidar);
    }
    const Pose truth = lidarAt(61, 0.5, 102) * T_base_lidar;
    const auto found = localizer.localize(scanAt(world, truth));
    ASSERT_TRUE(found.has_value()) << (upside_down ? "upside down" : "upright");
    EXPECT_EQ(found->match.index, 12u) << "the scan at x = 60";
    EXPECT_LT((found->T_world_lidar.translation() - truth.translation()).norm(), 0.05);
    EXPECT_LT(rotationErrorDeg(found->T_world_lidar, truth), 0.2);
    EXPECT_FALSE(localizer.localize(scanAt(world, lidarAt(50, -90, 0) * T_base_lidar)).has_value());
    EXPECT_FALSE(localizer.localize({}).has_value());
  }
}

}  // namespace
}  // namespace semsegmap
