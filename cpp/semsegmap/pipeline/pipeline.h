// The one place that wires the stages together, frame by frame: enrich -> local map ->
// incremental segmentation (describe and localize join here as they land). Mapping, localization
// and loop closure are configurations of this pipeline, not copies of it.
#pragma once

#include <memory>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/pipeline/pipeline_config.h"
#include "semsegmap/segment/incremental_segmenter.h"

namespace semsegmap {

enum class PoseSource { kGroundTruth, kOdometry };
PoseSource parsePoseSource(const std::string& name);  // "gt" | "odom"

struct StageTimes {
  double enrich_ms = 0, local_map_ms = 0, segment_ms = 0;
  double total() const { return enrich_ms + local_map_ms + segment_ms; }
};

struct FrameResult {
  size_t frame_index = 0;
  Pose T_map_base = Pose::Identity();
  size_t points = 0, colored_points = 0;
  LocalMapUpdate map_update;
  SegmentationUpdate segmentation;
  StageTimes times;
};

class Pipeline {
 public:
  Pipeline(const PipelineConfig& config, const DatasetInfo& info, PoseSource poses);

  // Throws when the frame lacks the pose asked for (ground truth on a dataset without it).
  FrameResult process(const Frame& frame);
  // End of the run: every segment still in the local map, finished.
  std::vector<Segment> finish() { return segmenter_.finishAll(); }

  const LocalMap& localMap() const { return local_map_; }
  const IncrementalSegmenter& segmenter() const { return segmenter_; }

 private:
  PipelineConfig config_;
  DatasetInfo info_;
  PoseSource poses_;
  LocalMap local_map_;
  IncrementalSegmenter segmenter_;
};

}  // namespace semsegmap
