// The one place that wires the stages together, frame by frame: enrich -> local map ->
// incremental segmentation -> describe the segments whose observation changed (batched) -> local
// segment map -> localization query. Mapping, localization and loop closure are configurations
// of this pipeline (pipeline/modes.h), not copies of it.
#pragma once

#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/describe/descriptor.h"
#include "semsegmap/localize/localizer.h"
#include "semsegmap/pipeline/pipeline_config.h"
#include "semsegmap/segment/incremental_segmenter.h"

namespace semsegmap {

enum class PoseSource { kGroundTruth, kOdometry };
PoseSource parsePoseSource(const std::string& name);  // "gt" | "odom"

struct StageTimes {
  double enrich_ms = 0, local_map_ms = 0, segment_ms = 0, describe_ms = 0, localize_ms = 0;
  double total() const { return enrich_ms + local_map_ms + segment_ms + describe_ms + localize_ms; }
  StageTimes& operator+=(const StageTimes& o);
};

// A segment of the local segment map: its latest observation, described.
struct DescribedSegment {
  SegmentId id = 0;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // local map frame
  uint32_t n_points = 0;
  ClassId majority_class = cls::kUnknown;
  size_t frame_index = 0;  // of the observation
  Eigen::VectorXf descriptor;
};

struct FrameResult {
  size_t frame_index = 0;
  Pose T_map_base = Pose::Identity();  // the pose the local map is built with (gt or odometry)
  size_t points = 0, colored_points = 0;
  LocalMapUpdate map_update;
  SegmentationUpdate segmentation;
  // Parallel to segmentation.finished when a describer is set: the final observation's
  // descriptor.
  std::vector<Eigen::VectorXf> finished_descriptors;
  size_t described = 0;                      // segments described this frame
  std::optional<Localization> localization;  // when a localizer is set and it succeeded
  std::vector<SegmentId> query_segments;     // local segment of each Localization match index
  StageTimes times;
};

// The local segment map as a localization query: ids in ascending order (a deterministic query
// order), their centroids in the local map frame and one descriptor row each.
struct LocalSegmentQuery {
  std::vector<SegmentId> ids;
  std::vector<Eigen::Vector3f> centroids;
  Eigen::MatrixXf descriptors;
};

class Pipeline {
 public:
  // `describer` (optional, not owned) turns segment observations into descriptors.
  Pipeline(const PipelineConfig& config, const DatasetInfo& info, PoseSource poses,
           Describer* describer = nullptr);

  // Optional, not owned; needs a describer. `usable` (one flag per target segment, optional)
  // limits the matches. Queries run every config.localization.every_n_frames frames.
  void setLocalizer(const Localizer* localizer, const std::vector<bool>* usable = nullptr);

  // Throws when the frame lacks the pose asked for (ground truth on a dataset without it).
  FrameResult process(const Frame& frame);
  // End of the run: every segment still in the local map, finished; `descriptors` (optional)
  // receives their final descriptors when a describer is set.
  std::vector<Segment> finish(std::vector<Eigen::VectorXf>* descriptors = nullptr);

  const LocalMap& localMap() const { return local_map_; }
  const IncrementalSegmenter& segmenter() const { return segmenter_; }
  const std::unordered_map<SegmentId, DescribedSegment>& localSegments() const {
    return described_;
  }
  LocalSegmentQuery localSegmentQuery() const;

 private:
  void describe(const std::vector<SegmentId>& ids, size_t frame_index);
  // The descriptor of a finished segment's final observation.
  Eigen::VectorXf finalDescriptor(const Segment& s) const;

  PipelineConfig config_;
  DatasetInfo info_;
  PoseSource poses_;
  LocalMap local_map_;
  IncrementalSegmenter segmenter_;
  Describer* describer_ = nullptr;
  const Localizer* localizer_ = nullptr;
  const std::vector<bool>* usable_ = nullptr;
  std::unordered_map<SegmentId, DescribedSegment> described_;
  size_t frames_ = 0;
};

}  // namespace semsegmap
