#include "semsegmap/pipeline/modes.h"

#include <algorithm>
#include <cmath>

namespace semsegmap {

namespace {

size_t framesToRun(const FrameSource& source, const RunOptions& options) {
  return options.max_frames > 0 ? std::min(source.size(), options.max_frames) : source.size();
}

MapSegment mapSegmentOf(const Segment& s, size_t points) {
  const SegmentObservation& o = s.last();
  MapSegment m;
  m.centroid = o.centroid.cast<float>();
  m.n_points = static_cast<uint32_t>(o.n_points);
  m.majority_class = o.majority_class;
  if (points > 0) {
    m.points.reserve(o.points.size());
    for (const EnrichedPoint& p : o.points) m.points.emplace_back(p.x, p.y, p.z);
  }
  return m;
}

}  // namespace

std::unique_ptr<Describer> makeDescriber(const DescriptorConfig& config, int threads) {
  DescriberOptions options;
  options.model_path = config.model;
  options.threads = threads;
  return makeDescriber(parseDescriptorKind(config.kind), options);
}

MappingRun runMapping(FrameSource& source, const PipelineConfig& config, PoseSource poses,
                      Describer& describer, const RunOptions& options) {
  Pipeline pipeline(config, source.info(), poses, &describer);
  TargetMapBuilder builder(descriptorName(describer.kind()), describer.fingerprint(),
                           describer.dimension(), config.target_map);
  MappingRun run;
  const size_t points = config.target_map.max_points_per_segment;
  auto add = [&](const std::vector<Segment>& segments, const std::vector<Eigen::VectorXf>& d) {
    for (size_t i = 0; i < segments.size(); ++i)
      builder.add(mapSegmentOf(segments[i], points), d[i]);
    run.segments += segments.size();
  };
  const size_t n = framesToRun(source, options);
  for (size_t i = 0; i < n; ++i) {
    const FrameResult r = pipeline.process(source.frame(i));
    run.trajectory.push_back(r.T_map_base);
    add(r.segmentation.finished, r.finished_descriptors);
    run.stats.total += r.times;
    ++run.stats.frames;
    if (options.progress) options.progress(i + 1, n);
  }
  std::vector<Eigen::VectorXf> last;
  const std::vector<Segment> remaining = pipeline.finish(&last);
  add(remaining, last);
  run.map = builder.build();
  run.duplicates_removed = builder.duplicatesRemoved();
  return run;
}

LocalizationRun runLocalization(FrameSource& source, const PipelineConfig& config,
                                const TargetMap& map, Describer& describer,
                                const RunOptions& options) {
  if (map.descriptor != descriptorName(describer.kind()) ||
      map.fingerprint != describer.fingerprint() || map.dimension() != describer.dimension())
    throw std::invalid_argument("the target map's descriptors (" + map.descriptor + " " +
                                map.fingerprint + ") do not match the describer's (" +
                                descriptorName(describer.kind()) + " " + describer.fingerprint() +
                                ")");
  const Localizer localizer(map, config.localization.localizer);
  Pipeline pipeline(config, source.info(), PoseSource::kOdometry, &describer);
  pipeline.setLocalizer(&localizer);
  LocalizationRun run;
  const size_t n = framesToRun(source, options);
  for (size_t i = 0; i < n; ++i) {
    const Frame frame = source.frame(i);
    const FrameResult r = pipeline.process(frame);
    if (!run.trajectory_odom.empty())
      run.distance_m +=
          (r.T_map_base.translation() - run.trajectory_odom.back().translation()).norm();
    run.trajectory_odom.push_back(r.T_map_base);
    if (frame.T_world_base_gt) run.trajectory_gt.push_back(*frame.T_world_base_gt);
    run.stats.total += r.times;
    ++run.stats.frames;
    if (r.localization) {
      const Localization& l = *r.localization;
      LocalizationRecord rec;
      rec.frame_index = frame.index;
      rec.timestamp_s = frame.timestamp_s;
      rec.T_map_robot = l.T_map_local * r.T_map_base;
      rec.inliers = l.inliers;
      rec.candidates = l.candidates;
      if (frame.T_world_base_gt) {
        rec.T_map_robot_gt = *frame.T_world_base_gt;
        rec.translation_error_m = translationError(rec.T_map_robot, *frame.T_world_base_gt);
        rec.rotation_error_deg = rotationErrorDeg(rec.T_map_robot, *frame.T_world_base_gt);
      }
      const auto& local = pipeline.localSegments();
      for (const auto& [q, t] : l.matches) {
        const Eigen::Vector3f c = local.at(r.query_segments.at(q)).centroid;
        rec.matches.emplace_back((l.T_map_local * c.cast<double>()).cast<float>(),
                                 map.segments.at(t).centroid);
      }
      run.localizations.push_back(std::move(rec));
    }
    if (options.progress) options.progress(i + 1, n);
  }
  return run;
}

LocalizationSummary summarize(const std::vector<LocalizationRecord>& records) {
  LocalizationSummary s;
  s.localizations = records.size();
  size_t with_gt = 0;
  for (const LocalizationRecord& r : records) {
    if (!r.T_map_robot_gt) continue;
    ++with_gt;
    s.below_1m += r.translation_error_m < 1.0;
    s.below_5m += r.translation_error_m < 5.0;
    s.mean_translation_error_m += r.translation_error_m;
    s.mean_rotation_error_deg += r.rotation_error_deg;
  }
  if (with_gt > 0) {
    s.mean_translation_error_m /= static_cast<double>(with_gt);
    s.mean_rotation_error_deg /= static_cast<double>(with_gt);
  }
  return s;
}

}  // namespace semsegmap
