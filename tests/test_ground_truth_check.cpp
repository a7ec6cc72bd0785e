// The ground-truth check registers a query scan to the mapped scans nearest it: where the ground
// truth of two mapped scans disagrees, the query lands where the near one says, not between them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "semsegmap/core/random.h"
#include "semsegmap/eval/ground_truth_check.h"

namespace semsegmap {
namespace {

// A street in the world frame: ground, two facades with recesses, poles, a few boxes.
std::vector<Eigen::Vector3d> street(uint64_t seed) {
  SeededRng rng(seed);
  std::vector<Eigen::Vector3d> w;
  for (int i = 0; i < 20000; ++i) w.emplace_back(rng.uniform(-40, 80), rng.uniform(-9, 11), 0);
  for (double side : {-9.0, 11.0})
    for (int i = 0; i < 20000; ++i) {
      const double x = rng.uniform(-40, 80);
      const double recess = std::fmod(std::abs(x), 12.0) < 3.0 ? 1.5 : 0.0;
      w.emplace_back(x, side + (side > 0 ? recess : -recess), rng.uniform(0, 8));
    }
  for (double x = -35; x < 80; x += 7.3)
    for (int i = 0; i < 300; ++i) {
      const double a = rng.uniform(0, 2 * M_PI);
      w.emplace_back(x + 0.2 * std::cos(a), 6 + 0.2 * std::sin(a), rng.uniform(0, 5));
    }
  for (double x = -30; x < 80; x += 11.0)
    for (int i = 0; i < 1500; ++i)
      w.emplace_back(x + rng.uniform(0, 4), -6 + rng.uniform(0, 1.8), rng.uniform(0, 1.5));
  return w;
}

// The scan a LiDAR at T_world_lidar takes: the street within 35 m, in the LiDAR frame.
std::vector<LidarPoint> scanAt(const std::vector<Eigen::Vector3d>& world,
                               const Pose& T_world_lidar) {
  std::vector<LidarPoint> scan;
  const Pose T_lidar_world = T_world_lidar.inverse();
  for (const Eigen::Vector3d& p : world) {
    if ((p - T_world_lidar.translation()).norm() > 35.0) continue;
    const Eigen::Vector3d q = T_lidar_world * p;
    scan.push_back(
        {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()), 0.f});
  }
  return scan;
}

Pose lidarAt(double x, double yaw_deg) {
  return Eigen::Translation3d(x, 1.0, 1.8) *
         Eigen::AngleAxisd(yaw_deg * M_PI / 180.0, Eigen::Vector3d::UnitZ());
}

double yawErrorDeg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

TEST(GroundTruthCheck, RegistersTheQueryToTheMappedScansNearestIt) {
  const std::vector<Eigen::Vector3d> world = street(1);
  GroundTruthCheck check;
  // Scan 0 is where its ground truth says; scan 1, 30 m on, is 2 degrees off in yaw (its ground
  // truth disagrees with scan 0's, as KITTI's does between passes).
  check.addMapped(scanAt(world, lidarAt(0, 0)), lidarAt(0, 0));
  check.addMapped(scanAt(world, lidarAt(30, 0)), lidarAt(30, 2.0));
  // The query 2 m from scan 0, its ground truth 0.4 m and 1 degree off.
  const Pose truth = lidarAt(2, 10);
  const Pose given = Eigen::Translation3d(0.3, -0.25, 0.1) * lidarAt(2, 11);
  const auto registered = check.registered(scanAt(world, truth), given);
  ASSERT_TRUE(registered.has_value());
  EXPECT_LT((registered->translation() - truth.translation()).norm(), 0.05);
  EXPECT_LT(yawErrorDeg(*registered, truth), 0.2);
  // Near scan 1 the query lands where scan 1's ground truth puts that place.
  const Pose near_one = lidarAt(28, 0);
  const auto there = check.registered(scanAt(world, near_one), near_one);
  ASSERT_TRUE(there.has_value());
  EXPECT_GT(yawErrorDeg(*there, near_one), 1.5);
}

// A pose metres off is beyond the coarse registration, whose voxel map looks for a point's
// correspondence one voxel around it; a first pass on voxels of initial_distance_m reaches it
// (Scan Context's matches start there). Points that are not finite are left out.
TEST(GroundTruthCheck, AFirstPassOnLargerVoxelsReachesAPoseMetresOff) {
  const std::vector<Eigen::Vector3d> world = street(3);
  GroundTruthCheckConfig coarse_only;
  coarse_only.max_correction_m = 5.0;
  GroundTruthCheckConfig reaching = coarse_only;
  reaching.initial_distance_m = 4.0;
  GroundTruthCheck without(coarse_only), with(reaching);
  for (const double x : {0.0, 10.0, 20.0}) {
    without.addMapped(scanAt(world, lidarAt(x, 0)), lidarAt(x, 0));
    with.addMapped(scanAt(world, lidarAt(x, 0)), lidarAt(x, 0));
  }
  const Pose truth = lidarAt(12, 4);
  const Pose given = Eigen::Translation3d(2.5, -1.5, 0.0) * lidarAt(12, 6);
  std::vector<LidarPoint> scan = scanAt(world, truth);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  scan.push_back({nan, nan, nan, 0.f});
  scan.push_back({1.f, std::numeric_limits<float>::infinity(), 0.f, 0.f});
  const auto reached = with.registered(scan, given);
  ASSERT_TRUE(reached.has_value());
  EXPECT_LT((reached->translation() - truth.translation()).norm(), 0.05);
  EXPECT_LT(yawErrorDeg(*reached, truth), 0.2);
  const auto stuck = without.registered(scan, given);
  if (stuck) {
    EXPECT_GT((stuck->translation() - truth.translation()).norm(), 1.0);
  }
}

TEST(GroundTruthCheck, NeedsAMappedScanNearAndAtLeastOneNearest) {
  GroundTruthCheck empty;
  EXPECT_FALSE(empty.registered({{1, 2, 3, 0}}, Pose::Identity()).has_value());
  const std::vector<Eigen::Vector3d> world = street(2);
  GroundTruthCheck far;
  far.addMapped(scanAt(world, lidarAt(0, 0)), lidarAt(0, 0));
  EXPECT_FALSE(far.registered(scanAt(world, lidarAt(40, 0)), lidarAt(40, 0)).has_value())
      << "a query 40 m from every mapped scan";
  GroundTruthCheckConfig none;
  none.nearest_scans = 0;
  EXPECT_THROW(GroundTruthCheck{none}, std::invalid_argument);
  GroundTruthCheckConfig fewer;
  fewer.max_scans = fewer.nearest_scans - 1;
  EXPECT_THROW(GroundTruthCheck{fewer}, std::invalid_argument);
}

}  // namespace
}  // namespace semsegmap
