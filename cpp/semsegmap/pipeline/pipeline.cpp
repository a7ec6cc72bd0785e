#include "semsegmap/pipeline/pipeline.h"

#include <chrono>
#include <stdexcept>

namespace semsegmap {

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

PoseSource parsePoseSource(const std::string& name) {
  if (name == "gt") return PoseSource::kGroundTruth;
  if (name == "odom") return PoseSource::kOdometry;
  throw std::invalid_argument("unknown pose source '" + name + "' (expected gt or odom)");
}

Pipeline::Pipeline(const PipelineConfig& config, const DatasetInfo& info, PoseSource poses)
    : config_(config),
      info_(info),
      poses_(poses),
      local_map_(config.local_map, info.classes),
      segmenter_(config.segmentation) {}

FrameResult Pipeline::process(const Frame& frame) {
  FrameResult r;
  r.frame_index = frame.index;
  if (poses_ == PoseSource::kGroundTruth) {
    if (!frame.T_world_base_gt)
      throw std::runtime_error("frame " + std::to_string(frame.index) +
                               " has no ground-truth pose (use --poses odom)");
    r.T_map_base = *frame.T_world_base_gt;
  } else {
    r.T_map_base = frame.T_world_base_odom;
  }

  auto t0 = std::chrono::steady_clock::now();
  const EnrichedCloud cloud = enrichFrame(frame, info_.rig, config_.enrichment);
  r.times.enrich_ms = msSince(t0);
  r.points = cloud.size();
  for (const auto& p : cloud) r.colored_points += p.has_color;

  t0 = std::chrono::steady_clock::now();
  // A scan carries semantics when the cameras gave classes or the points came with classes.
  bool semantic = false;
  for (const auto& cam : frame.cameras) semantic = semantic || !cam.label.empty();
  for (size_t k = 0; !semantic && k < frame.point_labels.size(); ++k)
    semantic = frame.point_labels[k].class_id != cls::kUnknown;
  r.map_update = local_map_.update(cloud, r.T_map_base * info_.rig.T_base_lidar,
                                   r.T_map_base.translation().head<2>(), semantic);
  r.times.local_map_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  r.segmentation = segmenter_.update(local_map_, r.map_update, frame.index, frame.timestamp_s);
  r.times.segment_ms = msSince(t0);
  return r;
}

}  // namespace semsegmap
