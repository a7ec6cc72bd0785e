// Global relocalization from one scan (localize/relocalizer.h) on a synthetic town of box-shaped
// buildings: each building is a map segment with points on its walls, and a robot's local
// segments are the buildings near it, sampled afresh and seen from its own frame. Descriptors are
// the map's with noise, so that the right target is among a local segment's 64 nearest but seldom
// its nearest: what a partial view's descriptor does.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/random.h"
#include "semsegmap/localize/registration_check.h"
#include "semsegmap/localize/relocalizer.h"

namespace semsegmap {
namespace {

using Points = std::vector<Eigen::Vector3f>;

struct Building {
  Eigen::Vector3f centre;
  Eigen::Vector3f size;  // x, y, height
};

// Points on the four walls of a building, about one every `spacing_m` at random.
Points wallsOf(const Building& b, SeededRng& rng, double spacing_m) {
  Points out;
  const float perimeter = 2 * (b.size.x() + b.size.y());
  const int n = static_cast<int>(perimeter * b.size.z() / (spacing_m * spacing_m));
  for (int i = 0; i < n; ++i) {
    float along = static_cast<float>(rng.uniform(0, perimeter));
    const float z = static_cast<float>(rng.uniform(0, b.size.z()));
    Eigen::Vector3f p = b.centre - 0.5f * Eigen::Vector3f(b.size.x(), b.size.y(), 0);
    const float sx = b.size.x(), sy = b.size.y();
    if (along < sx) {
      p += Eigen::Vector3f(along, 0, z);
    } else if ((along -= sx) < sy) {
      p += Eigen::Vector3f(sx, along, z);
    } else if ((along -= sy) < sx) {
      p += Eigen::Vector3f(sx - along, sy, z);
    } else {
      p += Eigen::Vector3f(0, sy - (along - sx), z);
    }
    out.push_back(p);
  }
  return out;
}

// A town of `n` buildings of random size and place on a side_m square, and its map.
struct Town {
  std::vector<Building> buildings;
  TargetMap map;
};

Town makeTown(int n, double side_m, uint64_t seed) {
  SeededRng rng(seed);
  Town town;
  town.map.descriptor = "eigen";
  town.map.descriptors.resize(n, 16);
  for (int i = 0; i < n; ++i) {
    Building b{Eigen::Vector3f(static_cast<float>(rng.uniform(0, side_m)),
                               static_cast<float>(rng.uniform(0, side_m)), 0),
               Eigen::Vector3f(static_cast<float>(rng.uniform(3, 15)),
                               static_cast<float>(rng.uniform(3, 15)),
                               static_cast<float>(rng.uniform(3, 10)))};
    town.buildings.push_back(b);
    MapSegment s;
    s.points = wallsOf(b, rng, 0.5);
    s.centroid = b.centre + Eigen::Vector3f(0, 0, b.size.z() / 2);
    s.n_points = static_cast<uint32_t>(s.points.size());
    town.map.segments.push_back(s);
    for (int d = 0; d < 16; ++d) town.map.descriptors(i, d) = static_cast<float>(rng.gaussian(1));
  }
  return town;
}

// The local segments of a robot at `robot` (map frame) whose local frame is T_map_local^-1 of
// the map's: the buildings within radius_m, their points sampled again, their descriptors the
// map's plus noise of `noise` sigma.
struct Query {
  std::vector<Eigen::Vector3f> centroids;
  Eigen::MatrixXf descriptors;
  std::vector<Points> points;
  Eigen::Vector3d robot_local;
};

Query queryAt(const Town& town, const Eigen::Vector3d& robot, const Pose& T_map_local,
              double radius_m, double noise, uint64_t seed) {
  SeededRng rng(seed);
  const Pose T_local_map = T_map_local.inverse();
  Query q;
  std::vector<Eigen::VectorXf> rows;
  for (size_t i = 0; i < town.buildings.size(); ++i) {
    const Building& b = town.buildings[i];
    if ((b.centre.head<2>().cast<double>() - robot.head<2>()).norm() > radius_m) continue;
    Points points;
    for (const Eigen::Vector3f& p : wallsOf(b, rng, 0.7))
      points.push_back((T_local_map * p.cast<double>()).cast<float>());
    q.points.push_back(points);
    q.centroids.push_back(
        (T_local_map * town.map.segments[i].centroid.cast<double>()).cast<float>());
    Eigen::VectorXf d = town.map.descriptors.row(static_cast<Eigen::Index>(i)).transpose();
    for (int k = 0; k < d.size(); ++k) d[k] += static_cast<float>(rng.gaussian(noise));
    rows.push_back(d);
  }
  q.descriptors.resize(static_cast<Eigen::Index>(rows.size()), 16);
  for (size_t i = 0; i < rows.size(); ++i)
    q.descriptors.row(static_cast<Eigen::Index>(i)) = rows[i];
  q.robot_local = T_local_map * robot;
  return q;
}

Pose someLocalFrame() {
  return Eigen::Translation3d(-420.0, 135.0, 2.0) *
         Eigen::AngleAxisd(2.1, Eigen::Vector3d::UnitZ());
}

TEST(RegistrationCheck, AcceptsThePosePointsLieOnAndRefusesAnother) {
  const Town town = makeTown(300, 300, 1);
  const Eigen::Vector3d robot(150, 150, 0);
  const Pose T = someLocalFrame();
  const Query q = queryAt(town, robot, T, 50, 0.0, 2);
  ASSERT_GE(q.points.size(), 5u);
  const RegistrationCheckConfig config;

  const RegistrationCheck right = checkRegistration(q.points, q.robot_local, town.map, T, config);
  EXPECT_TRUE(right.accepted) << right.reason;
  EXPECT_GT(right.fitness, 0.9) << right.correction_m << " m " << right.correction_deg << " deg";
  // The registration's planes come from 1.5 m voxels, and at the many corners of small
  // buildings they are bent: 9 cm off here (long facades do better).
  EXPECT_LT((right.T_map_local * q.robot_local - robot).norm(), 0.15);

  // Off by 0.6 m and 2 degrees: registration brings it back.
  const Pose off = Eigen::Translation3d(0.4, -0.45, 0.0) *
                   Eigen::AngleAxisd(2.0 * M_PI / 180, Eigen::Vector3d::UnitZ()) * T;
  const Pose off_robot = Eigen::Translation3d(T * q.robot_local - off * q.robot_local) * off;
  const RegistrationCheck near =
      checkRegistration(q.points, q.robot_local, town.map, off_robot, config);
  EXPECT_TRUE(near.accepted) << near.reason;
  EXPECT_LT((near.T_map_local * q.robot_local - T * q.robot_local).norm(), 0.1);

  // Another place of the town: the points do not lie on its walls.
  const Pose elsewhere = Eigen::Translation3d(120.0, -80.0, 0.0) * T;
  const RegistrationCheck wrong =
      checkRegistration(q.points, q.robot_local, town.map, elsewhere, config);
  EXPECT_FALSE(wrong.accepted);
  EXPECT_FALSE(wrong.reason.empty());
}

TEST(RegistrationCheck, RefusesTooFewPointsWithAReason) {
  const Town town = makeTown(50, 300, 3);
  const std::vector<Points> nothing(3);
  const RegistrationCheck r = checkRegistration(nothing, Eigen::Vector3d::Zero(), town.map,
                                                Pose::Identity(), RegistrationCheckConfig{});
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "too few points to register");
}

LocalizerConfig wholeMapLocalizer() {
  LocalizerConfig c;
  c.index.k = 16;
  return c;
}

// Noisy descriptors: the whole-map localizer (k = 16, six inliers) finds too few right matches,
// the places the 64 nearest vote for hold them, and the pose is the registered one.
TEST(Relocalizer, FindsTheRobotFromOneScanWhereTheWholeMapQueryDoesNot) {
  const Town town = makeTown(2000, 1000, 4);
  const Localizer localizer(town.map, wholeMapLocalizer());
  const Pose T = someLocalFrame();
  const RelocalizationConfig config;
  int relocalized = 0, whole_map = 0, tried = 0;
  for (double x : {200.0, 450.0, 650.0, 800.0})
    for (double y : {250.0, 550.0, 750.0}) {
      const Eigen::Vector3d robot(x, y, 0);
      const Query q = queryAt(town, robot, T, 45, 1.7, static_cast<uint64_t>(x + y));
      if (q.centroids.size() < 8) continue;
      ++tried;
      const auto l = localizer.localize(q.centroids, q.descriptors);
      whole_map += l && translationError(l->T_map_local, T) < 1.0;
      const auto r =
          relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local, config);
      if (!r) continue;
      // Never wrong: a pose it gives is the registered one.
      EXPECT_LT((r->match.T_map_local * q.robot_local - robot).norm(), 0.2);
      EXPECT_GE(r->check.fitness, config.check.min_fitness);
      ++relocalized;
    }
  ASSERT_GE(tried, 8);
  EXPECT_GE(relocalized, tried * 3 / 4) << "of " << tried;
  EXPECT_LE(2 * whole_map, relocalized) << "whole map " << whole_map << ", relocalized "
                                        << relocalized << ": the noise is meant to defeat "
                                        << "the whole-map query";
}

