#include "semsegmap/odometry/icp.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/Jacobi>

namespace semsegmap {

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

// The Gauss-Newton system of one iteration. The rotation is linearised about the sensor's
// current position, not the map origin: after kilometres of driving, lever arms from the origin
// would make the system ill-conditioned and the degeneracy test meaningless.
struct NormalEquations {
  Matrix6 H = Matrix6::Zero();
  Vector6 b = Vector6::Zero();
  double weight_sum = 0.0;
  size_t correspondences = 0;
  // The point-to-plane part alone: what the surfaces constrain. Point-to-point matches on
  // sampled surfaces constrain every direction a little (the sampling is not the same twice),
  // which would hide that a corridor says nothing along itself.
  Matrix6 H_planes = Matrix6::Zero();
  double plane_weight_sum = 0.0;
  // For the evidence at the solution: sum of w r^2, and of w per scalar residual.
  double weighted_squares = 0.0, weighted_residuals = 0.0;
};

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

void addCorrespondence(const Eigen::Vector3d& arm, const Eigen::Vector3d& diff,
                       const Eigen::Vector3d& normal, bool plane, double k_sq,
                       NormalEquations& eq) {
  if (plane) {
    const double r = normal.dot(diff);
    const double w = std::pow(k_sq / (k_sq + r * r), 2);
    Vector6 J;
    J << arm.cross(normal), normal;
    eq.H_planes.noalias() += w * J * J.transpose();
    eq.b.noalias() += w * r * J;
    eq.weight_sum += w;
    eq.plane_weight_sum += w;
    eq.weighted_squares += w * r * r;
    eq.weighted_residuals += w;
  } else {
    const double w = std::pow(k_sq / (k_sq + diff.squaredNorm()), 2);
    Eigen::Matrix<double, 3, 6> J;
    J << -skew(arm), Eigen::Matrix3d::Identity();
    eq.H.noalias() += w * J.transpose() * J;
    eq.b.noalias() += w * J.transpose() * diff;
    eq.weight_sum += w;
    eq.weighted_squares += w * diff.squaredNorm();
    eq.weighted_residuals += 3.0 * w;
  }
  ++eq.correspondences;
}

NormalEquations buildSystem(const std::vector<Eigen::Vector3d>& source, const VoxelMap& map,
                            const Pose& T, double max_distance_m, double kernel_scale_m,
                            IcpMetric metric, bool near_only) {
  NormalEquations eq;
  const double k_sq = kernel_scale_m * kernel_scale_m;
  for (const Eigen::Vector3d& p : source) {
    const Eigen::Vector3d arm = T.linear() * p;
    const Eigen::Vector3d q = arm + T.translation();
    const MapNeighbour nb = map.closest(q, max_distance_m, near_only);
    if (!nb.found || nb.linear) continue;
    const bool plane = metric == IcpMetric::kPointToPlane && nb.normal.squaredNorm() > 0.5;
    addCorrespondence(arm, q - nb.point, nb.normal, plane, k_sq, eq);
  }
  return eq;
}

// Eigenvalues and eigenvectors of a symmetric 6 x 6 matrix by cyclic Jacobi rotations (exact
// to rounding for such a small matrix; Eigen's SelfAdjointEigenSolver at 6 x 6 trips GCC 12's
// -Wmaybe-uninitialized, and warnings are errors).
void symmetricEigen(Matrix6 A, Vector6* values, Matrix6* vectors) {
  Matrix6 V = Matrix6::Identity();
  const double scale = std::max(A.squaredNorm(), 1e-300);
  for (int sweep = 0; sweep < 30; ++sweep) {
    const double off = A.squaredNorm() - A.diagonal().squaredNorm();
    if (off <= 1e-24 * scale) break;
    for (int p = 0; p < 6; ++p)
      for (int q = p + 1; q < 6; ++q) {
        if (A(p, q) == 0.0) continue;
        Eigen::JacobiRotation<double> J;
        J.makeJacobi(A, p, q);
        A.applyOnTheLeft(p, q, J.adjoint());
        A.applyOnTheRight(p, q, J);
        V.applyOnTheRight(p, q, J);
      }
  }
  *values = A.diagonal();
  *vectors = V;
}

// The update (rotation vector, translation), damped by `ratio` of what one match along a
// direction gives: where the scan constrains a direction far less than that (a corridor along
// itself), the step along it vanishes and the pose keeps the prediction there; elsewhere the
// damping only slows convergence a little. Rotations are scaled by the lever `lever_m` so that
// all six directions are compared in metres. `degenerate` counts the directions below the
// damping: those the surfaces (or, when most matches are point-to-point, all matches)
// constrain that little.
Vector6 solveDamped(const NormalEquations& eq, double lever_m, double ratio, int* degenerate) {
  Vector6 scale;
  scale << Eigen::Vector3d::Constant(1.0 / lever_m), Eigen::Vector3d::Ones();
  const Matrix6 H = eq.H + eq.H_planes;
  const bool by_planes = eq.plane_weight_sum > 0.5 * eq.weight_sum;
  const Matrix6 test = scale.asDiagonal() * (by_planes ? eq.H_planes : H) * scale.asDiagonal();
  const double floor = ratio * (by_planes ? eq.plane_weight_sum : eq.weight_sum);
  Vector6 values;
  Matrix6 vectors;
  symmetricEigen(test, &values, &vectors);
  *degenerate = static_cast<int>((values.array() <= floor).count());
  const Matrix6 Hs =
      scale.asDiagonal() * H * scale.asDiagonal() + ratio * eq.weight_sum * Matrix6::Identity();
  const Vector6 step = Hs.ldlt().solve(-scale.cwiseProduct(eq.b));
  return scale.cwiseProduct(step);
}

double rmsNorm(const std::vector<Eigen::Vector3d>& points) {
  double sum = 0.0;
  for (const Eigen::Vector3d& p : points) sum += p.squaredNorm();
  return points.empty() ? 1.0 : std::sqrt(sum / static_cast<double>(points.size()));
}

}  // namespace

