#include "semsegmap/describe/eigen_descriptor.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

namespace semsegmap {

namespace {

// Below this total variance (1 micrometre standard deviation) the eigenvalue ratios are
// rounding noise, not shape.
constexpr double kMinTotalVariance = 1e-12;

}  // namespace

Eigen::Matrix<float, eigen_feature::kCount, 1> eigenFeatures(const EnrichedCloud& points) {
  using namespace eigen_feature;
  Eigen::Matrix<float, kCount, 1> f = Eigen::Matrix<float, kCount, 1>::Zero();
  if (points.empty()) return f;

  // Work relative to the first point: map coordinates can be kilometres from the origin, and
  // identical points then give an exactly zero covariance instead of rounding noise.
  const Eigen::Vector3d origin(points[0].x, points[0].y, points[0].z);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const EnrichedPoint& p : points) sum += Eigen::Vector3d(p.x, p.y, p.z) - origin;
  if (!sum.allFinite())
    throw std::invalid_argument("eigenFeatures: a point has a non-finite coordinate");
  const double n = static_cast<double>(points.size());
  const Eigen::Vector3d mean = sum / n;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const EnrichedPoint& p : points) {
    const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.z) - origin - mean;
    cov.noalias() += d * d.transpose();
  }
  cov /= n;

  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(cov, Eigen::EigenvaluesOnly);
  const Eigen::Vector3d ev = solver.eigenvalues();  // ascending
  // Rounding can leave a zero eigenvalue slightly negative.
  double e1 = std::max(ev(2), 0.0), e2 = std::max(ev(1), 0.0), e3 = std::max(ev(0), 0.0);
  const double total = e1 + e2 + e3;
  if (!(total > kMinTotalVariance)) return f;
  e1 /= total;
  e2 /= total;
  e3 /= total;  // now e1 >= 1/3, so the ratios below are safe

  double entropy = 0.0;
  for (const double e : {e1, e2, e3})
    if (e > 0.0) entropy -= e * std::log(e);

  f(kLinearity) = static_cast<float>((e1 - e2) / e1);
  f(kPlanarity) = static_cast<float>((e2 - e3) / e1);
  f(kScattering) = static_cast<float>(e3 / e1);
  f(kOmnivariance) = static_cast<float>(std::cbrt(e1 * e2 * e3));
  f(kAnisotropy) = static_cast<float>((e1 - e3) / e1);
  f(kEigenentropy) = static_cast<float>(entropy);
  f(kChangeOfCurvature) = static_cast<float>(e3 / (e1 + e2 + e3));
  return f;
}

Eigen::MatrixXf EigenDescriber::describe(const std::vector<DescriptorInput>& batch) {
  Eigen::MatrixXf out(static_cast<Eigen::Index>(batch.size()), eigen_feature::kCount);
  for (size_t i = 0; i < batch.size(); ++i) {
    if (batch[i].points == nullptr)
      throw std::invalid_argument("EigenDescriber::describe: input " + std::to_string(i) +
                                  " of the batch has no point cloud (null pointer)");
    out.row(static_cast<Eigen::Index>(i)) = eigenFeatures(*batch[i].points).transpose();
  }
  return out;
}

}  // namespace semsegmap