// The robot stands where the map has nothing like it: the map's segments near it were moved
// together to another place (so their descriptors and the layout of their centroids still
// match the query's: the verification finds a large clique there) and are other buildings there.
// Only the registration check can refuse it.
TEST(Relocalizer, RefusesAPlaceWhoseSegmentsMatchButWhosePointsDoNot) {
  Town town = makeTown(2000, 1000, 5);
  const Eigen::Vector3d robot(500, 500, 0);
  const Pose T = someLocalFrame();
  const Query q = queryAt(town, robot, T, 45, 0.3, 6);
  ASSERT_GE(q.centroids.size(), 8u);
  const Localizer before(town.map, wholeMapLocalizer());
  ASSERT_TRUE(relocalize(before, q.centroids, q.descriptors, q.points, q.robot_local, {}));

  SeededRng rng(11);
  size_t moved = 0;
  for (size_t i = 0; i < town.map.size(); ++i) {
    MapSegment& s = town.map.segments[i];
    if ((s.centroid.head<2>().cast<double>() - robot.head<2>()).norm() > 100) continue;
    Building other = town.buildings[i];
    other.centre += Eigen::Vector3f(700, 300, 0);
    other.size = Eigen::Vector3f(other.size.y() + 4, other.size.x() + 3, other.size.z());
    s.centroid += Eigen::Vector3f(700, 300, 0);
    s.points = wallsOf(other, rng, 0.5);
    ++moved;
  }
  ASSERT_GT(moved, 8u);
  const Localizer after(town.map, wholeMapLocalizer());
  const auto match = after.localize(q.centroids, q.descriptors);
  ASSERT_TRUE(match) << "the moved segments are meant to match as a whole";
  EXPECT_FALSE(relocalize(after, q.centroids, q.descriptors, q.points, q.robot_local, {}));
}

