#include "semsegmap/pipeline/slam.h"

#include <algorithm>
#include <chrono>

#include "semsegmap/graph/pose_graph.h"
#include "semsegmap/pipeline/map_parameters.h"

namespace semsegmap {

namespace {

// Mapping with loop closure, frame by frame. Every finished segment is anchored at the node
// (frame) that finished it: its centroid is kept in that node's odometry frame, so that moving
// the node moves the segment. The localizer's map grows by the segments of each frame, placed
// with the current node estimates; only an optimization moves the segments already in it.
class SlamSession {
 public:
  SlamSession(const PipelineConfig& config, const DatasetInfo& given,
              std::shared_ptr<Describer> describer, const FrontEndStages& stages)
      : config_(config),
        graph_(config.loop_closure.graph),
        pipeline_(config, given, PoseSource::kOdometry, describer, stages),
        localizer_(emptyMap(requireDescriber(describer, "SlamSession")),
                   config.localization.localizer) {
    const DatasetInfo info = infoWithStages(given, stages);
    run_.odometry_is_ground_truth = info.odometry_is_ground_truth;
    run_.has_frame_times = info.has_frame_times;
  }

  void process(const Frame& frame) {
    FrameResult r = pipeline_.process(frame);
    addNode(frame, r.T_local_base);
    anchor(nodes() - 1, r.segmentation.finished, r.finished_descriptors);
    const auto t0 = std::chrono::steady_clock::now();
    closeLoop(frame.index);
    const double graph_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.times.localize_ms += graph_ms;
    run_.graph_ms += graph_ms;
    run_.stats.total += r.times;
    ++run_.stats.frames;
  }

  SlamRun finish() {
    std::vector<Eigen::VectorXf> last;
    const std::vector<Segment> remaining = pipeline_.finish(&last);
    // No node when a stop request came before the first frame: nothing to anchor to.
    if (nodes() > 0) anchor(nodes() - 1, remaining, last);
    for (size_t i = 0; i < graph_.size(); ++i) {
      run_.trajectory.push_back({stamps_[i], graph_.pose(i)});
      run_.trajectory_odom.push_back({stamps_[i], odom_[i]});
    }
    // The saved map: corrected centroids, duplicates of revisited places removed.
    const TargetMap& all = localizer_.map();
    TargetMapBuilder builder(all.descriptor, all.fingerprint, all.dimension(), config_.target_map);
    builder.setParameters(mapParametersOf(config_));
    for (size_t s = 0; s < all.size(); ++s)
      builder.add(all.segments[s], all.descriptors.row(static_cast<Eigen::Index>(s)).transpose());
    run_.map = builder.build();
    return std::move(run_);
  }

 private:
  static TargetMap emptyMap(const Describer& describer) {
    TargetMap map;
    map.descriptor = descriptorName(describer.kind());
    map.fingerprint = describer.fingerprint();
    map.descriptors.resize(0, describer.dimension());
    return map;
  }
  size_t nodes() const { return odom_.size(); }
  // Segment centroids kept in a node's odometry frame, to the map frame.
  Pose T_map_odom(size_t node) const { return graph_.pose(node) * odom_[node].inverse(); }

  void addNode(const Frame& frame, const Pose& T_odom_base) {
    if (odom_.empty()) {
      graph_.addNode(T_odom_base);
      travelled_.push_back(0.0);
    } else {
      const size_t i = nodes();
      const Pose step = odom_.back().inverse() * T_odom_base;
      graph_.addNode(graph_.pose(i - 1) * step);
      graph_.addOdometry(i - 1, i, step);
      travelled_.push_back(travelled_.back() + step.translation().norm());
    }
    odom_.push_back(T_odom_base);
    stamps_.push_back(frame.timestamp_s);
    run_.frames.push_back(stampOf(frame, run_.has_frame_times));
    frame_indices_.push_back(frame.index);
    if (frame.T_world_base) run_.trajectory_gt.push_back(*frame.T_world_base);
  }

