// What 3DSmoothNet (Gojcic et al., "The Perfect Match", CVPR 2019) sees of a keypoint, without
// torch so that the geometry can be tested on its own: a local reference frame from the
// covariance of the points around the keypoint, and in it the smoothed density value (SDV) voxel
// grid. The segment descriptor `3dsmoothnet` (describe/smoothnet.h) describes random keypoints of
// a segment so and aggregates them into a bag of words, as the SemSegMap paper did because one
// 3DSmoothNet descriptor over a whole segment "did not yield meaningful results".
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/enriched_point.h"

namespace semsegmap {

// The axes of a keypoint's local reference frame as the rows of a rotation (map -> local).
// `points` are the support: the points within `radius` of the keypoint (the keypoint may be
// among them). z is the direction of least spread of the points about the keypoint, turned
// towards the side most points lie on; x is the tangent direction the points far above or below
// the tangent plane pull towards, weighted by (radius - distance)^2 so that the points near the
// keypoint count most; y = z x x. Without points off the tangent plane (a flat patch) x is the
// direction of largest spread, turned towards its longer side. Fewer than 3 points, or points on
// a line or at one place, have no frame: returns false and leaves `axes` untouched.
bool localReferenceFrame(const std::vector<Eigen::Vector3f>& support,
                         const Eigen::Vector3f& keypoint, float radius, Eigen::Matrix3f* axes);

// The SDV grid of `voxels`^3 cells (x-major, then y, then z) over the cube of side 2 * radius
// centred on the keypoint and aligned with `axes`: a cell holds the mean Gaussian weight
// exp(-d^2 / 2 h^2), h = half the cell's side, of the points within 3 h of its centre (mean, not
// sum: the grid does not change with the point density, which differs by range and by LiDAR);
// the grid is then scaled to sum to 1. All zero when no point is near a cell.
std::vector<float> sdvGrid(const std::vector<Eigen::Vector3f>& support,
                           const Eigen::Vector3f& keypoint, const Eigen::Matrix3f& axes,
                           float radius, int voxels);

// The input of 3dsmoothnet for one segment: `keypoints` grids of voxels^3 values, one after the
// other. The keypoints are the segment's points of smallest hash with `salt` (hashSubsample,
// net_input.h: the same points whatever their order; repeated when the segment has fewer). A
// keypoint without a local frame (too few neighbours) gets an all-zero grid. Throws
// std::invalid_argument on an empty segment.
std::vector<float> smoothNetSample(const EnrichedCloud& segment, int keypoints, float radius,
                                   int voxels, uint64_t salt);

// The points of `cloud` within `radius` of `centre`. A segment has a few thousand points at most:
// a pass over them costs less than building a tree for a few dozen keypoints.
std::vector<Eigen::Vector3f> pointsWithin(const std::vector<Eigen::Vector3f>& cloud,
                                          const Eigen::Vector3f& centre, float radius);

// The SDV grid of one keypoint of `cloud`, frame and all, both from the points within `radius`
// (the paper's spherical support); all zero without a frame.
std::vector<float> keypointGrid(const std::vector<Eigen::Vector3f>& cloud,
                                const Eigen::Vector3f& keypoint, float radius, int voxels);

}  // namespace semsegmap
