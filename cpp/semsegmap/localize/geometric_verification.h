// Geometric verification of centroid correspondences (paper section III-D, after the k-NN step):
// the largest set of (local segment, target segment) pairs consistent with one rigid transform,
// and the 6-DoF T_target_local fitted to it.
//
// Why a maximum clique of a pairwise-consistency graph rather than RANSAC: with k = 16 retrieved
// candidates per local segment at most one in 16 is right, so 70-95 % outliers are normal.
// RANSAC needs ~log(0.01) / log(1 - w^3) minimal samples at inlier ratio w (~40000 at w = 0.05)
// and is still random; the consistency graph (SegMap's recognizer) only asks pairwise questions
// that hold whatever the transform, so outliers rarely form large cliques, and an exact maximum
// clique is deterministic and returns the true set whenever it is the largest consistent one.
// The graph is sparse (targets further apart than the local map's diameter cannot be
// consistent), so a branch and bound per vertex over its later neighbours in a degeneracy
// order, pruned by core numbers and greedy colouring (Tomita-style), is exact at the sizes seen
// in practice (hundreds to a few thousand correspondences, cliques of 6-40). A node budget
// bounds adversarial cases; the best clique so far is then used.
//
// Pairwise distances are also preserved by reflections, so a clique may be consistent only with
// a mirror transform: rigidFit returns rotations only (det +1), and the final check of every
// inlier against the fitted proper transform drops such solutions.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "semsegmap/core/pose.h"

namespace semsegmap {

// A local segment centroid (robot's local map frame) matched to a target segment centroid (map
// frame). Ids identify segments: a clique uses each local and each target segment at most once;
// -1 means unknown (no such constraint).
struct Correspondence {
  Eigen::Vector3d local = Eigen::Vector3d::Zero();
  Eigen::Vector3d target = Eigen::Vector3d::Zero();
  int64_t local_id = -1;
  int64_t target_id = -1;
  float descriptor_distance = 0;  // breaks ties between cliques of equal size: smaller sum wins
};

struct GeometricVerificationConfig {
  // Two correspondences are consistent when their centroid distances in the two frames differ
  // by at most this (SegMap's geometric consistency resolution).
  double resolution_m = 0.4;
  int min_inliers = 6;  // the paper: 6 in simulation, 7 on real data
  // Refit the transform on the inliers that pass the final check (Umeyama/Horn without scale);
  // false keeps the fit on the whole clique.
  bool refine = true;
  // Final check: an inlier must lie within this of its target after the fitted transform.
  // Pairwise tolerance accumulates over the clique, hence twice the resolution.
  double inlier_tolerance_m = 0.8;
  // Inliers nearly on a line leave the rotation about that line undetermined: reject solutions
  // whose local centroids spread less than this (standard deviation) across the main axis.
  double min_spread_m = 1.0;
  // Branch-and-bound nodes before the search settles for the best clique so far: a time guard
  // that stays deterministic (a node costs ~1 us at these sizes; building the graph is apart,
  // ~15 ms for 2000 correspondences whose targets all lie within the local map's diameter).
  size_t max_search_nodes = 1'000'000;
};

struct VerificationResult {
  bool found = false;
  Pose T_target_local = Pose::Identity();
  std::vector<int> inliers;     // indices into the input, ascending
  size_t clique_size = 0;       // largest consistent set found (before the final check)
  bool search_complete = true;  // false: a budget ran out, the clique may not be maximum
  size_t search_nodes = 0;
};

VerificationResult verify(const std::vector<Correspondence>& correspondences,
                          const GeometricVerificationConfig& config = {});

// Least-squares rigid transform T (rotation and translation, no scale) with T * from[i] ~=
// to[i]; never a reflection. Throws std::invalid_argument when the sizes differ. Fewer than
// three non-collinear points leave the rotation partly free; the one returned is still optimal.
Pose rigidFit(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to);

}  // namespace semsegmap
