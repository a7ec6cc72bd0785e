// Convex hulls of 3-D point sets and the exact intersection over union of two of them, for the
// segmentation-consistency experiment: how much the convex hulls Vi, Vj of two segments overlap,
// IoU = vol(Vi ∩ Vj) / vol(Vi ∪ Vj). Exact up to floating point, not estimated by sampling, so
// that small differences between segmentations are not drowned in sampling noise.
//
// The hulls come from qhull (the reentrant libqhull_r). Every call has its own qhull state, so all
// functions here may be called concurrently from several threads. qhull never prints: its
// messages go to /dev/null.
#pragma once

#include <array>
#include <vector>

#include <Eigen/Core>

namespace semsegmap {

// A closed convex polytope with positive volume, or an empty one (all fields empty, volume 0).
// Made by convexHull(): intersectionVolume() relies on the fields describing the same polytope.
struct ConvexHull {
  // The extreme points of the input.
  std::vector<Eigen::Vector3d> vertices;
  // The boundary as triangles of indices into `vertices`, counter-clockwise seen from outside.
  std::vector<std::array<int, 3>> triangles;
  // One plane per facet, (n.x, n.y, n.z, d) with |n| = 1 and n·x + d <= 0 inside.
  std::vector<Eigen::Vector4d> planes;
  // Axis-aligned bounding box of the vertices, for a quick rejection of distant pairs.
  Eigen::Vector3d lower = Eigen::Vector3d::Zero();
  Eigen::Vector3d upper = Eigen::Vector3d::Zero();
  // 0 for degenerate input: fewer than 4 distinct points, or all on one plane or line.
  double volume = 0.0;

  bool empty() const { return volume <= 0.0; }
};

// Convex hull of the points. Non-finite points are ignored; degenerate input (see above, flat up
// to the rounding of the coordinates) or a qhull error gives an empty hull rather than an
// exception, since segments of a few points or of one flat wall are ordinary in the experiment.
// (It throws std::runtime_error only if /dev/null cannot be opened for qhull's messages.)
ConvexHull convexHull(const std::vector<Eigen::Vector3d>& points);
ConvexHull convexHull(const std::vector<Eigen::Vector3f>& points);

// Volume of the intersection of two hulls; 0 when either is empty or they only touch. The surface
// of a ∩ b is the part of a's surface inside b and the part of b's inside a: each hull's triangles
// clipped by the other's planes. By the divergence theorem the volume is the sum of the cones from
// one point over these pieces. This needs no third hull (no qhull call, which would also have to
// cope with the many coplanar points of such a surface) and degrades gracefully for thin overlaps.
// Cost O(triangles x planes) per pair, after a bounding-box test that rejects distant pairs.
double intersectionVolume(const ConvexHull& a, const ConvexHull& b);

// vol(a ∩ b) / vol(a ∪ b) with vol(a ∪ b) = vol(a) + vol(b) - vol(a ∩ b); 0 when either is empty.
double convexHullIoU(const ConvexHull& a, const ConvexHull& b);

}  // namespace semsegmap