  void anchor(size_t node, const std::vector<Segment>& segments,
              const std::vector<Eigen::VectorXf>& descriptors) {
    if (segments.empty()) return;
    std::vector<MapSegment> added;
    Eigen::MatrixXf rows(static_cast<Eigen::Index>(segments.size()), descriptors[0].size());
    const Pose T = T_map_odom(node);
    for (size_t k = 0; k < segments.size(); ++k) {
      const SegmentObservation& o = segments[k].last();
      MapSegment m;
      m.centroid = (T * o.centroid).cast<float>();
      m.n_points = static_cast<uint32_t>(o.n_points);
      m.majority_class = o.majority_class;
      added.push_back(m);
      anchors_.push_back({node, o.centroid});
      rows.row(static_cast<Eigen::Index>(k)) = descriptors[k].transpose();
    }
    localizer_.append(added, rows);
  }

  // The current local segments against the part of the map left far enough behind, at most
  // once every min_travel_between_loops_m.
  void closeLoop(size_t frame_index) {
    const LoopClosureConfig& lc = config_.loop_closure;
    const size_t i = nodes() - 1;
    std::vector<bool> usable(anchors_.size());
    size_t n_usable = 0;
    for (size_t s = 0; s < anchors_.size(); ++s) {
      usable[s] = travelled_[i] - travelled_[anchors_[s].node] > lc.exclude_recent_m;
      n_usable += usable[s];
    }
    const auto min_inliers = config_.localization.localizer.verification.min_inliers;
    if (n_usable < static_cast<size_t>(min_inliers) ||
        travelled_[i] - last_loop_at_ < lc.min_travel_between_loops_m)
      return;
    const LocalSegmentQuery q = pipeline_.localSegmentQuery();
    const auto found = localizer_.localize(q.centroids, q.descriptors, &usable);
    if (found) addLoop(frame_index, i, *found);
  }

  void addLoop(size_t frame_index, size_t i, const Localization& found) {
    std::vector<size_t> old_nodes;
    for (const auto& m : found.matches) old_nodes.push_back(anchors_[m.second].node);
    std::nth_element(old_nodes.begin(), old_nodes.begin() + old_nodes.size() / 2, old_nodes.end());
    const size_t j = old_nodes[old_nodes.size() / 2];
    const Pose corrected = found.T_map_local * odom_[i];
    LoopClosure loop;
    loop.frame_index = frame_index;
    loop.old_frame_index = frame_indices_[j];
    loop.node = i;
    loop.old_node = j;
    loop.inliers = found.inliers;
    loop.correction_m = translationError(corrected, graph_.pose(i));
    graph_.addLoop(j, i, graph_.pose(j).inverse() * corrected);
    graph_.optimize();
    // The nodes moved: so do the segments anchored at them (the descriptors do not change).
    for (size_t s = 0; s < anchors_.size(); ++s)
      localizer_.setCentroid(
          s, (T_map_odom(anchors_[s].node) * anchors_[s].centroid_odom).cast<float>());
    run_.loops.push_back(loop);
    last_loop_at_ = travelled_[i];
  }

  struct Anchor {
    size_t node = 0;
    Eigen::Vector3d centroid_odom = Eigen::Vector3d::Zero();
  };

  PipelineConfig config_;
  PoseGraph graph_;
  Pipeline pipeline_;
  Localizer localizer_;
  std::vector<Anchor> anchors_;             // one per segment of the localizer's map
  std::vector<Pose> odom_;                  // T_odom_base at each node
  std::vector<double> travelled_, stamps_;  // odometry distance and time at each node
  std::vector<size_t> frame_indices_;
  double last_loop_at_ = -1e9;
  SlamRun run_;
};

}  // namespace

SlamRun runSlam(FrameSource& source, const PipelineConfig& config,
                std::shared_ptr<Describer> describer, const RunOptions& options) {
  SlamSession session(config, source.info(), std::move(describer), options.stages);
  const bool whole =
      feedFrames(source, options, [&session](const Frame& frame) { session.process(frame); });
  SlamRun run = session.finish();
  run.stats.interrupted = !whole;
  return run;
}

}  // namespace semsegmap
