#include "semsegmap/localize/pose_covariance.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace semsegmap {

namespace {

using Vector6 = Eigen::Matrix<double, 6, 1>;

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

constexpr double kDegree = M_PI / 180.0;

// sigma^2 H^-1 in the registration's parameters (rotation vector, translation), each direction's
// variance capped: rotations are compared in metres at `lever_m` so that one cap in metres
// bounds both, and an eigenvalue too small for the cap is raised to it.
Covariance6 cappedInverse(const Covariance6& information, size_t correspondences, double variance,
                          double lever_m, const PoseCovarianceConfig& config) {
  Vector6 scale;
  scale << Eigen::Vector3d::Constant(1.0 / lever_m), Eigen::Vector3d::Ones();
  const Covariance6 scaled = scale.asDiagonal() * information * scale.asDiagonal();
  Vector6 values;
  Covariance6 vectors;
  symmetricEigen6(scaled, &values, &vectors);
  const double cap_m = std::min(config.max_sigma_m, config.max_sigma_deg * kDegree * lever_m);
  const double floor = variance / (cap_m * cap_m);
  const double degenerate =
      config.degeneracy_ratio * static_cast<double>(std::max<size_t>(1, correspondences));
  Vector6 inverse;
  for (int i = 0; i < 6; ++i)
    inverse[i] = variance / (values[i] < degenerate ? floor : std::max(values[i], floor));
  const Covariance6 in_scaled = vectors * inverse.asDiagonal() * vectors.transpose();
  return scale.asDiagonal() * in_scaled * scale.asDiagonal();
}

}  // namespace

Covariance6 covarianceFromEvidence(const RegistrationEvidence& evidence,
                                   const Eigen::Vector3d& robot_map, double inflation,
                                   const PoseCovarianceConfig& config) {
  const Eigen::Vector3d arm = robot_map - evidence.centre;
  // No residual spread (a perfect synthetic fit) still leaves the floors.
  const double variance = std::max(evidence.residual_variance * inflation, 1e-12);
  const Covariance6 params = cappedInverse(evidence.information, evidence.correspondences, variance,
                                           std::max(1.0, arm.norm()), config);
  // The robot moves with the rotation about the centre: dr = -[arm]x omega + dt; the
  // orientation turns by omega.
  Covariance6 G = Covariance6::Zero();
  G.block<3, 3>(0, 0) = -skew(arm);
  G.block<3, 3>(0, 3) = Eigen::Matrix3d::Identity();
  G.block<3, 3>(3, 0) = Eigen::Matrix3d::Identity();
  Covariance6 c = G * params * G.transpose();
  c = 0.5 * (c + c.transpose());
  const double cap_m2 = config.max_sigma_m * config.max_sigma_m;
  const double cap_rad2 = std::pow(config.max_sigma_deg * kDegree, 2);
  for (int i = 0; i < 6; ++i) {
    const bool position = i < 3;
    const double floor = position ? config.min_sigma_m * config.min_sigma_m
                                  : std::pow(config.min_sigma_deg * kDegree, 2);
    c(i, i) = std::clamp(c(i, i) + floor, floor, position ? cap_m2 : cap_rad2);
  }
  return c;
}

RegistrationEvidence centroidEvidence(
    const std::vector<std::pair<Eigen::Vector3f, Eigen::Vector3f>>& pairs) {
  RegistrationEvidence e;
  if (pairs.empty()) return e;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& [local, target] : pairs) centre += local.cast<double>();
  centre /= static_cast<double>(pairs.size());
  double squares = 0.0;
  for (const auto& [local, target] : pairs) {
    Eigen::Matrix<double, 3, 6> J;
    J << -skew(local.cast<double>() - centre), Eigen::Matrix3d::Identity();
    e.information.noalias() += J.transpose() * J;
    squares += (target - local).cast<double>().squaredNorm();
  }
  // Six parameters fitted to 3 n residuals: their spread is that much wider than the sum says.
  const double dof = std::max(1.0, 3.0 * static_cast<double>(pairs.size()) - 6.0);
  e.residual_variance = squares / dof;
  e.centre = centre;
  e.correspondences = pairs.size();
  return e;
}

Eigen::Matrix<double, 6, 1> sigmasOf(const Covariance6& covariance) {
  Eigen::Matrix<double, 6, 1> s = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  s.tail<3>() /= kDegree;
  return s;
}

double positionNees(const Covariance6& covariance, const Eigen::Vector3d& error) {
  const Eigen::Matrix3d P = covariance.topLeftCorner<3, 3>();
  return error.dot(P.ldlt().solve(error));
}

}  // namespace semsegmap
