// The FPFH baseline descriptor ("fpfh", paper section IV): PCL's Fast Point Feature Histogram of
// one keypoint, the segment centroid, with a radius that takes in the whole segment.
#pragma once

#include <Eigen/Core>

#include "semsegmap/describe/descriptor.h"

namespace semsegmap {

constexpr int kFpfhDimension = 33;  // three 11-bin histograms (PCL's FPFHSignature33)

struct FpfhConfig {
  // Normals from the k nearest points rather than a fixed radius: segments are one point per
  // 0.1 m voxel, so 10 neighbours span about 0.2 m on a surface, and far segments whose scan rows
  // are further apart than a fixed radius still get a plane through two rows, not a line.
  int normal_k = 10;
  // The centroid's FPFH needs the SPFH of every point in its radius, each over the whole
  // segment: O(n^2) pair features at ~0.14 us each in Debian's PCL. Larger segments are
  // subsampled to this many points (normals still come from all points): ~6 ms per segment of
  // any size, and plane / sphere / cylinder stay as far apart as without subsampling.
  int max_points = 200;
  // Added to the largest centroid-to-point distance so that the farthest point is inside.
  double radius_margin_m = 0.1;
  // Normals are flipped towards a viewpoint this far from the centroid along the segment's
  // least-variance axis: inward on closed shapes, one consistent side on flat ones, and
  // independent of where the segment sits in the map (PCL's default viewpoint is the origin).
  double normal_viewpoint_offset_m = 0.3;
  int threads = 0;  // OpenMP threads over the segments of a batch; 0: OpenMP's default
};

// The 33 bins, each 11-bin block scaled to sum to 1 (PCL makes them sum to 100). Clouds with
// fewer than 3 points, or with no pair of distinct points with a usable normal, give the zero
// vector. Throws std::invalid_argument when a coordinate is not finite or the config is out of
// range.
Eigen::Matrix<float, kFpfhDimension, 1> fpfhFeatures(const EnrichedCloud& points,
                                                     const FpfhConfig& config = {});

class FpfhDescriber : public Describer {
 public:
  // Throws std::invalid_argument naming the field when the config is out of range.
  explicit FpfhDescriber(const FpfhConfig& config = {});
  DescriptorKind kind() const override { return DescriptorKind::kFpfh; }
  int dimension() const override { return kFpfhDimension; }
  std::string fingerprint() const override { return "fpfh-v1"; }
  // Segments in parallel (OpenMP); throws std::invalid_argument naming the batch index when an
  // input has no point cloud.
  Eigen::MatrixXf describe(const std::vector<DescriptorInput>& batch) override;

 private:
  FpfhConfig config_;
};

}  // namespace semsegmap
