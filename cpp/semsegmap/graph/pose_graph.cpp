#include "semsegmap/graph/pose_graph.h"

#include <ceres/ceres.h>

#include <array>
#include <memory>
#include <stdexcept>
#include <string>

namespace semsegmap {

namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

// The error of the estimated relative pose against the measured one: translation difference
// expressed in the `from` frame, then 2 * vec(q_err) (the small-angle rotation vector), each
// divided by its sigma so that the squared norm is a Mahalanobis distance.
class RelativePoseError {
 public:
  RelativePoseError(const Pose& T_from_to, const Vector6d& inv_sigma)
      : t_from_to_(T_from_to.translation()),
        q_from_to_(Eigen::Quaterniond(T_from_to.linear()).normalized()),
        inv_sigma_(inv_sigma) {}

  template <typename T>
  bool operator()(const T* t_from, const T* q_from, const T* t_to, const T* q_to,
                  T* residual) const {
    using Vec3 = Eigen::Matrix<T, 3, 1>;
    using Quat = Eigen::Quaternion<T>;
    const Eigen::Map<const Vec3> p_a(t_from);
    const Eigen::Map<const Vec3> p_b(t_to);
    const Eigen::Map<const Quat> q_a(q_from);
    const Eigen::Map<const Quat> q_b(q_to);

    const Quat q_a_inverse = q_a.conjugate();
    const Vec3 t_estimated = q_a_inverse * (p_b - p_a);
    const Quat q_estimated = q_a_inverse * q_b;
    // q and -q are the same rotation; for a small error vec() is small with either sign, so no
    // sign fix is needed.
    const Quat q_error = q_from_to_.template cast<T>().conjugate() * q_estimated;

    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(residual);
    r.template head<3>() = t_estimated - t_from_to_.template cast<T>();
    r.template tail<3>() = T(2.0) * q_error.vec();
    for (int i = 0; i < 6; ++i) r[i] *= T(inv_sigma_[i]);
    return true;
  }

 private:
  Eigen::Vector3d t_from_to_;
  Eigen::Quaterniond q_from_to_;
  Vector6d inv_sigma_;
};

Vector6d inverseSigmas(double translation_sigma, double rotation_sigma) {
  Vector6d w;
  w << Eigen::Vector3d::Constant(1.0 / translation_sigma),
      Eigen::Vector3d::Constant(1.0 / rotation_sigma);
  return w;
}

void requirePositive(double value, const char* name) {
  if (!(value > 0.0))
    throw std::invalid_argument(std::string("PoseGraphConfig: ") + name + " must be > 0, got " +
                                std::to_string(value));
}

void configureLinearSolver(ceres::Solver::Options& options) {
  // Ceres 2.1 preselects the best sparse library it was built with (SuiteSparse on Debian);
  // NO_SPARSE means a build without any, where dense QR is slow on big graphs but still correct.
  options.linear_solver_type = options.sparse_linear_algebra_library_type != ceres::NO_SPARSE
                                   ? ceres::SPARSE_NORMAL_CHOLESKY
                                   : ceres::DENSE_QR;
  std::string why;
  if (options.IsValid(&why)) return;
  options.linear_solver_type = ceres::DENSE_QR;
  if (!options.IsValid(&why)) throw std::runtime_error("PoseGraph: invalid solver options: " + why);
}

}  // namespace

PoseGraph::PoseGraph(const PoseGraphConfig& config) : config_(config) {
  requirePositive(config.odometry_translation_sigma_m, "odometry_translation_sigma_m");
  requirePositive(config.odometry_rotation_sigma_rad, "odometry_rotation_sigma_rad");
  requirePositive(config.loop_translation_sigma_m, "loop_translation_sigma_m");
  requirePositive(config.loop_rotation_sigma_rad, "loop_rotation_sigma_rad");
  if (config.max_iterations < 1 || config.threads < 1)
    throw std::invalid_argument("PoseGraphConfig: max_iterations and threads must be >= 1");
}

size_t PoseGraph::addNode(const Pose& T_map_base) {
  if (!T_map_base.matrix().allFinite())
    throw std::invalid_argument("PoseGraph::addNode: non-finite pose");
  nodes_.push_back(T_map_base);
  return nodes_.size() - 1;
}

