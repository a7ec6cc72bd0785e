#include "semsegmap/pipeline/session_merge.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "semsegmap/graph/pose_graph.h"
#include "semsegmap/pipeline/map_parameters.h"

namespace semsegmap {

namespace {

const TargetMap& checkedMergeTarget(const std::shared_ptr<const TargetMap>& map,
                                    const Describer& describer, const PipelineConfig& config) {
  if (!map) throw std::invalid_argument("SessionMerge: no map to merge into");
  const std::string name = map->source.empty() ? "the map" : map->source;
  checkMapCompatible(name, *map, descriptorName(describer.kind()), describer.fingerprint(),
                     describer.dimension());
  checkMapParameters(name, *map, config, MapSettingsCheck::kRefuse,
                     "map the session with the map's configuration");
  return *map;
}

// The entries of `map` on a grid of `cell` metres, to find an entry's neighbours within `cell`
// among thousands without comparing every pair.
class EntryGrid {
 public:
  EntryGrid(const TargetMap& map, double cell) : map_(map), cell_(cell) {
    for (size_t i = 0; i < map.segments.size(); ++i)
      cells_[key(cellOf(map.segments[i].centroid))].push_back(i);
  }
  // The entries of class `c` within the cell size of `p`.
  std::vector<size_t> near(const Eigen::Vector3f& p, ClassId c) const {
    const Eigen::Vector3i at = cellOf(p);
    std::vector<size_t> out;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(key(at + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (size_t i : it->second) {
            const MapSegment& s = map_.segments[i];
            if (s.majority_class == c && (s.centroid - p).norm() < cell_) out.push_back(i);
          }
        }
    return out;
  }

 private:
  Eigen::Vector3i cellOf(const Eigen::Vector3f& p) const {
    return (p.cast<double>() / cell_).array().floor().cast<int>();
  }
  static int64_t key(const Eigen::Vector3i& c) {
    return (static_cast<int64_t>(c.x()) * 73856093) ^ (static_cast<int64_t>(c.y()) * 19349663) ^
           (static_cast<int64_t>(c.z()) * 83492791);
  }
  const TargetMap& map_;
  double cell_;
  std::unordered_map<int64_t, std::vector<size_t>> cells_;
};

// Of the older entries of `e`'s class near it, the one whose descriptor is nearest: the final
// observations of one object by two sessions differ by up to a metre (a building seen from
// other streets, a hedge behind other parked cars), so nearness alone would join neighbours.
std::optional<size_t> sameSegment(const TargetMap& map, const EntryGrid& older, const MapSegment& e,
                                  const Eigen::VectorXf& descriptor) {
  std::optional<size_t> best;
  float best_d = std::numeric_limits<float>::infinity();
  for (size_t i : older.near(e.centroid, e.majority_class)) {
    const float d =
        (map.descriptors.row(static_cast<Eigen::Index>(i)).transpose() - descriptor).squaredNorm();
    if (d < best_d) best = i, best_d = d;
  }
  return best;
}

// The session's map moved entry by entry: each by the correction of the frame that placed it.
TargetMap movedSession(const MappingRun& run, const std::vector<Pose>& T_map_base) {
  TargetMap moved = run.map;
  const auto correction = [&](size_t k) { return T_map_base[k] * run.trajectory[k].inverse(); };
  for (MapSegment& s : moved.segments) {
    const Pose T = correction(s.keyframe);
    s.centroid = (T * s.centroid.cast<double>()).cast<float>();
    for (Eigen::Vector3f& p : s.points) p = (T * p.cast<double>()).cast<float>();
  }
  // A scan context was made at a frame's position: it follows the nearest frame.
  ScanContextDatabase contexts(run.map.scan_contexts.config());
  for (const ScanContextDatabase::MappedScan& scan : run.map.scan_contexts.scans()) {
    size_t nearest = 0;
    double best = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < run.trajectory.size(); ++k) {
      const double d = (run.trajectory[k].translation() - scan.T_world_scan.translation()).norm();
      if (d < best) best = d, nearest = k;
    }
    contexts.add(scan.context, correction(nearest) * scan.T_world_scan);
  }
  moved.scan_contexts = std::move(contexts);
  return moved;
}

// The session alone, in its own frame: one session whose entries are each their own segment (as
// TargetMapBuilder numbers them).
TargetMap separateSession(const MappingRun& run, MapSession info) {
  TargetMap map = run.map;
  info.trajectory = run.trajectory;
  map.sessions = {std::move(info)};
  return map;
}

}  // namespace

SessionMerge::SessionMerge(const PipelineConfig& config, const DatasetInfo& info,
                           std::shared_ptr<const TargetMap> map,
                           std::shared_ptr<Describer> describer, PoseSource poses,
                           const FrontEndStages& stages)
    : config_(config),
      map_(std::move(map)),
      mapping_(config, info, poses, describer, stages),
      localizer_(
          (checkedMergeTarget(map_, requireDescriber(describer, "SessionMerge"), config), map_),
          config.localization.localizer) {}

void SessionMerge::process(const Frame& frame) {
  mapping_.process(frame);
  const size_t k = frames_++;
  const size_t every = std::max<size_t>(1, config_.localization.every_n_frames);
  if (k % every != 0) return;
  const LocalSegmentQuery q = mapping_.pipeline().localSegmentQuery();
  const auto found = localizer_.localize(q.centroids, q.descriptors);
  if (found)
    ties_.push_back({k, found->T_map_local * mapping_.trajectory().back(), found->inliers});
}

MergedSession SessionMerge::finish(const std::string& name, int64_t now_unix_s) {
  MergedSession out;
  out.mapping = mapping_.finish();
  out.ties = ties_;
  out.entries = out.mapping.map.size();
  MapSession info{name, now_unix_s, {}};
  if (ties_.size() < config_.session_merge.min_localizations) {  // at least 1 (setting table)
    out.map = separateSession(out.mapping, std::move(info));
    return out;
  }
  out.aligned = true;
  const std::vector<Pose> poses =
      alignTrajectory(out.mapping.trajectory, ties_, config_.loop_closure.graph);
  for (const SessionTie& t : ties_)
    out.mean_tie_residual_m += translationError(poses[t.frame], t.T_map_base) / ties_.size();
  info.trajectory = poses;
  out.map = *map_;
  out.same_segments = joinSession(out.map, movedSession(out.mapping, poses), std::move(info),
                                  config_.session_merge.same_segment_m);
  return out;
}

std::vector<Pose> alignTrajectory(const std::vector<Pose>& T_odom_base,
                                  const std::vector<SessionTie>& ties,
                                  const PoseGraphConfig& graph_config) {
  if (ties.empty()) throw std::invalid_argument("alignTrajectory: no localization to align by");
  const auto best = std::max_element(
      ties.begin(), ties.end(), [](const auto& a, const auto& b) { return a.inliers < b.inliers; });
  const Pose T_map_odom = best->T_map_base * T_odom_base.at(best->frame).inverse();
  PoseGraph graph(graph_config);
  graph.addNode(Pose::Identity());  // the map's frame, held fixed
  for (size_t k = 0; k < T_odom_base.size(); ++k) {
    graph.addNode(T_map_odom * T_odom_base[k]);
    if (k > 0) graph.addOdometry(k, k + 1, T_odom_base[k - 1].inverse() * T_odom_base[k]);
  }
  // A localization ties its frame to the map's frame; the robust loss of loop edges lets a wrong
  // one be outvoted by the drive's others.
  for (const SessionTie& t : ties) graph.addLoop(0, t.frame + 1, t.T_map_base);
  graph.optimize();
  std::vector<Pose> poses;
  for (size_t k = 0; k < T_odom_base.size(); ++k) poses.push_back(graph.pose(k + 1));
  return poses;
}

size_t joinSession(TargetMap& map, const TargetMap& session, MapSession info,
                   double same_segment_m) {
  if (session.dimension() != map.dimension())
    throw std::invalid_argument("joinSession: descriptors of dimension " +
                                std::to_string(session.dimension()) + ", the map's are " +
                                std::to_string(map.dimension()));
  if (map.sessions.empty()) {  // the map of one run becomes its first session, the map's frame
    map.sessions.push_back({map.source.empty() ? "session 0" : map.source, 0, {}});
    for (MapSegment& s : map.segments) s.session = 0, s.keyframe = 0;
  }
  if (map.sessions.size() >= 65535) throw std::invalid_argument("a map holds 65535 sessions");
  const auto index = static_cast<uint16_t>(map.sessions.size());
  uint32_t next_id = 0;
  for (const MapSegment& s : map.segments) next_id = std::max(next_id, s.segment + 1);
  const EntryGrid older(map, same_segment_m > 0 ? same_segment_m : 1.0);
  std::vector<MapSegment> added;
  size_t same = 0;
  for (size_t i = 0; i < session.segments.size(); ++i) {
    MapSegment m = session.segments[i];
    m.session = index;
    const auto seen =
        same_segment_m > 0
            ? sameSegment(map, older, m,
                          session.descriptors.row(static_cast<Eigen::Index>(i)).transpose())
            : std::optional<size_t>();
    m.segment = seen ? map.segments[*seen].segment : next_id++;
    same += seen.has_value();
    added.push_back(std::move(m));
  }
  const Eigen::Index rows = map.descriptors.rows();
  map.descriptors.conservativeResize(rows + session.descriptors.rows(), map.dimension());
  map.descriptors.bottomRows(session.descriptors.rows()) = session.descriptors;
  map.segments.insert(map.segments.end(), added.begin(), added.end());
  for (const ScanContextDatabase::MappedScan& scan : session.scan_contexts.scans())
    map.scan_contexts.add(scan.context, scan.T_world_scan);
  map.sessions.push_back(std::move(info));
  return same;
}

MergedSession runSessionMerge(FrameSource& source, const PipelineConfig& config,
                              std::shared_ptr<const TargetMap> map,
                              std::shared_ptr<Describer> describer, const std::string& name,
                              int64_t now_unix_s, PoseSource poses, const RunOptions& options) {
  SessionMerge merge(config, source.info(), std::move(map), std::move(describer), poses,
                     options.stages);
  const bool whole =
      feedFrames(source, options, [&merge](const Frame& frame) { merge.process(frame); });
  MergedSession out = merge.finish(name, now_unix_s);
  out.mapping.stats.interrupted = !whole;
  return out;
}

}  // namespace semsegmap
