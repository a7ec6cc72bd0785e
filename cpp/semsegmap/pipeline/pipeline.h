// The front end, the one place that wires the stages together frame by frame: enrich -> local
// map -> incremental segmentation -> describe the segments whose observation changed (batched)
// -> the local segment map, which LocalSegmentQuery hands to a localizer. Mapping, localization
// and loop closure (pipeline/modes.h, pipeline/slam.h) run this front end and call the localizer
// themselves.
#pragma once

#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/describe/descriptor.h"
#include "semsegmap/localize/localizer.h"
#include "semsegmap/pipeline/front_end_stages.h"
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
  Pose T_local_base = Pose::Identity();   // the pose the local map is built with: its frame is
                                          // the world (ground-truth poses) or odometry
  size_t points = 0, colored_points = 0;  // unobserved ones: map_update.points_unobserved
  LocalMapUpdate map_update;
  SegmentationUpdate segmentation;
  // Parallel to segmentation.finished when a describer is set: the final observation's
  // descriptor.
  std::vector<Eigen::VectorXf> finished_descriptors;
  size_t described = 0;  // segments described this frame
  StageTimes times;      // localize_ms is filled by the mode that localizes
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
  // `describer` (optional; shared, e.g. by several runs of one experiment, but used by one
  // pipeline at a time) turns segment observations into descriptors. `stages` (optional) label
  // and register each frame before enrichment (pipeline/front_end_stages.h).
  Pipeline(const PipelineConfig& config, const DatasetInfo& info, PoseSource poses,
           std::shared_ptr<Describer> describer = nullptr, const FrontEndStages& stages = {});

  // Throws when the frame lacks the pose asked for (ground truth on a dataset without it).
  FrameResult process(const Frame& frame);
  // The frame the last process() worked on, given the frame passed to it: that frame itself, or
  // with front-end stages its labelled and registered copy.
  const Frame& processedFrame(const Frame& given) const { return preparation_.last(given); }
  // How often the front end's network ran; nullptr without one.
  std::optional<LabelingStats> labeling() const { return preparation_.labeling(); }
  // End of the run: every segment still in the local map, finished; `descriptors` (optional)
  // receives their final descriptors when a describer is set.
  std::vector<Segment> finish(std::vector<Eigen::VectorXf>* descriptors = nullptr);

  const IncrementalSegmenter& segmenter() const { return segmenter_; }
  const std::unordered_map<SegmentId, DescribedSegment>& localSegments() const {
    return described_;
  }
  LocalSegmentQuery localSegmentQuery() const;
  // The points of a local segment's described observation (local map frame), for pose
  // refinement: asked for the matched segments only, after a localization.
  std::vector<Eigen::Vector3f> observedPoints(SegmentId id) const;
  const Describer* describer() const { return describer_.get(); }

 private:
  void describe(const std::vector<SegmentId>& ids, size_t frame_index);
  // The descriptor of a finished segment's final observation.
  Eigen::VectorXf finalDescriptor(const Segment& s) const;
  // Counts the points a camera gave a class; after the first frames (or at the end of a shorter
  // run), warns once when so few have one that the semantic part is nearly off.
  void checkCameraCoverage(const LocalMapUpdate& update, size_t points, bool at_end);

  PipelineConfig config_;
  DatasetInfo info_;
  PoseSource poses_;
  FramePreparation preparation_;
  LocalMap local_map_;
  IncrementalSegmenter segmenter_;
  std::shared_ptr<Describer> describer_;
  std::unordered_map<SegmentId, DescribedSegment> described_;
  struct {
    size_t frames = 0, points = 0, unobserved = 0;
    bool checked = false;
  } coverage_;
};

}  // namespace semsegmap
