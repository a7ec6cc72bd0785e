#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "semsegmap/sim/polyline.h"
#include "semsegmap/sim/trajectory.h"
#include "semsegmap/sim/world.h"

using namespace semsegmap;
using namespace semsegmap::sim;

namespace {

double hue(const Eigen::Vector3f& rgb) {
  const float mx = rgb.maxCoeff(), mn = rgb.minCoeff();
  if (mx - mn < 1e-6f) return 0.0;
  double h;
  if (mx == rgb.x())
    h = std::fmod((rgb.y() - rgb.z()) / (mx - mn), 6.0);
  else if (mx == rgb.y())
    h = (rgb.z() - rgb.x()) / (mx - mn) + 2.0;
  else
    h = (rgb.x() - rgb.y()) / (mx - mn) + 4.0;
  h /= 6.0;
  return h < 0 ? h + 1.0 : h;
}

const World& fullWorld() {
  static const World w = generateWorld(WorldConfig{}, 1);
  return w;
}

}  // namespace

TEST(World, SameSeedsGiveTheSameWorld) {
  const World a = generateWorld(worldPreset("tiny", 3), 4);
  const World b = generateWorld(worldPreset("tiny", 3), 4);
  ASSERT_EQ(a.mesh.vertices.size(), b.mesh.vertices.size());
  for (size_t k = 0; k < a.mesh.vertices.size(); ++k)
    ASSERT_EQ(a.mesh.vertices[k], b.mesh.vertices[k]);
  EXPECT_EQ(a.mesh.triangle_surface, b.mesh.triangle_surface);
  const World c = generateWorld(worldPreset("tiny", 4), 4);
  EXPECT_NE(a.mesh.vertices.size(), c.mesh.vertices.size());
}

TEST(World, TrafficSeedChangesCarsButNotTheWorldsInstances) {
  const World a = generateWorld(worldPreset("small", 1), 1);
  const World b = generateWorld(worldPreset("small", 1), 2);
  std::vector<std::pair<uint16_t, Eigen::Vector2d>> static_a, static_b;
  std::vector<Eigen::Vector2d> cars_a, cars_b;
  for (const auto& o : a.objects) {
    if (o.instance_id < kTrafficInstanceBase) static_a.emplace_back(o.instance_id, o.center_xy);
    if (o.kind == "parked-car") cars_a.push_back(o.center_xy);
  }
  for (const auto& o : b.objects) {
    if (o.instance_id < kTrafficInstanceBase) static_b.emplace_back(o.instance_id, o.center_xy);
    if (o.kind == "parked-car") cars_b.push_back(o.center_xy);
  }
  ASSERT_EQ(static_a.size(), static_b.size());
  for (size_t k = 0; k < static_a.size(); ++k) {
    EXPECT_EQ(static_a[k].first, static_b[k].first);
    EXPECT_EQ(static_a[k].second, static_b[k].second);
  }
  ASSERT_GT(cars_a.size(), 5u);
  EXPECT_NE(cars_a, cars_b);
  for (const auto& o : a.objects) {
    if (o.kind == "parked-car" || o.kind == "moving-car" || o.kind == "person") {
      EXPECT_GE(o.instance_id, kTrafficInstanceBase);
    }
  }
}

TEST(World, FullWorldIsANeighbourhoodOfAbout400Metres) {
  const World& w = fullWorld();
  const Eigen::Vector2d extent = w.max_xy - w.min_xy;
  EXPECT_GT(extent.x(), 350.0);
  EXPECT_LT(extent.x(), 600.0);
  std::map<std::string, int> kinds;
  std::set<uint16_t> ids;
  for (const auto& o : w.objects) {
    ++kinds[o.kind];
    EXPECT_TRUE(ids.insert(o.instance_id).second) << "instance id " << o.instance_id << " twice";
  }
  EXPECT_GT(kinds["house"], 80);
  EXPECT_GT(kinds["tree"], 80);
  for (const char* k : {"hedge", "fence", "bush", "street-light", "traffic-sign", "bin", "mailbox",
                        "parked-car", "moving-car", "person", "driveway"})
    EXPECT_GT(kinds[k], 0) << k;
  // The road network has several loops: a grid of at least 3 x 3 intersections.
  EXPECT_GE(w.roads.grid_nodes, 3);
  EXPECT_EQ(w.roads.edges.size(),
            static_cast<size_t>(2 * w.roads.grid_nodes * (w.roads.grid_nodes - 1)));
}

