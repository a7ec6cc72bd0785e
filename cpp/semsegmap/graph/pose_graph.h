// The pose graph of loop closure (SegMap style): nodes are robot poses T_map_base at keyframes,
// edges are odometry between consecutive nodes and loop closures found by localizing the current
// local segments against the older map. Ceres stays out of this header: the problem is built
// from the plain storage below at every optimize().
#pragma once

#include <cstddef>
#include <vector>

#include "semsegmap/core/pose.h"

namespace semsegmap {

struct PoseGraphConfig {
  // Standard deviations per edge, for keyframes ~1 m apart and odometry drifting ~1 %. They are
  // deliberately looser than the drift itself: real drift is a bias, not white noise, and an
  // odometry chain that claims to be stiffer than it is makes the robust loss below treat a
  // correct loop closure with a large correction as an outlier.
  double odometry_translation_sigma_m = 0.05;
  double odometry_rotation_sigma_rad = 0.01;
  double loop_translation_sigma_m = 0.2;
  double loop_rotation_sigma_rad = 0.02;
  // Cauchy loss on loop edges only, in units of the whitened residual (so 1 = one sigma); <= 0
  // disables it. Cauchy rather than Huber because its influence falls back towards zero for
  // gross errors, while Huber's stays constant: with Huber a loop 20 m off keeps pulling the
  // whole chain with a fixed force, with Cauchy it is all but ignored.
  double loop_robust_scale = 1.0;
  int max_iterations = 100;
  int threads = 1;
};

enum class EdgeKind { kOdometry, kLoop };

struct PoseGraphEdge {
  size_t from = 0;
  size_t to = 0;
  Pose T_from_to = Pose::Identity();
  EdgeKind kind = EdgeKind::kOdometry;
};

class PoseGraph {
 public:
  explicit PoseGraph(const PoseGraphConfig& config = {});

  // Returns the new node's index. The pose is the initial estimate; node 0 is held fixed during
  // optimize() and so sets the gauge (the map frame).
  size_t addNode(const Pose& T_map_base);
  // Both throw std::out_of_range for unknown nodes and std::invalid_argument for from == to or
  // a non-finite pose.
  void addOdometry(size_t from, size_t to, const Pose& T_from_to);
  void addLoop(size_t from, size_t to, const Pose& T_from_to);

  struct Summary {
    bool converged = false;  // Ceres reached a convergence criterion (not the iteration limit)
    double initial_cost = 0.0;
    double final_cost = 0.0;
    int iterations = 0;
    size_t loops = 0;  // loop edges in the problem
  };
  // Updates the node poses in place (only if Ceres returns a usable solution).
  Summary optimize();

  const Pose& pose(size_t node) const { return nodes_.at(node); }
  size_t size() const { return nodes_.size(); }
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }
  const PoseGraphConfig& config() const { return config_; }

 private:
  void addEdge(size_t from, size_t to, const Pose& T_from_to, EdgeKind kind);

  PoseGraphConfig config_;
  std::vector<Pose> nodes_;
  std::vector<PoseGraphEdge> edges_;
};

}  // namespace semsegmap