void PoseGraph::addOdometry(size_t from, size_t to, const Pose& T_from_to) {
  addEdge(from, to, T_from_to, EdgeKind::kOdometry);
}

void PoseGraph::addLoop(size_t from, size_t to, const Pose& T_from_to) {
  addEdge(from, to, T_from_to, EdgeKind::kLoop);
}

void PoseGraph::addEdge(size_t from, size_t to, const Pose& T_from_to, EdgeKind kind) {
  if (from >= nodes_.size() || to >= nodes_.size())
    throw std::out_of_range("PoseGraph: edge " + std::to_string(from) + " -> " +
                            std::to_string(to) + " names a node that does not exist (" +
                            std::to_string(nodes_.size()) + " nodes)");
  if (from == to) throw std::invalid_argument("PoseGraph: edge from a node to itself");
  if (!T_from_to.matrix().allFinite())
    throw std::invalid_argument("PoseGraph: non-finite edge measurement");
  edges_.push_back({from, to, T_from_to, kind});
}

PoseGraph::Summary PoseGraph::optimize() {
  Summary result;
  for (const PoseGraphEdge& e : edges_) result.loops += e.kind == EdgeKind::kLoop ? 1 : 0;
  if (edges_.empty()) {
    result.converged = true;
    return result;
  }

  // Quaternions in Eigen's coefficient order (x y z w), which EigenQuaternionManifold expects.
  const size_t n = nodes_.size();
  std::vector<std::array<double, 3>> translations(n);
  std::vector<std::array<double, 4>> rotations(n);
  for (size_t i = 0; i < n; ++i) {
    Eigen::Map<Eigen::Vector3d>(translations[i].data()) = nodes_[i].translation();
    Eigen::Map<Eigen::Quaterniond>(rotations[i].data()) =
        Eigen::Quaterniond(nodes_[i].linear()).normalized();
  }

  // Shared by all blocks and declared before the problem so that they outlive it.
  ceres::EigenQuaternionManifold quaternion_manifold;
  std::unique_ptr<ceres::LossFunction> loop_loss;
  if (config_.loop_robust_scale > 0.0)
    loop_loss = std::make_unique<ceres::CauchyLoss>(config_.loop_robust_scale);

  ceres::Problem::Options problem_options;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);

  const Vector6d odometry_weight =
      inverseSigmas(config_.odometry_translation_sigma_m, config_.odometry_rotation_sigma_rad);
  const Vector6d loop_weight =
      inverseSigmas(config_.loop_translation_sigma_m, config_.loop_rotation_sigma_rad);
  for (const PoseGraphEdge& e : edges_) {
    const bool loop = e.kind == EdgeKind::kLoop;
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseError, 6, 3, 4, 3, 4>(
        new RelativePoseError(e.T_from_to, loop ? loop_weight : odometry_weight));
    problem.AddResidualBlock(cost, loop ? loop_loss.get() : nullptr, translations[e.from].data(),
                             rotations[e.from].data(), translations[e.to].data(),
                             rotations[e.to].data());
  }
  // Nodes without edges are not in the problem (Ceres would reject them in these calls).
  for (size_t i = 0; i < n; ++i)
    if (problem.HasParameterBlock(rotations[i].data()))
      problem.SetManifold(rotations[i].data(), &quaternion_manifold);
  if (problem.HasParameterBlock(translations[0].data())) {
    problem.SetParameterBlockConstant(translations[0].data());
    problem.SetParameterBlockConstant(rotations[0].data());
  }

  ceres::Solver::Options options;
  configureLinearSolver(options);
  options.max_num_iterations = config_.max_iterations;
  options.num_threads = config_.threads;
  options.minimizer_progress_to_stdout = false;
  options.logging_type = ceres::SILENT;

  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
  if (!summary.IsSolutionUsable()) return result;

  for (size_t i = 0; i < n; ++i) {
    if (!problem.HasParameterBlock(translations[i].data())) continue;
    nodes_[i].translation() = Eigen::Map<const Eigen::Vector3d>(translations[i].data());
    nodes_[i].linear() =
        Eigen::Map<const Eigen::Quaterniond>(rotations[i].data()).normalized().toRotationMatrix();
  }
  return result;
}

}  // namespace semsegmap