void symmetricEigen6(const Matrix6d& A, Eigen::Matrix<double, 6, 1>* values, Matrix6d* vectors) {
  symmetricEigen(A, values, vectors);
}

RegistrationEvidence evidenceAt(const std::vector<Eigen::Vector3d>& source, const VoxelMap& map,
                                const Pose& T, double max_distance_m, double kernel_scale_m,
                                IcpMetric metric) {
  const NormalEquations eq =
      buildSystem(source, map, T, max_distance_m, kernel_scale_m, metric, true);
  RegistrationEvidence e;
  // As the update's degeneracy test (solveDamped): where most matches are point-to-plane, the
  // point-to-point ones (voxels without a plane) would constrain a slide along a wall by the
  // sampling alone.
  const bool by_planes = eq.plane_weight_sum > 0.5 * eq.weight_sum;
  e.information = by_planes ? eq.H_planes : Matrix6(eq.H + eq.H_planes);
  e.residual_variance =
      eq.weighted_residuals > 0 ? eq.weighted_squares / eq.weighted_residuals : 0.0;
  e.centre = T.translation();
  e.correspondences = eq.correspondences;
  return e;
}

IcpResult alignToMap(const std::vector<Eigen::Vector3d>& source, const VoxelMap& map,
                     const Pose& initial, double max_distance_m, double kernel_scale_m,
                     const IcpConfig& config) {
  IcpResult result;
  result.T = initial;
  const double lever = std::max(1.0, rmsNorm(source));
  constexpr double kConvergenceLever = 10.0;
  constexpr double kNearOnlyFraction = 0.05;
  constexpr double kSettled = 0.02;  // metres (radians times the lever) an iteration moved
  // Far from the solution a correspondence may lie a voxel away; close to it, half a voxel.
  bool near_only = false;
  // The kernel starts as wide as the correspondence threshold and halves, down to its scale,
  // each time the pose has settled at the current width: a wide kernel lets a start far off (a
  // turn the prediction missed) pull the pose in, the narrow one then keeps wrong matches out of
  // the result. Narrowing before the pose settles would freeze it where it stood.
  double kernel = std::max(kernel_scale_m, max_distance_m);
  for (int it = 0; it < config.max_iterations; ++it) {
    const NormalEquations eq =
        buildSystem(source, map, result.T, max_distance_m, kernel, config.metric, near_only);
    result.iterations = it + 1;
    result.correspondences = eq.correspondences;
    result.enough_correspondences = eq.correspondences >= config.min_correspondences;
    if (!result.enough_correspondences) break;
    const Vector6 step =
        solveDamped(eq, lever, config.degeneracy_ratio, &result.degenerate_directions);
    const Eigen::Vector3d omega = step.head<3>();
    const double angle = omega.norm();
    const Eigen::Matrix3d R = angle > 0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix()
                                        : Eigen::Matrix3d::Identity();
    result.T.linear() = R * result.T.linear();
    result.T.translation() += step.tail<3>();
    const double moved = step.tail<3>().norm() + kConvergenceLever * angle;
    const bool narrowest = kernel <= kernel_scale_m;
    if (moved < config.convergence && narrowest) break;
    if (moved < kSettled) kernel = std::max(kernel_scale_m, 0.5 * kernel);
    near_only = moved < kNearOnlyFraction * map.voxelSize();
  }
  return result;
}

}  // namespace semsegmap
