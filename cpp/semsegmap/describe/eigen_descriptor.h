// The eigenvalue baseline descriptor ("eigen", as in SegMap): seven shape features of a segment
// from the eigenvalues of the covariance of its points, with the definitions of Weinmann et al.
#pragma once

#include <Eigen/Core>

#include "semsegmap/describe/descriptor.h"

namespace semsegmap {

// Position of each feature in the vector eigenFeatures() returns. With the eigenvalues
// e1 >= e2 >= e3 >= 0 of the covariance, normalised to e1 + e2 + e3 = 1:
namespace eigen_feature {
constexpr int kLinearity = 0;          // (e1 - e2) / e1
constexpr int kPlanarity = 1;          // (e2 - e3) / e1
constexpr int kScattering = 2;         // e3 / e1
constexpr int kOmnivariance = 3;       // (e1 e2 e3)^(1/3)
constexpr int kAnisotropy = 4;         // (e1 - e3) / e1
constexpr int kEigenentropy = 5;       // -sum ei ln ei, with 0 ln 0 = 0
constexpr int kChangeOfCurvature = 6;  // e3 / (e1 + e2 + e3)
constexpr int kCount = 7;
}  // namespace eigen_feature

// The seven features in the order above. Points without spread (an empty cloud, one point, or
// all points identical: total variance below 1e-12 m^2) have no shape to describe and give the
// zero vector; two distinct points are an exact line (linearity 1, anisotropy 1, the rest 0).
// Throws std::invalid_argument when a coordinate is not finite.
Eigen::Matrix<float, eigen_feature::kCount, 1> eigenFeatures(const EnrichedCloud& points);

// Stateless and cheap (one 3x3 eigen-decomposition per segment), so no threads.
class EigenDescriber : public Describer {
 public:
  DescriptorKind kind() const override { return DescriptorKind::kEigen; }
  int dimension() const override { return eigen_feature::kCount; }
  std::string fingerprint() const override { return "eigen-v1"; }
  // Throws std::invalid_argument naming the batch index when an input has no point cloud.
  Eigen::MatrixXf describe(const std::vector<DescriptorInput>& batch) override;
};

}  // namespace semsegmap