TEST(World, EveryClassOfTheTableIsInTheWorld) {
  const World& w = fullWorld();
  std::set<ClassId> classes;
  for (const auto& s : w.surfaces) classes.insert(s.class_id);
  for (const auto& a : w.agents)
    for (const auto& s : a.surfaces) classes.insert(s.class_id);
  for (ClassId c : {cls::kRoad, cls::kSidewalk, cls::kTerrain, cls::kBuilding, cls::kRoof,
                    cls::kFence, cls::kVegetation, cls::kTrunk, cls::kPole, cls::kTrafficSign,
                    cls::kCar, cls::kPerson, cls::kOther})
    EXPECT_TRUE(classes.count(c)) << ClassTable::Default().at(c).name;
}

TEST(World, HouseWallsComeInAtLeastEightHues) {
  // Same shapes in many colours is what lets colour tell segments apart.
  std::set<int> hue_bins;
  for (const auto& s : fullWorld().surfaces)
    if (s.class_id == cls::kBuilding && s.albedo.maxCoeff() - s.albedo.minCoeff() > 0.08f)
      hue_bins.insert(static_cast<int>(hue(s.albedo) * 24.0));
  EXPECT_GE(hue_bins.size(), 8u);
}

TEST(World, HousesStayOffTheStreets) {
  const World& w = fullWorld();
  const double curb = 0.5 * w.roads.road_width_m + w.roads.sidewalk_width_m;
  for (const auto& o : w.objects) {
    if (o.kind != "house") continue;
    double d = 1e9;
    for (const auto& [a, b] : w.roads.edges)
      d = std::min(d, distanceToSegment(o.center_xy, w.roads.nodes[a], w.roads.nodes[b]));
    EXPECT_GT(d, curb + 4.0) << "house " << o.instance_id;
  }
}

TEST(Trajectory, RunLengthsMatchThePaper) {
  const std::map<sim::Run, double> target = {
      {Run::S0, 2000.0}, {Run::S1, 1500.0}, {Run::S2, 380.0}, {Run::S3, 380.0}};
  for (const auto& [run, len] : target) {
    const Trajectory t = makeTrajectory(fullWorld().roads, run, {}, {}, 1);
    EXPECT_NEAR(t.length_m, len, 0.1 * len) << runName(run);
    // 5 m/s at 5 Hz: about a metre between frames, never a jump.
    for (size_t k = 1; k < t.T_world_base.size(); ++k) {
      const double step = translationError(t.T_world_base[k - 1], t.T_world_base[k]);
      ASSERT_NEAR(step, 1.0, 0.15) << runName(run) << " frame " << k;
      ASSERT_LT(rotationErrorDeg(t.T_world_base[k - 1], t.T_world_base[k]), 15.0);
    }
  }
}

TEST(Trajectory, S3IsS2Reversed) {
  const Trajectory s2 = makeTrajectory(fullWorld().roads, Run::S2, {}, {}, 1);
  const Trajectory s3 = makeTrajectory(fullWorld().roads, Run::S3, {}, {}, 1);
  EXPECT_EQ(defaultCondition(Run::S3), "sunrise");
  // Every S3 pose is on S2's streets (the other lane) and heads the other way.
  for (size_t k = 0; k < s3.T_world_base.size(); k += 5) {
    const Pose& p = s3.T_world_base[k];
    double best = 1e9;
    size_t best_j = 0;
    for (size_t j = 0; j < s2.T_world_base.size(); ++j) {
      const double d = translationError(p, s2.T_world_base[j]);
      if (d < best) best = d, best_j = j;
    }
    EXPECT_LT(best, 6.0) << "S3 frame " << k;
    EXPECT_GT(rotationErrorDeg(p, s2.T_world_base[best_j]), 120.0) << "S3 frame " << k;
  }
  // And it starts where S2 ends, roughly.
  EXPECT_LT(translationError(s3.T_world_base.front(), s2.T_world_base.back()), 8.0);
}