TEST(Relocalizer, APriorRestrictsThePlaces) {
  const Town town = makeTown(1000, 800, 7);
  const Localizer localizer(town.map, wholeMapLocalizer());
  const Eigen::Vector3d robot(400, 450, 0);
  const Pose T = someLocalFrame();
  const Query q = queryAt(town, robot, T, 45, 0.5, 8);
  ASSERT_GE(q.centroids.size(), 6u);
  RelocalizationPrior near{Eigen::Vector3d(390, 470, 0), 60};
  EXPECT_TRUE(relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local,
                         RelocalizationConfig{}, near));
  RelocalizationPrior far{Eigen::Vector3d(200, 200, 0), 100};
  EXPECT_FALSE(relocalize(localizer, q.centroids, q.descriptors, q.points, q.robot_local,
                          RelocalizationConfig{}, far));
}

TEST(Relocalizer, RefusesMismatchedInput) {
  const Town town = makeTown(20, 200, 9);
  const Localizer localizer(town.map, wholeMapLocalizer());
  const std::vector<Eigen::Vector3f> centroids(5, Eigen::Vector3f::Zero());
  EXPECT_THROW(relocalize(localizer, centroids, Eigen::MatrixXf::Zero(4, 16),
                          std::vector<Points>(5), Eigen::Vector3d::Zero(), {}),
               std::invalid_argument);
}

}  // namespace
}  // namespace semsegmap
