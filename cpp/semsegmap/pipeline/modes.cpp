#include "semsegmap/pipeline/modes.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/localize/registration_check.h"
#include "semsegmap/pipeline/live_session.h"
#include "semsegmap/pipeline/map_parameters.h"

namespace semsegmap {

// Between frames only: a frame the session started is finished, so what it holds stays whole.
bool feedFrames(FrameSource& source, const RunOptions& options,
                const std::function<void(const Frame&)>& process) {
  const size_t n = options.frameCount(source);
  for (size_t i = 0; i < n; ++i) {
    if (options.stop.stopRequested()) return false;
    process(source.frame(i));
    if (options.progress) options.progress(i + 1, n);
  }
  return true;
}

namespace {

// Feeds the run's frames (at most options.max_frames) to a mapping or localization session
// through the live core (live_session.h), as a robot's would be, but never dropping: the session
// works on one frame on the live session's worker while the next is read and decoded, in order,
// so a recording gives what it gave frame by frame. Whether every frame was fed.
template <typename Session>
bool feed(FrameSource& source, const RunOptions& options, Session& session) {
  LiveConfig config;
  config.never_drop = true;
  LiveSession live(config, [&session](const Frame& frame) {
    session.process(frame);
    return std::vector<LivePose>{};
  });
  const bool whole =
      feedFrames(source, options, [&live](const Frame& frame) { live.addFrame(frame); });
  live.finish();
  return whole;
}

// The describer is checked before any of it is read: a constructor's arguments are evaluated in
// no fixed order.
TargetMapBuilder builderFor(const Describer& describer, const TargetMapBuilderConfig& config) {
  return TargetMapBuilder(descriptorName(describer.kind()), describer.fingerprint(),
                          describer.dimension(), config);
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
                               PoseSource poses, std::shared_ptr<Describer> describer,
                               const FrontEndStages& stages)
    : config_(config),
      pipeline_(config, info, poses, describer, stages),
      builder_(builderFor(requireDescriber(describer, "MappingSession"), config.target_map)),
      T_base_lidar_(info.rig.T_base_lidar) {
  builder_.setParameters(mapParametersOf(config));
}

// The scan context of a scan every target_map.scan_context_apart_m, for a map a relocalization can
// use (one with segment points): made in the LiDAR's frame turned level with the base.
void MappingSession::keepScanContext(const Frame& frame, const Pose& T_local_base) {
  const TargetMapBuilderConfig& c = config_.target_map;
  if (c.max_points_per_segment == 0 || c.scan_context_apart_m <= 0) return;
  const Pose T_local_scan = scanContextFrame(T_local_base, T_base_lidar_);
  if (last_scan_context_ &&
      (T_local_scan.translation() - *last_scan_context_).norm() < c.scan_context_apart_m)
    return;
  last_scan_context_ = T_local_scan.translation();
  builder_.addScan(makeScanContext(frame.points, ScanContextConfig{}, T_base_lidar_.linear()),
                   T_local_scan);
}

void MappingSession::add(const std::vector<Segment>& segments,
                         const std::vector<Eigen::VectorXf>& d) {
  const double apart = config_.target_map.earlier_observations_apart_m;
  for (size_t i = 0; i < segments.size(); ++i) {
    MapSegment final = mapSegmentOf(segments[i], config_.target_map.max_points_per_segment);
    final.keyframe = currentKeyframe();
    // The earlier observations first: the builder lets a later segment replace an earlier one
    // nearby, and the final observation is the most complete.
    if (auto views = earlier_.extract(segments[i].id))
      for (const KeptObservation& k : views.mapped().kept)
        if ((k.segment.centroid - final.centroid).norm() >= apart) {
          builder_.add(k.segment, k.descriptor);
          ++run_.earlier_observations;
        }
    builder_.add(final, d[i]);
  }
  run_.segments += segments.size();
}

void MappingSession::keep(std::vector<KeptObservation>& kept, KeptObservation observation) const {
  const double apart = config_.target_map.earlier_observations_apart_m;
  if (observation.descriptor.size() == 0) return;  // never described
  for (const KeptObservation& k : kept)
    if ((k.segment.centroid - observation.segment.centroid).norm() < apart) return;
  kept.push_back(std::move(observation));
}

// A segment's observation is kept when the next one has moved its centroid `apart` from the last
// kept (or the first): the place as it looked before the views that moved it (with sparse scans,
// as of one scan), which a robot that comes back with fewer views sees again. A segment absorbed
// by another hands its views to it, its last observation among them. The observations come as
// the pipeline described them, so keeping them costs no description.
void MappingSession::keepEarlierObservations(const FrameResult& r) {
  const double apart = config_.target_map.earlier_observations_apart_m;
  if (apart <= 0) return;
  for (const SegmentMerge& m : r.segmentation.merges) {
    auto absorbed = earlier_.extract(m.absorbed);
    if (!absorbed) continue;
    SegmentViews& survivor = earlier_[m.survivor];
    for (KeptObservation& k : absorbed.mapped().kept) keep(survivor.kept, std::move(k));
    keep(survivor.kept, std::move(absorbed.mapped().latest));
  }
  for (SegmentId id : r.segmentation.dropped) earlier_.erase(id);  // never goes into the map
  const auto& described = pipeline_.localSegments();
  for (SegmentId id : r.segmentation.observed) {
    const auto it = described.find(id);
    if (it == described.end()) continue;  // finished this frame: its final observation goes in
    const DescribedSegment& e = it->second;
    SegmentViews& views = earlier_[id];
    // Its first observation: a segment that absorbed others before it was first observed holds
    // their views, but none of its own yet.
    const bool first = views.latest.descriptor.size() == 0;
    KeptObservation k;
    k.segment.centroid = e.centroid;
    k.segment.n_points = e.n_points;
    k.segment.majority_class = e.majority_class;
    k.segment.keyframe = currentKeyframe();
    k.segment.points =
        subsamplePoints(pipeline_.observedPoints(id), config_.target_map.max_points_per_segment);
    k.descriptor = e.descriptor;
    if (first) {
      views.since = k.segment.centroid;
    } else if ((k.segment.centroid - views.since).norm() >= apart) {
      views.since = views.latest.segment.centroid;
      keep(views.kept, std::move(views.latest));
    }
    views.latest = std::move(k);
  }
}

// A segment can also leave the local map unfinished: one dropped as too large (its observations
// cleared) is never handed out when its voxels leave. Its views go with it, as its final
// observation does, instead of being held until the run ends.
void MappingSession::forgetVanishedSegments() {
  const IncrementalSegmenter& segmenter = pipeline_.segmenter();
  for (auto it = earlier_.begin(); it != earlier_.end();)
    it = segmenter.segment(it->first) ? std::next(it) : earlier_.erase(it);
}

std::vector<SegmentId> MappingSession::segmentsWithEarlierObservations() const {
  std::vector<SegmentId> out;
  for (const auto& [id, views] : earlier_) out.push_back(id);
  return out;
}

void MappingSession::process(const Frame& frame) {
  const FrameResult r = pipeline_.process(frame);
  run_.trajectory.push_back(r.T_local_base);
  keepScanContext(frame, r.T_local_base);
  keepEarlierObservations(r);
  add(r.segmentation.finished, r.finished_descriptors);
  forgetVanishedSegments();
  run_.stats.total += r.times;
  ++run_.stats.frames;
}

MappingRun MappingSession::finish() {
  std::vector<Eigen::VectorXf> last;
  const std::vector<Segment> remaining = pipeline_.finish(&last);
  add(remaining, last);
  run_.map = builder_.build();
  run_.duplicates_removed = builder_.duplicatesRemoved();
  run_.stats.labelling = pipeline_.labeling();
  return std::move(run_);
}

MappingRun runMapping(FrameSource& source, const PipelineConfig& config, PoseSource poses,
                      std::shared_ptr<Describer> describer, const RunOptions& options) {
  MappingSession session(config, source.info(), poses, describer, options.stages);
  const bool whole = feed(source, options, session);
  MappingRun run = session.finish();
  run.stats.interrupted = !whole;
  return run;
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

// Relocalization checks a pose on the map's stored points, about one per 0.5 x 0.5 m of
// surface (registration_check.h): a map that keeps fewer than this for its largest segments
// (every map built with the paper's settings, or the 32 points pose refinement needs) cannot
// tell a right place from a look-alike.
constexpr size_t kRelocalizationPoints = 256;

// Whether `map` holds what relocalization needs; otherwise relocalization is off for the run,
// which says so in one line: a robot still localizes on a map built before it, and only loses
// the wake-up from one scan.
bool relocalizationPossible(const std::string& name, const TargetMap& map,
                            const RelocalizationConfig& config) {
  if (!config.enabled) return false;
  size_t most = 0;
  for (const MapSegment& s : map.segments) most = std::max(most, s.points.size());
  const std::string rebuild =
      "rebuild the map with target_map.max_points_per_segment: 512 and "
      "target_map.scan_context_apart_m: 1.0 (as config/lidar-camera.yaml has them)";
  if (most < kRelocalizationPoints || !hasSegmentPoints(map)) {
    note(name + ": keeps " + (most == 0 ? std::string("no") : "at most " + std::to_string(most)) +
         " points a segment, too few to check a relocalization, so relocalization is off for "
         "this run; " +
         rebuild);
    return false;
  }
  if (config.scan_context && map.scan_contexts.size() == 0)
    note(name +
         ": holds no scan contexts, so a relocalization checks only the places its segments "
         "vote for; " +
         rebuild);
  return true;
}

// Each local segment's points, as its latest observation holds them.
std::vector<std::vector<Eigen::Vector3f>> segmentPoints(const Pipeline& pipeline,
                                                        const LocalSegmentQuery& q) {
  std::vector<std::vector<Eigen::Vector3f>> points(q.ids.size());
  for (size_t i = 0; i < points.size(); ++i) points[i] = pipeline.observedPoints(q.ids[i]);
  return points;
}
}  // namespace

LocalizationSession::LocalizationSession(const PipelineConfig& config, const DatasetInfo& info,
                                         std::shared_ptr<const TargetMap> map,
                                         std::shared_ptr<Describer> describer,
                                         MapSettingsCheck settings, const FrontEndStages& stages)
    : config_(config),
      info_(infoWithStages(info, stages)),
      describer_(describer),
      stages_(stages),
      localizer_(checkedMap(std::move(map), requireDescriber(describer, "LocalizationSession"),
                            config, settings),
                 config.localization.localizer),
      pipeline_(config, info, PoseSource::kOdometry, describer, stages) {
  run_.odometry_is_ground_truth = info_.odometry_is_ground_truth;
  const TargetMap& target = localizer_.map();
  config_.localization.relocalization.enabled =
      relocalizationPossible(target.source.empty() ? "the target map" : target.source, target,
                             config.localization.relocalization);
}

// Without history, each list keeps its last entry: the latest frame's poses and stamp (the
// distance moved is measured from its odometry pose) and the latest localization.
namespace {
template <typename T>
void keepLast(std::vector<T>& v) {
  if (v.size() > 1) v.erase(v.begin(), v.end() - 1);
}
}  // namespace

void LocalizationSession::forgetHistory() {
  keepLast(run_.localizations);
  keepLast(run_.ambiguous);
  keepLast(run_.frames);
  keepLast(run_.trajectory_gt);
  keepLast(run_.trajectory_odom);
}

std::optional<LocalizationRecord> LocalizationSession::process(const Frame& frame) {
  std::optional<LocalizationRecord> found;
  FrameResult r = pipeline_.process(frame);
  const double moved =
      run_.trajectory_odom.empty()
          ? 0.0
          : (r.T_local_base.translation() - run_.trajectory_odom.back().translation()).norm();
  run_.distance_m += moved;
  run_.trajectory_odom.push_back(r.T_local_base);
  run_.frames.push_back(stampOf(frame, info_));
  if (frame.T_world_base) run_.trajectory_gt.push_back(*frame.T_world_base);
  const size_t every = std::max<size_t>(1, config_.localization.every_n_frames);
  if (frames_++ % every == 0) {
    const auto t0 = std::chrono::steady_clock::now();
    const RelocalizationConfig& reloc = config_.localization.relocalization;
    const bool lost = localized_at_m_ < 0 || run_.distance_m - localized_at_m_ >= reloc.after_m;
    const Outcome o =
        localizeFrame(pipeline_, frame, r.T_local_base, moved, reloc.enabled && lost, prior_);
    r.times.localize_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (o.attempt.found && o.attempt.ambiguous) {
      run_.ambiguous.push_back(recordOf(frame, o));
    } else if (o.attempt.found) {
      run_.localizations.push_back(recordOf(frame, o));
      found = run_.localizations.back();
      localized_at_m_ = run_.distance_m;
      T_map_local_ = o.T_map_base * r.T_local_base.inverse();
    }
  }
  if (tiles_) followRobot(r.T_local_base);
  run_.stats.total += r.times;
  ++run_.stats.frames;
  if (!keep_history_) forgetHistory();
  return found;
}

// Where the robot is in the map (its last localization carried on by odometry): far enough from
// where the tiles were last asked for, the tiles around it join the localizer. The query runs in
// the scan loop, once every half tile (50 m, seconds of driving): a 100 m disc of a 10-million-
// segment store loads in 3-6 ms (docs/map-store.md), less than a frame's slack at 10 Hz, so it is
// not worth a thread of its own.
void LocalizationSession::followRobot(const Pose& T_local_base) {
  if (!T_map_local_) return;
  const Eigen::Vector2d at = (*T_map_local_ * T_local_base).translation().head<2>();
  if ((at - tiles_->centre()).norm() < tiles_->reloadAfterM()) return;
  const TargetMap more = tiles_->around(at.x(), at.y());
  localizer_.append(more.segments, more.descriptors);
}

// The local map's segments first; then, when the scan lies far from the one before, its own
// segments (localization.latest_scan_fallback_m); then, when the robot has not been localized
// for a while, those of the last try against the whole map (localization.relocalization).
LocalizationSession::Outcome LocalizationSession::localizeFrame(
    const Pipeline& pipeline, const Frame& frame, const Pose& T_local_base, double moved,
    bool relocalize, const std::optional<RelocalizationPrior>& prior) const {
  Outcome o;
  o.attempt = attempt(pipeline);
  if (relocalize || jumps(o.attempt, T_local_base))
    requireRegistration(pipeline, frame, T_local_base, o.attempt);
  const Pipeline* tried = &pipeline;
  Pose base = T_local_base;
  std::optional<Pipeline> scan;
  const double fallback_m = config_.localization.latest_scan_fallback_m;
  if (!o.attempt.found && fallback_m > 0 && moved >= fallback_m) {
    scan.emplace(config_, info_, PoseSource::kOdometry, describer_);
    // The scan as the front-end stages left it: labelled and posed.
    base = scan->process(pipeline.processedFrame(frame)).T_local_base;
    o.attempt = attempt(*scan);
    if (relocalize || jumps(o.attempt, base)) requireRegistration(*scan, frame, base, o.attempt);
    o.path = LocalizationPath::kLatestScan;
    tried = &*scan;
  }
  if (!o.attempt.found && relocalize) {
    o.attempt = attemptRelocalization(*tried, frame, base, prior);
    o.path = o.attempt.by_scan_context ? LocalizationPath::kScanContext
                                       : LocalizationPath::kRelocalization;
  }
  if (o.attempt.found) o.T_map_base = o.attempt.found->T_map_local * base;
  return o;
}

LocalizationSession::Attempt LocalizationSession::attempt(const Pipeline& pipeline) const {
  Attempt a;
  a.query = pipeline.localSegmentQuery();
  a.found = localizer_.localize(a.query.centroids, a.query.descriptors);
  if (a.found && config_.localization.refinement.enabled) {
    a.refined = refine(pipeline, *a.found, a.query);
    a.found->T_map_local = a.refined->T_map_local;
    if (a.refined->applied) a.evidence = a.refined->evidence;
  }
  return a;
}

// While lost, a pose from the local map or the latest scan must pass the relocalization's
// registration check too: a robot waking up where the map has nothing can find six consistent
// matches somewhere (the simulator's VLP-32 did, at a third of its wake-ups away from the map).
void LocalizationSession::requireRegistration(const Pipeline& pipeline, const Frame& frame,
                                              const Pose& T_local_base, Attempt& a) const {
  if (!a.found) return;
  const RelocalizationConfig& config = config_.localization.relocalization;
  RegistrationCheck c =
      checkRegistration(segmentPoints(pipeline, a.query), T_local_base.translation(),
                        localizer_.map(), a.found->T_map_local, config.check);
  // The scan context only matters to a pose the points alone did not accept, and to one whose
  // heading the map's scans nearby contradict.
  const std::optional<ScanContextQuery> scan = scanContextQuery(frame, T_local_base);
  if (!c.accepted) corroborate(c, localizer_.map(), scan, config);
  refuseAContradictedHeading(c, localizer_.map(), scan, config);
  if (!c.accepted) {
    a.found.reset();
    a.refined.reset();
    return;
  }
  a.found->T_map_local = c.T_map_local;
  a.fitness = c.fitness;
  a.evidence = c.evidence;
}

// Whether a pose found while the robot holds one (not lost) lies farther from it than
// relocalization.jump_m or jump_deg: then it must pass the registration check too. Only with the
// map's points at hand (relocalization on); the simulator's configurations keep the paper's path.
bool LocalizationSession::jumps(const Attempt& a, const Pose& T_local_base) const {
  const RelocalizationConfig& config = config_.localization.relocalization;
  if (!a.found || !T_map_local_ || !config.enabled) return false;
  return jumpsFrom(*T_map_local_ * T_local_base, a.found->T_map_local * T_local_base, config);
}

// The scan's scan context on the map's grid, when the map holds scan contexts and the
// relocalization uses them.
std::optional<ScanContextQuery> LocalizationSession::scanContextQuery(
    const Frame& frame, const Pose& T_local_base) const {
  const ScanContextDatabase& scans = localizer_.map().scan_contexts;
  if (!config_.localization.relocalization.scan_context || scans.size() == 0) return std::nullopt;
  const Pose& T_base_lidar = info_.rig.T_base_lidar;
  return ScanContextQuery{makeScanContext(frame.points, scans.config(), T_base_lidar.linear()),
                          scanContextFrame(T_local_base, T_base_lidar)};
}

LocalizationSession::Attempt LocalizationSession::attemptRelocalization(
    const Pipeline& pipeline, const Frame& frame, const Pose& T_local_base,
    const std::optional<RelocalizationPrior>& prior) const {
  Attempt a;
  a.query = pipeline.localSegmentQuery();
  const std::vector<std::vector<Eigen::Vector3f>> points = segmentPoints(pipeline, a.query);
  const std::optional<Relocalization> r = semsegmap::relocalize(
      localizer_, a.query.centroids, a.query.descriptors, points, T_local_base.translation(),
      config_.localization.relocalization, prior, scanContextQuery(frame, T_local_base));
  if (r) {
    a.found = r->match;
    a.fitness = r->check.fitness;
    a.by_scan_context = r->by_scan_context;
    a.ambiguous = r->ambiguous;
    a.runner_up_fitness = r->runner_up_fitness;
    a.evidence = r->check.evidence;
  }
  return a;
}

Refinement LocalizationSession::refine(const Pipeline& pipeline, const Localization& l,
                                       const LocalSegmentQuery& q) const {
  // Only the matched segments' points (with refinement.neighbours_m, every local segment's), and
  // only once a match is found: copying every local segment's points on every frame would be
  // most of the work for nothing.
  std::vector<std::vector<Eigen::Vector3f>> local_points(q.ids.size());
  if (config_.localization.refinement.neighbours_m > 0)
    for (size_t i = 0; i < q.ids.size(); ++i) local_points[i] = pipeline.observedPoints(q.ids[i]);
  for (const auto& [query, target] : l.matches)
    if (local_points.at(query).empty()) local_points[query] = pipeline.observedPoints(q.ids[query]);
  return refinePose(l, local_points, localizer_.map(), config_.localization.refinement);
}

std::optional<LocalizationRecord> LocalizationSession::relocalize(
    const Frame& frame, const std::optional<RelocalizationPrior>& prior) const {
  if (!hasSegmentPoints(localizer_.map()))
    throw std::invalid_argument(
        "relocalize: the target map stores no segment points, which a relocalization needs to "
        "check a pose: build it with target_map.max_points_per_segment (map --points N)");
  // No odometry: one scan's local map is in the scan's own frame (the frame's T_odom_base).
  DatasetInfo info = info_;
  info.has_odometry = true;
  Pipeline scan(
      config_, info, PoseSource::kOdometry, describer_,
      FrontEndStages{stages_.network, std::nullopt, FrontEndStages::Labelling::kEveryPicture});
  const Pose T_local_base = scan.process(frame).T_local_base;
  const Outcome o = localizeFrame(scan, frame, T_local_base, 0.0, true, prior);
  // An ambiguous pose is no answer: the scan fits another place as well.
  if (!o.attempt.found || o.attempt.ambiguous) return std::nullopt;
  return recordOf(frame, o);
}

LocalizationRecord LocalizationSession::recordOf(const Frame& frame, const Outcome& o) const {
  const Attempt& a = o.attempt;
  const Localization& l = *a.found;
  LocalizationRecord rec;
  rec.frame_index = frame.index;
  const FrameStamp stamp = stampOf(frame, info_);
  rec.frame_number = stamp.number;
  rec.timestamp_s = stamp.time_s;
  rec.T_map_base = o.T_map_base;
  rec.inliers = l.inliers;
  rec.candidates = l.candidates;
  rec.path = o.path;
  rec.registration_fitness = a.fitness;
  if (frame.T_world_base) {
    rec.T_world_base = *frame.T_world_base;
    rec.translation_error_m = translationError(rec.T_map_base, *frame.T_world_base);
    rec.rotation_error_deg = rotationErrorDeg(rec.T_map_base, *frame.T_world_base);
  }
  if (a.refined) {
    rec.refined = a.refined->applied;
    rec.refinement_correction_m = a.refined->correction_m;
  }
  for (const auto& [query, target] : l.matches)
    rec.matches.emplace_back(
        (l.T_map_local * a.query.centroids.at(query).cast<double>()).cast<float>(),
        localizer_.map().segments.at(target).centroid);
  rec.ambiguous = a.ambiguous;
  rec.runner_up_fitness = a.runner_up_fitness;  // a relocalization's alone
  const PoseCovarianceConfig& cc = config_.localization.covariance;
  rec.covariance =
      a.evidence ? covarianceFromEvidence(*a.evidence, rec.T_map_base.translation(),
                                          cc.registration_inflation, cc)
                 : covarianceFromEvidence(centroidEvidence(rec.matches),
                                          rec.T_map_base.translation(), cc.centroid_inflation, cc);
  return rec;
}

const char* localizationPathName(LocalizationPath path) {
  switch (path) {
    case LocalizationPath::kLocalMap:
      return "local-map";
    case LocalizationPath::kLatestScan:
      return "latest-scan";
    case LocalizationPath::kRelocalization:
      return "relocalization";
    case LocalizationPath::kScanContext:
      return "scan-context";
  }
  return "?";
}

LocalizationRun runLocalization(FrameSource& source, const PipelineConfig& config,
                                std::shared_ptr<const TargetMap> map,
                                std::shared_ptr<Describer> describer, const RunOptions& options,
                                MapSettingsCheck settings, std::optional<RelocalizationPrior> prior,
                                std::shared_ptr<MapTileSource> tiles) {
  LocalizationSession session(config, source.info(), std::move(map), std::move(describer), settings,
                              options.stages);
  session.setPrior(std::move(prior));
  session.followTiles(std::move(tiles));
  const bool whole = feed(source, options, session);
  LocalizationRun run = session.take();
  run.stats.interrupted = !whole;
  return run;
}

void summarizeCovariances(
    const std::vector<std::pair<const Covariance6*, Eigen::Vector3d>>& covariance_and_error,
    LocalizationSummary& s) {
  std::vector<double> sigmas;
  double nees_sum = 0.0;
  size_t within = 0;
  for (const auto& [covariance, error] : covariance_and_error) {
    const double nees = positionNees(*covariance, error);
    nees_sum += nees;
    within += nees <= 9.0;
    sigmas.push_back(std::sqrt(covariance->topLeftCorner<3, 3>().trace() / 3.0));
  }
  if (sigmas.empty()) return;
  const double n = static_cast<double>(sigmas.size());
  s.share_mahalanobis_within_3 = static_cast<double>(within) / n;
  s.mean_nees = nees_sum / n;
  std::nth_element(sigmas.begin(), sigmas.begin() + static_cast<long>(sigmas.size() / 2),
                   sigmas.end());
  s.median_sigma_m = sigmas[sigmas.size() / 2];
}

LocalizationSummary summarize(const std::vector<LocalizationRecord>& records) {
  LocalizationSummary s;
  s.localizations = records.size();
  size_t below_1m = 0, below_5m = 0;
  double translation = 0.0, rotation = 0.0;
  for (const LocalizationRecord& r : records) {
    if (!r.T_world_base) continue;
    ++s.with_ground_truth;
    below_1m += r.translation_error_m < 1.0;
    below_5m += r.translation_error_m < 5.0;
    translation += r.translation_error_m;
    rotation += r.rotation_error_deg;
  }
  if (s.with_ground_truth == s.localizations) {
    s.below_1m = below_1m;
    s.below_5m = below_5m;
  }
  if (s.with_ground_truth > 0) {
    s.mean_translation_error_m = translation / static_cast<double>(s.with_ground_truth);
    s.mean_rotation_error_deg = rotation / static_cast<double>(s.with_ground_truth);
  }
  std::vector<std::pair<const Covariance6*, Eigen::Vector3d>> errors;
  for (const LocalizationRecord& r : records)
    if (r.T_world_base)
      errors.emplace_back(&r.covariance,
                          r.T_map_base.translation() - r.T_world_base->translation());
  summarizeCovariances(errors, s);
  return s;
}

LocalizationSummary summarize(const LocalizationRun& run) {
  LocalizationSummary s = summarize(run.localizations);
  if (run.trajectory_gt.empty()) s.below_1m = s.below_5m = std::nullopt;
  return s;
}

}  // namespace semsegmap
