// Localization against a target map (paper section III-D): the k nearest target descriptors of
// every local segment are its candidate matches; geometric verification keeps the largest set of
// candidates consistent with one rigid transform, which is the pose.
#pragma once

#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "semsegmap/core/pose.h"
#include "semsegmap/localize/descriptor_index.h"
#include "semsegmap/localize/geometric_verification.h"
#include "semsegmap/localize/target_map.h"

namespace semsegmap {

struct LocalizerConfig {
  DescriptorIndexConfig index;
  GeometricVerificationConfig verification;
  // Fewer described local segments than this cannot give min_inliers matches: no query.
  size_t min_local_segments = 6;
};

struct Localization {
  Pose T_map_local = Pose::Identity();  // target map frame <- the robot's local map frame
  int inliers = 0;
  size_t candidates = 0;  // correspondences that went into verification
  // Matched pairs (local segment index into the query, target segment index).
  std::vector<std::pair<size_t, size_t>> matches;
};

// The localization a verification found among `candidates`: its pose and matched pairs.
Localization localizationOf(const VerificationResult& v,
                            const std::vector<Correspondence>& candidates);

// Owns or shares its target map: a saved map is shared between localizers (it never changes),
// a map that grows while the robot moves (loop closure) is the localizer's own, copied on the
// first change if it was shared. Growing adds to the descriptor index instead of rebuilding it.
class Localizer {
 public:
  Localizer(std::shared_ptr<const TargetMap> map, const LocalizerConfig& config);
  Localizer(TargetMap map, const LocalizerConfig& config);

  // `centroids` in the local map frame, one descriptor row each. `usable` (optional, one flag per
  // target segment) restricts the matches, e.g. to the older part of a map during loop closure.
  std::optional<Localization> localize(const std::vector<Eigen::Vector3f>& centroids,
                                       const Eigen::MatrixXf& descriptors,
                                       const std::vector<bool>* usable = nullptr) const;
  const TargetMap& map() const { return *map_; }
  const DescriptorIndex& index() const { return index_; }
  const LocalizerConfig& config() const { return config_; }

  // Appends segments (one descriptor row each, the map's dimension) to the map and the index.
  void append(const std::vector<MapSegment>& segments, const Eigen::MatrixXf& descriptors);
  // Moves segment i (e.g. after a pose graph optimization); the index is unchanged.
  void setCentroid(size_t i, const Eigen::Vector3f& centroid);

 private:
  TargetMap& ownMap();

  std::shared_ptr<const TargetMap> map_;
  std::shared_ptr<TargetMap> own_;  // map_ when the map is this localizer's own, else null
  LocalizerConfig config_;
  DescriptorIndex index_;
};

}  // namespace semsegmap