TEST(Trajectory, LapsDriveTheLoopAgainWithoutAJump) {
  const Trajectory one = makeTrajectory(fullWorld().roads, Run::S2, {}, {}, 1);
  TrajectoryConfig three_laps;
  three_laps.laps = 3;
  const Trajectory three = makeTrajectory(fullWorld().roads, Run::S2, three_laps, {}, 1);
  EXPECT_NEAR(three.length_m, 3.0 * one.length_m, 1e-6);
  EXPECT_NEAR(static_cast<double>(three.T_world_base.size()), 3.0 * one.T_world_base.size(), 3.0);
  // Frames stay 1 m apart through the seams between laps, and time goes on.
  for (size_t k = 1; k < three.T_world_base.size(); ++k) {
    ASSERT_NEAR(translationError(three.T_world_base[k - 1], three.T_world_base[k]), 1.0, 0.1)
        << "frame " << k;
    ASSERT_LT(rotationErrorDeg(three.T_world_base[k - 1], three.T_world_base[k]), 15.0);
    ASSERT_GT(three.timestamps_s[k], three.timestamps_s[k - 1]);
  }
  // The second lap drives the first one's streets, with odometry for every frame.
  const size_t n = one.T_world_base.size();
  EXPECT_LT(translationError(three.T_world_base[n + 100], one.T_world_base[100]), 1.5);
  EXPECT_EQ(three.T_odom_base.size(), three.T_world_base.size());
  // A run that does not end where it starts has no laps.
  EXPECT_THROW(makeTrajectory(fullWorld().roads, Run::S1, three_laps, {}, 1),
               std::invalid_argument);
}

TEST(Trajectory, S1RevisitsPlaces) {
  const Trajectory t = makeTrajectory(fullWorld().roads, Run::S1, {}, {}, 1);
  // Count frames that come within 4 m of a frame at least 200 frames earlier.
  int revisits = 0;
  for (size_t k = 200; k < t.T_world_base.size(); ++k)
    for (size_t j = 0; j + 200 < k; ++j) {
      if (translationError(t.T_world_base[k], t.T_world_base[j]) < 4.0) {
        ++revisits;
        break;
      }
    }
  EXPECT_GT(revisits, 200);
}

TEST(Trajectory, OdometryDriftsAboutOnePercent) {
  const Trajectory t = makeTrajectory(fullWorld().roads, Run::S0, {}, {}, 3);
  EXPECT_LT(translationError(t.T_world_base.front(), t.T_odom_base.front()), 1e-12);
  // Relative motion over 100 frames: scale error close to the configured 1 %.
  double gt_dist = 0, odom_dist = 0;
  for (size_t k = 1; k <= 100; ++k) {
    gt_dist += translationError(t.T_world_base[k - 1], t.T_world_base[k]);
    odom_dist += translationError(t.T_odom_base[k - 1], t.T_odom_base[k]);
  }
  EXPECT_NEAR(std::abs(odom_dist / gt_dist - 1.0), 0.01, 0.004);
  // Heading drifts by the configured 0.05 degrees a metre (plus a little noise).
  const Pose rel_gt = t.T_world_base[0].inverse() * t.T_world_base[100];
  const Pose rel_odom = t.T_odom_base[0].inverse() * t.T_odom_base[100];
  EXPECT_NEAR(rotationErrorDeg(rel_gt, rel_odom), 0.05 * gt_dist, 1.0);
}

TEST(Polyline, OffsetAndPointAt) {
  const Polyline square = {{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  const Polyline inner = offsetPolyline(square, 1.0, true);  // left of a ccw loop: inside
  EXPECT_NEAR(inner[0].x(), 1.0, 1e-12);
  EXPECT_NEAR(inner[0].y(), 1.0, 1e-12);
  EXPECT_NEAR(polylineLength(inner, true), 32.0, 1e-9);
  const PolylinePoint p = pointAt(square, 15.0, true);
  EXPECT_NEAR(p.position.x(), 10.0, 1e-12);
  EXPECT_NEAR(p.position.y(), 5.0, 1e-12);
  EXPECT_NEAR(p.heading, M_PI / 2, 1e-12);
  EXPECT_NEAR(pointAt(square, 45.0, true).position.x(), 5.0, 1e-12);  // wraps around
}
