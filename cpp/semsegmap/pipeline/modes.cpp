#include "semsegmap/pipeline/modes.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "semsegmap/pipeline/map_parameters.h"

namespace semsegmap {

namespace {

// Feeds the run's frames (at most options.max_frames) to a mapping or localization session.
template <typename Session>
void feed(FrameSource& source, const RunOptions& options, Session& session) {
  const size_t n = options.frameCount(source);
  for (size_t i = 0; i < n; ++i) {
    session.process(source.frame(i));
    if (options.progress) options.progress(i + 1, n);
  }
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

MappingSession::MappingSession(const PipelineConfig& config, const DatasetInfo& info,
                               PoseSource poses, std::shared_ptr<Describer> describer)
    : config_(config),
      pipeline_(config, info, poses, describer),
      builder_(descriptorName(describer->kind()), describer->fingerprint(), describer->dimension(),
               config.target_map) {
  builder_.setParameters(mapParametersOf(config));
}

void MappingSession::add(const std::vector<Segment>& segments,
                         const std::vector<Eigen::VectorXf>& d) {
  for (size_t i = 0; i < segments.size(); ++i)
    builder_.add(mapSegmentOf(segments[i], config_.target_map.max_points_per_segment), d[i]);
  run_.segments += segments.size();
}

void MappingSession::process(const Frame& frame) {
  const FrameResult r = pipeline_.process(frame);
  run_.trajectory.push_back(r.T_local_base);
  add(r.segmentation.finished, r.finished_descriptors);
  run_.stats.total += r.times;
  ++run_.stats.frames;
}

MappingRun MappingSession::finish() {
  std::vector<Eigen::VectorXf> last;
  const std::vector<Segment> remaining = pipeline_.finish(&last);
  add(remaining, last);
  run_.map = builder_.build();
  run_.duplicates_removed = builder_.duplicatesRemoved();
  return std::move(run_);
}

MappingRun runMapping(FrameSource& source, const PipelineConfig& config, PoseSource poses,
                      std::shared_ptr<Describer> describer, const RunOptions& options) {
  MappingSession session(config, source.info(), poses, describer);
  feed(source, options, session);
  return session.finish();
}

namespace {
std::shared_ptr<const TargetMap> checkedMap(std::shared_ptr<const TargetMap> map,
                                            const Describer& describer,
                                            const PipelineConfig& config,
                                            MapSettingsCheck settings) {
  if (!map) throw std::invalid_argument("no target map");
  const std::string name = map->source.empty() ? "the target map" : map->source;
  checkMapCompatible(name, *map, descriptorName(describer.kind()), describer.fingerprint(),
                     describer.dimension());
  checkMapParameters(name, *map, config, settings);
  if (config.localization.refinement.enabled && !hasSegmentPoints(*map))
    throw std::invalid_argument(
        "the target map stores no segment points, which localization.refinement needs: build "
        "it with target_map.max_points_per_segment (map --points N) or turn refinement off");
  return map;
}
}  // namespace

LocalizationSession::LocalizationSession(const PipelineConfig& config, const DatasetInfo& info,
                                         std::shared_ptr<const TargetMap> map,
                                         std::shared_ptr<Describer> describer,
                                         MapSettingsCheck settings)
    : config_(config),
      localizer_(checkedMap(std::move(map), *describer, config, settings),
                 config.localization.localizer),
      pipeline_(config, info, PoseSource::kOdometry, std::move(describer)) {}

void LocalizationSession::process(const Frame& frame) {
  FrameResult r = pipeline_.process(frame);
  if (!run_.trajectory_odom.empty())
    run_.distance_m +=
        (r.T_local_base.translation() - run_.trajectory_odom.back().translation()).norm();
  run_.trajectory_odom.push_back(r.T_local_base);
  if (frame.T_world_base) run_.trajectory_gt.push_back(*frame.T_world_base);
  const size_t every = std::max<size_t>(1, config_.localization.every_n_frames);
  if (frames_++ % every == 0) {
    const auto t0 = std::chrono::steady_clock::now();
    const LocalSegmentQuery q = pipeline_.localSegmentQuery();
    auto found = localizer_.localize(q.centroids, q.descriptors);
    std::optional<Refinement> refined;
    if (found && config_.localization.refinement.enabled) {
      refined = refine(*found, q);
      found->T_map_local = refined->T_map_local;
    }
    r.times.localize_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (found) record(frame, r, *found, q, refined ? &*refined : nullptr);
  }
  run_.stats.total += r.times;
  ++run_.stats.frames;
}

Refinement LocalizationSession::refine(const Localization& l, const LocalSegmentQuery& q) const {
  // Only the matched segments' points, and only once a match is found: copying every local
  // segment's points on every frame would be most of the work for nothing.
  std::vector<std::vector<Eigen::Vector3f>> local_points(q.ids.size());
  for (const auto& [query, target] : l.matches)
    if (local_points.at(query).empty())
      local_points[query] = pipeline_.observedPoints(q.ids[query]);
  return refinePose(l, local_points, localizer_.map(), config_.localization.refinement);
}

void LocalizationSession::record(const Frame& frame, const FrameResult& r, const Localization& l,
                                 const LocalSegmentQuery& q, const Refinement* refined) {
  LocalizationRecord rec;
  rec.frame_index = frame.index;
  rec.timestamp_s = frame.timestamp_s;
  rec.T_map_base = l.T_map_local * r.T_local_base;
  rec.inliers = l.inliers;
  rec.candidates = l.candidates;
  if (frame.T_world_base) {
    rec.T_world_base = *frame.T_world_base;
    rec.translation_error_m = translationError(rec.T_map_base, *frame.T_world_base);
    rec.rotation_error_deg = rotationErrorDeg(rec.T_map_base, *frame.T_world_base);
  }
  if (refined) {
    rec.refined = refined->applied;
    rec.refinement_correction_m = refined->correction_m;
  }
  for (const auto& [query, target] : l.matches)
    rec.matches.emplace_back((l.T_map_local * q.centroids.at(query).cast<double>()).cast<float>(),
                             localizer_.map().segments.at(target).centroid);
  run_.localizations.push_back(std::move(rec));
}

LocalizationRun runLocalization(FrameSource& source, const PipelineConfig& config,
                                std::shared_ptr<const TargetMap> map,
                                std::shared_ptr<Describer> describer, const RunOptions& options,
                                MapSettingsCheck settings) {
  LocalizationSession session(config, source.info(), std::move(map), std::move(describer),
                              settings);
  feed(source, options, session);
  return session.take();
}

LocalizationSummary summarize(const std::vector<LocalizationRecord>& records) {
  LocalizationSummary s;
  s.localizations = records.size();
  size_t with_gt = 0;
  for (const LocalizationRecord& r : records) {
    if (!r.T_world_base) continue;
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
