#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Geometry>

#include "semsegmap/eval/convex_hull.h"

using namespace semsegmap;

namespace {

using Points = std::vector<Eigen::Vector3d>;

// The 8 corners of the box [lo, hi].
Points box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  Points corners;
  for (int k = 0; k < 8; ++k)
    corners.emplace_back(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  return corners;
}

Points unitCube() {
  return box(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones());
}

Points uniformIn(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points points;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d t(u(rng), u(rng), u(rng));
    points.push_back(lo + t.cwiseProduct(hi - lo));
  }
  return points;
}

bool inside(const ConvexHull& hull, const Eigen::Vector3d& x) {
  for (const auto& p : hull.planes)
    if (p.head<3>().dot(x) + p[3] > 0.0) return false;
  return true;
}

// Relative tolerance of the exact cases.
constexpr double kRel = 1e-9;

void expectIoU(const Points& a, const Points& b, double expected) {
  const ConvexHull ha = convexHull(a), hb = convexHull(b);
  const double tolerance = kRel * std::max(expected, 1e-300);
  EXPECT_NEAR(convexHullIoU(ha, hb), expected, tolerance);
  EXPECT_NEAR(convexHullIoU(hb, ha), expected, tolerance);  // symmetric
}

}  // namespace

TEST(ConvexHull, CubeAndTetrahedron) {
  const ConvexHull cube = convexHull(unitCube());
  EXPECT_NEAR(cube.volume, 1.0, kRel);
  EXPECT_EQ(cube.vertices.size(), 8u);
  EXPECT_EQ(cube.planes.size(), 6u);  // qhull merges the coplanar triangles of each face
  EXPECT_EQ(cube.triangles.size(), 12u);
  EXPECT_EQ(cube.lower, Eigen::Vector3d::Zero());
  EXPECT_EQ(cube.upper, Eigen::Vector3d::Ones());
  for (const auto& p : cube.planes) EXPECT_NEAR(p.head<3>().norm(), 1.0, 1e-12);
  // Every triangle faces outward: its normal points away from the centre.
  const Eigen::Vector3d centre(0.5, 0.5, 0.5);
  for (const auto& t : cube.triangles) {
    const Eigen::Vector3d& p0 = cube.vertices[t[0]];
    const Eigen::Vector3d n = (cube.vertices[t[1]] - p0).cross(cube.vertices[t[2]] - p0);
    EXPECT_GT(n.dot(p0 - centre), 0.0);
  }
  // Interior points do not become vertices.
  Points with_interior = unitCube();
  with_interior.emplace_back(0.5, 0.5, 0.5);
  with_interior.emplace_back(0.2, 0.9, 0.3);
  EXPECT_EQ(convexHull(with_interior).vertices.size(), 8u);

  const Points tetra{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const ConvexHull t = convexHull(tetra);
  EXPECT_NEAR(t.volume, 1.0 / 6.0, kRel / 6.0);
  EXPECT_EQ(t.triangles.size(), 4u);
  // Inside the cube: IoU = (1/6) / 1.
  expectIoU(tetra, unitCube(), 1.0 / 6.0);

  // Single precision input gives the same hull.
  std::vector<Eigen::Vector3f> cube_f;
  for (const auto& p : unitCube()) cube_f.push_back(p.cast<float>());
  EXPECT_NEAR(convexHull(cube_f).volume, 1.0, kRel);
}

TEST(ConvexHullIoU, IdenticalDisjointAndTouchingBoxes) {
  expectIoU(unitCube(), unitCube(), 1.0);
  // Far apart (rejected by the boxes) and apart across a diagonal plane only (boxes overlap).
  expectIoU(unitCube(), box({3, 0, 0}, {4, 1, 1}), 0.0);
  const Points slab_a{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const Points slab_b{{1, 1, 1}, {0.6, 0.6, 0.6}, {1, 0.2, 0.6}, {0.2, 1, 0.6}};
  expectIoU(slab_a, slab_b, 0.0);
  // Sharing a face, an edge, a corner.
  expectIoU(unitCube(), box({1, 0, 0}, {2, 1, 1}), 0.0);
  expectIoU(unitCube(), box({1, 1, 0}, {2, 2, 1}), 0.0);
  expectIoU(unitCube(), box({1, 1, 1}, {2, 2, 2}), 0.0);
  // Tetrahedra sharing a face: on an axis plane (boxes touch) and on a slanted one (boxes overlap).
  expectIoU(unitCube(), Points{{1, 0, 0}, {1, 1, 0}, {1, 0, 1}, {2, 0.5, 0.5}}, 0.0);
  expectIoU(slab_a, Points{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}}, 0.0);
}

TEST(ConvexHullIoU, OverlappingBoxes) {
  // Half along x: 0.5 / 1.5.
  expectIoU(unitCube(), box({0.5, 0, 0}, {1.5, 1, 1}), 1.0 / 3.0);
  // Shifted along all three axes: intersection 0.7 * 0.6 * 0.5.
  const double common = 0.7 * 0.6 * 0.5;
  expectIoU(unitCube(), box({0.3, 0.4, 0.5}, {1.3, 1.4, 1.5}), common / (2.0 - common));
  // Nested: inner / outer.
  expectIoU(unitCube(), box({0.25, 0.25, 0.25}, {0.75, 0.75, 0.75}), 0.125);
  // Bars of 0.04 and 0.12 crossing like a plus sign: a cube of side 0.2 in common, 0.008 / 0.152.
  expectIoU(box({0.4, 0.4, 0}, {0.6, 0.6, 1}), box({-1, 0.4, 0.4}, {2, 0.6, 0.6}), 1.0 / 19.0);
}

TEST(ConvexHullIoU, CubeAndItsRotation) {
  // The cube [-1/2, 1/2]^3 and itself rotated 45 degrees about z meet in a prism of height 1 over
  // a regular octagon with apothem 1/2, of area 8 (1/2)^2 tan(pi/8) = 2 (sqrt2 - 1). So
  // IoU = 2 (sqrt2 - 1) / (2 - 2 (sqrt2 - 1)) = 1 / sqrt2.
  const Points cube = box(Eigen::Vector3d::Constant(-0.5), Eigen::Vector3d::Constant(0.5));
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(M_PI / 4.0, Eigen::Vector3d::UnitZ()).matrix();
  Points rotated;
  for (const auto& p : cube) rotated.push_back(rotation * p);
  const ConvexHull a = convexHull(cube), b = convexHull(rotated);
  const double octagon = 2.0 * (std::sqrt(2.0) - 1.0);
  EXPECT_NEAR(intersectionVolume(a, b), octagon, kRel * octagon);
  expectIoU(cube, rotated, 1.0 / std::sqrt(2.0));

  // Far from the origin (map coordinates) the same.
  const Eigen::Vector3d offset(1234.5, -987.25, 42.0);
  Points cube_far, rotated_far;
  for (const auto& p : cube) cube_far.push_back(p + offset);
  for (const auto& p : rotated) rotated_far.push_back(p + offset);
  expectIoU(cube_far, rotated_far, 1.0 / std::sqrt(2.0));
}

TEST(ConvexHullIoU, CubeAndCornerTetrahedron) {
  // The tetrahedron x, y, z >= 0, x + y + z <= 3/2 has volume (3/2)^3 / 6 = 9/16; three corners of
  // volume (1/2)^3 / 6 each stick out of the unit cube, so 9/16 - 3/48 = 1/2 is in common and
  // IoU = (1/2) / (1 + 9/16 - 1/2) = 8/17. Here edges of each cross facets of the other.
  const Points tetra{{0, 0, 0}, {1.5, 0, 0}, {0, 1.5, 0}, {0, 0, 1.5}};
  EXPECT_NEAR(intersectionVolume(convexHull(tetra), convexHull(unitCube())), 0.5, kRel);
  expectIoU(tetra, unitCube(), 8.0 / 17.0);
}

TEST(ConvexHullIoU, RandomPointsAgreeWithSampling) {
  const Points points = uniformIn(Eigen::Vector3d::Zero(), Eigen::Vector3d::Ones(), 500, 7);
  const ConvexHull hull = convexHull(points);
  EXPECT_LT(hull.volume, 1.0);
  EXPECT_GT(hull.volume, 0.8);
  EXPECT_LT(hull.vertices.size(), points.size());
  EXPECT_NEAR(convexHullIoU(hull, hull), 1.0, kRel);
  // Every input point is inside its hull (up to rounding).
  double farthest_out = -1.0;
  for (const auto& p : points)
    for (const auto& plane : hull.planes)
      farthest_out = std::max(farthest_out, plane.head<3>().dot(p) + plane[3]);
  EXPECT_LE(farthest_out, 1e-12);

  // A general overlap of two random hulls: the exact volume agrees with a Monte Carlo estimate
  // within 4 standard deviations, and does not depend on the order of the arguments.
  const ConvexHull other = convexHull(
      uniformIn(Eigen::Vector3d(0.4, 0.3, -0.2), Eigen::Vector3d(1.5, 1.1, 0.7), 300, 8));
  const double exact = intersectionVolume(hull, other);
  EXPECT_NEAR(intersectionVolume(other, hull), exact, 1e-12);
  const int samples = 200000;
  const Eigen::Vector3d lo(0.4, 0.3, 0.0), hi(1.0, 1.0, 0.7);  // contains the intersection
  const double box_volume = (hi - lo).prod();
  int hits = 0;
  for (const auto& x : uniformIn(lo, hi, samples, 9)) hits += inside(hull, x) && inside(other, x);
  const double p = static_cast<double>(hits) / samples;
  const double estimate = p * box_volume;
  const double sigma = box_volume * std::sqrt(p * (1.0 - p) / samples);
  EXPECT_GT(exact, 0.05);
  EXPECT_NEAR(exact, estimate, 4.0 * sigma);
  const double iou = convexHullIoU(hull, other);
  EXPECT_NEAR(iou, exact / (hull.volume + other.volume - exact), 1e-12);
}

TEST(ConvexHull, DegenerateInputIsEmptyAndSilent) {
  const ConvexHull cube = convexHull(unitCube());
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  std::vector<ConvexHull> hulls;
  hulls.push_back(convexHull(Points{}));
  hulls.push_back(convexHull(Points{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}));     // three points
  hulls.push_back(convexHull(Points(10, Eigen::Vector3d(0.5, 0.5, 0.5))));  // one point repeated
  Points line, plane, tilted_plane;
  for (int i = 0; i < 20; ++i) line.emplace_back(0.1 * i, 0.2 * i, -0.05 * i);
  for (int i = 0; i < 50; ++i) plane.emplace_back(std::sin(i), std::cos(3.0 * i), 0.5);
  const Eigen::Vector3d u(1, 2, 3), v(-2, 0.5, 1);
  for (int i = 0; i < 50; ++i)
    tilted_plane.push_back(Eigen::Vector3d(7, 8, 9) + std::sin(i) * u + std::cos(5.0 * i) * v);
  hulls.push_back(convexHull(line));
  hulls.push_back(convexHull(plane));
  hulls.push_back(convexHull(tilted_plane));
  Points with_nan{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {NAN, 0, 1}, {INFINITY, 1, 1}};
  hulls.push_back(convexHull(with_nan));  // three finite points
  double iou_sum = 0.0;
  for (const auto& h : hulls) iou_sum += convexHullIoU(h, cube) + convexHullIoU(cube, h);
  // The face of the cube as a flat hull.
  hulls.push_back(convexHull(box({0, 0, 1}, {1, 1, 1})));
  // Thin is not flat: a slab a micrometre thick is a hull (qhull warns of a narrow hull, silently).
  const ConvexHull slab = convexHull(box({0, 0, 0}, {1, 1, 1e-6}));
  const std::string out = testing::internal::GetCapturedStdout();
  const std::string err = testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "");
  for (const auto& h : hulls) {
    EXPECT_TRUE(h.empty());
    EXPECT_EQ(h.volume, 0.0);
    EXPECT_TRUE(h.vertices.empty());
    EXPECT_TRUE(h.planes.empty());
  }
  EXPECT_EQ(iou_sum, 0.0);
  EXPECT_NEAR(slab.volume, 1e-6, 1e-6 * kRel);
  EXPECT_NEAR(convexHullIoU(slab, cube), 1e-6, 1e-6 * kRel);
  EXPECT_EQ(convexHullIoU(ConvexHull(), ConvexHull()), 0.0);
  EXPECT_EQ(intersectionVolume(ConvexHull(), cube), 0.0);

  // Duplicates and non-finite points alongside a proper volume are harmless.
  Points cube_twice = unitCube();
  for (const auto& p : unitCube()) cube_twice.push_back(p);
  cube_twice.emplace_back(NAN, 0, 0);
  EXPECT_NEAR(convexHull(cube_twice).volume, 1.0, kRel);
}

TEST(ConvexHullIoU, ConcurrentCallsAgree) {
  std::vector<ConvexHull> hulls;
  for (unsigned s = 0; s < 8; ++s)
    hulls.push_back(convexHull(uniformIn(Eigen::Vector3d::Constant(0.1 * s),
                                         Eigen::Vector3d::Constant(1.0 + 0.1 * s), 200, s)));
  std::vector<double> serial;
  for (size_t i = 0; i + 1 < hulls.size(); ++i)
    serial.push_back(convexHullIoU(hulls[i], hulls[i + 1]));
  std::vector<std::vector<double>> parallel(4);
  std::vector<std::thread> threads;
  for (auto& result : parallel)
    threads.emplace_back([&hulls, &result] {
      for (int repeat = 0; repeat < 5; ++repeat) {
        result.clear();
        for (size_t i = 0; i + 1 < hulls.size(); ++i)
          result.push_back(convexHullIoU(hulls[i], hulls[i + 1]));
      }
    });
  for (auto& t : threads) t.join();
  for (const auto& result : parallel) EXPECT_EQ(result, serial);
}
