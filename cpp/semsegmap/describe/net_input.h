// Segment points turned into the arrays the learned descriptors take (plain floats, no torch, so
// that the geometry can be tested on its own): semsegmap-net's normalised, subsampled coloured
// points, class-histogram grid and occupancy target; segmap-cnn's yaw-aligned occupancy grid.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "semsegmap/core/enriched_point.h"

namespace semsegmap {

// ---- semsegmap-net -----------------------------------------------------------------------------

// Colour as three features that are continuous where HSV is not: hue is cyclic and meaningless
// for grey, so it enters as (s cos 2 pi h, s sin 2 pi h); value as 2 v - 1. A point seen by no
// camera gets (0, 0, 0), a neutral mid grey.
std::array<float, 3> colorFeatures(const EnrichedPoint& p);

struct PointNetSample {
  std::vector<float> points;      // num_points x 6: (p - centroid) / scale, colorFeatures(p)
  std::vector<float> class_grid;  // num_classes x 3 x 3 x 3 (class-major, then x, y, z)
  float scale = 1.0f;             // metres: largest distance of a point from the centroid
  std::vector<float> occupancy;   // recon_grid^3 (x-major) over [-1, 1]^3 of the normalised frame
};

// The subsample keeps the num_points points of smallest hash(point bytes, salt), in that order:
// a uniformly random subset for a random salt, yet a pure function of the point set (the input
// order does not matter) for a fixed one. A segment with fewer points repeats them cyclically.
// Centroid, scale, class grid and occupancy use every point. Throws std::invalid_argument on an
// empty segment. Without `use_color` every point enters as seen by no camera, without
// `use_classes` as of class unknown: a model for a LiDAR without a camera sees the same input
// whatever the data carries (NetConfig::use_color, use_classes).
PointNetSample makePointNetSample(const EnrichedCloud& points, int num_points, int num_classes,
                                  int recon_grid, uint64_t salt, bool use_color = true,
                                  bool use_classes = true);

// Indices of the subsample described above (exposed for tests).
std::vector<uint32_t> hashSubsample(const EnrichedCloud& points, int count, uint64_t salt);

// ---- segmap-cnn --------------------------------------------------------------------------------

// SegMap's smallest grid extent: small segments are not blown up to fill the grid.
constexpr std::array<float, 3> kSegMapMinExtentM = {3.2f, 3.2f, 1.6f};

// Yaw (radians) of the principal axis of the x-y covariance, its direction chosen so that the
// third moment (skew) of the points along it is >= 0: rotating the segment by -yaw about z puts
// that axis on +x whatever the segment's own heading, which makes the grid yaw invariant.
// Degenerate (circular, or skew-symmetric) footprints have no stable axis; their yaw is
// whatever the numbers give.
double principalYaw(const EnrichedCloud& points);

struct OccupancyGridSample {
  std::vector<float> occupancy;     // grid_xy x grid_xy x grid_z (x-major), 0 or 1
  std::array<float, 3> extent_m{};  // grid size in metres along the aligned x, y, z
};

// Centre on the centroid, rotate by -principalYaw, centre the aligned bounding box in a grid of
// extent max(bounding box, kSegMapMinExtentM) per axis, mark the voxels that hold a point.
// Throws std::invalid_argument on an empty segment.
OccupancyGridSample makeSegMapGrid(const EnrichedCloud& points, int grid_xy, int grid_z);

}  // namespace semsegmap
