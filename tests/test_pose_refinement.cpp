// Pose refinement after the segment match: registering the matched local segments' points to the
// target map's stored points removes the error a centroid-only pose keeps when the local map saw
// other parts of the segments than the map did.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/random.h"
#include "semsegmap/localize/pose_refinement.h"

namespace semsegmap {
namespace {

using Points = std::vector<Eigen::Vector3f>;

// Points on a rectangle through `corner` spanned by u and v (lengths included), `share` of it
// along u: a wall or facade seen in part.
Points rectangle(SeededRng& rng, const Eigen::Vector3f& corner, const Eigen::Vector3f& u,
                 const Eigen::Vector3f& v, double share, int n) {
  Points out;
  for (int i = 0; i < n; ++i)
    out.push_back(corner + static_cast<float>(rng.uniform(0, share)) * u +
                  static_cast<float>(rng.uniform(0, 1)) * v);
  return out;
}

// A vertical cylinder (a pole or trunk) seen from one side: `from_deg` to `to_deg` of its round.
Points cylinder(SeededRng& rng, const Eigen::Vector3f& base, float radius, float height,
                double from_deg, double to_deg, int n) {
  Points out;
  for (int i = 0; i < n; ++i) {
    const double a = rng.uniform(from_deg, to_deg) * M_PI / 180.0;
    out.push_back(base + Eigen::Vector3f(radius * static_cast<float>(std::cos(a)),
                                         radius * static_cast<float>(std::sin(a)),
                                         height * static_cast<float>(rng.uniform(0, 1))));
  }
  return out;
}

// A parked car as a box on the ground: its roof and its sides (the faces in `faces`, of +x, -x,
// +y, -y, top), the only level surfaces left once the ground is removed.
Points box(SeededRng& rng, const Eigen::Vector3f& lo, const Eigen::Vector3f& size,
           const std::vector<int>& faces, int n_per_face) {
  const Eigen::Vector3f x(size.x(), 0, 0), y(0, size.y(), 0), z(0, 0, size.z());
  Points out;
  for (int f : faces) {
    const Eigen::Vector3f corner = lo + (f == 0   ? x
                                         : f == 2 ? y
                                         : f == 4 ? z
                                                  : Eigen::Vector3f::Zero());
    const Eigen::Vector3f u = f < 2 ? y : x, v = f < 4 ? z : y;
    const Points face = rectangle(rng, corner, u, v, 1.0, n_per_face);
    out.insert(out.end(), face.begin(), face.end());
  }
  return out;
}

// A street corner in the map frame: two facades at right angles, a low wall, a pole, a tree
// trunk, a parked car; each segment as a target map holds it (seen whole) and as the local map saw
// it (in part, other samples, sensor noise), in the local frame through T_map_local.
struct Scene {
  TargetMap map;
  std::vector<Points> local;
  Localization match;  // one match per segment, i <-> i
};

Scene streetCorner(const Pose& T_map_local, uint64_t seed) {
  SeededRng rng(seed);
  const Eigen::Vector3f x(1, 0, 0), y(0, 1, 0), z(0, 0, 1);
  struct Shape {
    Points whole, part;
  };
  const std::vector<Shape> shapes = {
      {rectangle(rng, {0, 0, 0}, 20 * x, 8 * z, 1.0, 3000),
       rectangle(rng, {0, 0, 0}, 20 * x, 8 * z, 0.6, 1500)},
      {rectangle(rng, {0, 0, 0}, 15 * y, 8 * z, 1.0, 3000),
       rectangle(rng, {0, 0, 0}, 15 * y, 8 * z, 0.5, 1500)},
      {rectangle(rng, {3, 6, 0}, 10 * x + 2 * y, 1.2f * z, 1.0, 1000),
       rectangle(rng, {3, 6, 0}, 10 * x + 2 * y, 1.2f * z, 0.7, 600)},
      {cylinder(rng, {8, 4, 0}, 0.15f, 5, 0, 360, 600),
       cylinder(rng, {8, 4, 0}, 0.15f, 5, 180, 300, 300)},
      {cylinder(rng, {14, 9, 0}, 0.4f, 3, 0, 360, 800),
       cylinder(rng, {14, 9, 0}, 0.4f, 3, 160, 280, 400)},
      {box(rng, {9, 11, 0}, {4.2f, 1.8f, 1.5f}, {0, 1, 2, 3, 4}, 400),
       box(rng, {9, 11, 0}, {4.2f, 1.8f, 1.5f}, {1, 3, 4}, 250)},
  };
  Scene scene;
  const Pose T_local_map = T_map_local.inverse();
  for (size_t i = 0; i < shapes.size(); ++i) {
    MapSegment s;
    s.points = shapes[i].whole;
    s.n_points = static_cast<uint32_t>(s.points.size());
    s.centroid = Eigen::Vector3f::Zero();
    for (const Eigen::Vector3f& p : s.points) s.centroid += p / static_cast<float>(s.n_points);
    scene.map.segments.push_back(s);
    Points local;
    for (const Eigen::Vector3f& p : shapes[i].part) {
      const Eigen::Vector3d noise(rng.gaussian(0.01), rng.gaussian(0.01), rng.gaussian(0.01));
      local.push_back((T_local_map * (p.cast<double>() + noise)).cast<float>());
    }
    scene.local.push_back(local);
    scene.match.matches.emplace_back(i, i);
  }
  scene.match.inliers = static_cast<int>(shapes.size());
  return scene;
}

Pose truth() {
  // The local map's origin far from the place, as where the odometry started a drive ago.
  return Eigen::Translation3d(-412.0, 250.0, 3.0) *
         Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ());
}

// Where the segments are: errors are measured there, not at the far-away local origin.
const Eigen::Vector3d kPlace(8, 6, 2);

// What a centroid-only match leaves: a few tenths of a metre and a degree or two about the place.
Pose centroidPose(const Pose& T) {
  return Eigen::Translation3d(kPlace + Eigen::Vector3d(0.35, -0.25, 0.12)) *
         Eigen::AngleAxisd(1.5 * M_PI / 180.0, Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(0.5 * M_PI / 180.0, Eigen::Vector3d::UnitX()) *
         Eigen::Translation3d(-kPlace) * T;
}

double rotationErrorDeg(const Pose& a, const Pose& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle() * 180.0 / M_PI;
}

RefinementConfig enabled() {
  RefinementConfig config;
  config.enabled = true;
  return config;
}

TEST(PoseRefinement, RecoversAKnownOffsetOfTheCentroidPose) {
  const Pose T = truth();
  Scene scene = streetCorner(T, 1);
  scene.match.T_map_local = centroidPose(T);
  ASSERT_GT((scene.match.T_map_local.translation() - T.translation()).norm(), 0.4);
  const Refinement r = refinePose(scene.match, scene.local, scene.map, enabled());
  ASSERT_TRUE(r.applied) << r.reason;
  EXPECT_LT((r.T_map_local * (T.inverse() * kPlace) - kPlace).norm(), 0.03);
  EXPECT_LT(rotationErrorDeg(r.T_map_local, T), 0.2);
  EXPECT_GT(r.correction_m, 0.2);
  EXPECT_GE(r.correspondences, 1000u);
}

// One matched facade lets the registration slide along it and turn about its normal; the place's
// unmatched segments near map segments under the match's pose (refinement.neighbours_m) pin both.
TEST(PoseRefinement, UnmatchedNeighboursPinWhatOneMatchedSegmentLeavesLoose) {
  const Pose T = truth();
  Scene scene = streetCorner(T, 7);
  scene.match.matches = {{0, 0}};
  scene.match.T_map_local = centroidPose(T);
  const auto placeError = [&](const Refinement& r) {
    return (r.T_map_local * (T.inverse() * kPlace) - kPlace).norm();
  };
  const Refinement alone = refinePose(scene.match, scene.local, scene.map, enabled());
  RefinementConfig config = enabled();
  config.neighbours_m = 3.0;
  const Refinement pinned = refinePose(scene.match, scene.local, scene.map, config);
  ASSERT_TRUE(pinned.applied) << pinned.reason;
  EXPECT_LT(placeError(pinned), 0.03);
  EXPECT_LT(rotationErrorDeg(pinned.T_map_local, T), 0.2);
  EXPECT_GT(placeError(alone), 0.2) << "one facade alone should leave the slide along it";
  EXPECT_GT(pinned.correspondences, alone.correspondences);
}

TEST(PoseRefinement, KeepsTheMatchWhenThePointsDisagreeWithIt) {
  const Pose T = truth();
  Scene scene = streetCorner(T, 2);
  // The target points lie 3 m from where the match says: the matched segments are not these.
  for (MapSegment& s : scene.map.segments)
    for (Eigen::Vector3f& p : s.points) p += Eigen::Vector3f(3, 0, 0);
  scene.match.T_map_local = centroidPose(T);
  const Refinement r = refinePose(scene.match, scene.local, scene.map, enabled());
  EXPECT_FALSE(r.applied);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_TRUE(r.T_map_local.isApprox(scene.match.T_map_local));
}

TEST(PoseRefinement, KeepsTheMatchWithTooFewPointsAndCapsTheLargeCorrections) {
  const Pose T = truth();
  Scene few = streetCorner(T, 3);
  for (Points& p : few.local) p.resize(5);
  few.match.T_map_local = centroidPose(T);
  const Refinement r = refinePose(few.match, few.local, few.map, enabled());
  EXPECT_FALSE(r.applied);
  EXPECT_EQ(r.reason, "too few segment points");

  Scene far = streetCorner(T, 4);
  far.match.T_map_local = centroidPose(T);
  RefinementConfig strict = enabled();
  strict.max_correction_m = 0.1;  // less than the 0.45 m the points ask for
  const Refinement capped = refinePose(far.match, far.local, far.map, strict);
  EXPECT_FALSE(capped.applied);
  EXPECT_TRUE(capped.T_map_local.isApprox(far.match.T_map_local));
}

TEST(PoseRefinement, AMatchOutsideTheQueryOrTheMapIsAnError) {
  const Pose T = truth();
  Scene scene = streetCorner(T, 5);
  scene.match.matches.emplace_back(scene.local.size(), 0);
  EXPECT_THROW(refinePose(scene.match, scene.local, scene.map, enabled()), std::out_of_range);
}

TEST(PoseRefinement, NeedsPointsForEverySegmentOfTheMap) {
  Scene scene = streetCorner(truth(), 6);
  EXPECT_TRUE(hasSegmentPoints(scene.map));
  scene.map.segments[2].points.clear();
  EXPECT_FALSE(hasSegmentPoints(scene.map));
}

}  // namespace
}  // namespace semsegmap
