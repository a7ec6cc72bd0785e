#include "semsegmap/pipeline/slam.h"

#include <algorithm>
#include <chrono>

#include "semsegmap/graph/pose_graph.h"

namespace semsegmap {

namespace {

// A finished segment of the SLAM map, anchored at the node (frame) that finished it: its
// centroid is kept in that node's odometry frame, so that moving the node moves the segment.
struct AnchoredSegment {
  size_t node = 0;
  Eigen::Vector3d centroid_odom = Eigen::Vector3d::Zero();
  MapSegment segment;
};

class SlamMap {
 public:
  void add(size_t node, const Segment& s, const Eigen::VectorXf& d) {
    AnchoredSegment a;
    a.node = node;
    a.centroid_odom = s.last().centroid;
    a.segment.n_points = static_cast<uint32_t>(s.last().n_points);
    a.segment.majority_class = s.last().majority_class;
    segments_.push_back(a);
    descriptors_.push_back(d);
  }
  // Centroids in the map frame from the current node estimates.
  TargetMap targetMap(const PoseGraph& graph, const std::vector<Pose>& odom,
                      const std::string& kind, const std::string& fingerprint) const {
    TargetMap map;
    map.descriptor = kind;
    map.fingerprint = fingerprint;
    const Eigen::Index dim = descriptors_.empty() ? 0 : descriptors_[0].size();
    map.descriptors.resize(static_cast<Eigen::Index>(segments_.size()), dim);
    for (size_t i = 0; i < segments_.size(); ++i) {
      MapSegment m = segments_[i].segment;
      const Pose T_map_odom = graph.pose(segments_[i].node) * odom[segments_[i].node].inverse();
      m.centroid = (T_map_odom * segments_[i].centroid_odom).cast<float>();
      map.segments.push_back(m);
      map.descriptors.row(static_cast<Eigen::Index>(i)) = descriptors_[i].transpose();
    }
    return map;
  }
  size_t size() const { return segments_.size(); }
  size_t node(size_t i) const { return segments_[i].node; }

 private:
  std::vector<AnchoredSegment> segments_;
  std::vector<Eigen::VectorXf> descriptors_;
};

}  // namespace

SlamRun runSlam(FrameSource& source, const PipelineConfig& config, Describer& describer,
                const RunOptions& options) {
  const LoopClosureConfig& lc = config.loop_closure;
  PoseGraphConfig graph_config;
  graph_config.odometry_translation_sigma_m = lc.odometry_translation_sigma_m;
  graph_config.odometry_rotation_sigma_rad = lc.odometry_rotation_sigma_rad;
  graph_config.loop_translation_sigma_m = lc.loop_translation_sigma_m;
  graph_config.loop_rotation_sigma_rad = lc.loop_rotation_sigma_rad;
  PoseGraph graph(graph_config);
  Pipeline pipeline(config, source.info(), PoseSource::kOdometry, &describer);
  SlamMap map;
  const std::string kind = descriptorName(describer.kind());

  SlamRun run;
  std::vector<Pose> odom;
  std::vector<double> travelled;  // odometry distance at each node
  std::vector<double> stamps;
  std::vector<size_t> frame_indices;
  double last_loop_at = -1e9;
  const size_t n =
      options.max_frames > 0 ? std::min(source.size(), options.max_frames) : source.size();
  for (size_t i = 0; i < n; ++i) {
    const Frame frame = source.frame(i);
    FrameResult r = pipeline.process(frame);
    const Pose& T_odom = r.T_map_base;
    if (odom.empty()) {
      graph.addNode(T_odom);
      travelled.push_back(0.0);
    } else {
      const Pose step = odom.back().inverse() * T_odom;
      graph.addNode(graph.pose(i - 1) * step);
      graph.addOdometry(i - 1, i, step);
      travelled.push_back(travelled.back() + step.translation().norm());
    }
    odom.push_back(T_odom);
    stamps.push_back(frame.timestamp_s);
    frame_indices.push_back(frame.index);
    if (frame.T_world_base_gt) run.trajectory_gt.push_back(*frame.T_world_base_gt);
    for (size_t k = 0; k < r.segmentation.finished.size(); ++k)
      map.add(i, r.segmentation.finished[k], r.finished_descriptors[k]);

    // Loop closure: the current local segments against the part of the map left far enough
    // behind, at most once every min_travel_between_loops_m.
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<bool> usable(map.size());
    size_t n_usable = 0;
    for (size_t s = 0; s < map.size(); ++s) {
      usable[s] = travelled[i] - travelled[map.node(s)] > lc.exclude_recent_m;
      n_usable += usable[s];
    }
    if (n_usable >= static_cast<size_t>(config.localization.localizer.verification.min_inliers) &&
        travelled[i] - last_loop_at >= lc.min_travel_between_loops_m) {
      const TargetMap target = map.targetMap(graph, odom, kind, describer.fingerprint());
      const Localizer localizer(target, config.localization.localizer);
      const LocalSegmentQuery q = pipeline.localSegmentQuery();
      const auto found = localizer.localize(q.centroids, q.descriptors, &usable);
      if (found) {
        std::vector<size_t> old_nodes;
        for (const auto& m : found->matches) old_nodes.push_back(map.node(m.second));
        std::nth_element(old_nodes.begin(), old_nodes.begin() + old_nodes.size() / 2,
                         old_nodes.end());
        const size_t j = old_nodes[old_nodes.size() / 2];
        const Pose corrected = found->T_map_local * T_odom;
        LoopClosure loop;
        loop.frame_index = frame.index;
        loop.old_frame_index = frame_indices[j];
        loop.node = i;
        loop.old_node = j;
        loop.inliers = found->inliers;
        loop.correction_m = translationError(corrected, graph.pose(i));
        graph.addLoop(j, i, graph.pose(j).inverse() * corrected);
        graph.optimize();
        run.loops.push_back(loop);
        last_loop_at = travelled[i];
      }
    }
    const double graph_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.times.localize_ms += graph_ms;
    run.graph_ms += graph_ms;
    run.stats.total += r.times;
    ++run.stats.frames;
    if (options.progress) options.progress(i + 1, n);
  }
  std::vector<Eigen::VectorXf> last;
  const std::vector<Segment> remaining = pipeline.finish(&last);
  for (size_t k = 0; k < remaining.size(); ++k) map.add(n - 1, remaining[k], last[k]);

  for (size_t i = 0; i < graph.size(); ++i) {
    run.trajectory.push_back({stamps[i], graph.pose(i)});
    run.trajectory_odom.push_back({stamps[i], odom[i]});
  }
  // The saved map: corrected centroids, duplicates of revisited places removed.
  const TargetMap all = map.targetMap(graph, odom, kind, describer.fingerprint());
  TargetMapBuilder builder(kind, describer.fingerprint(), describer.dimension(), config.target_map);
  for (size_t s = 0; s < all.size(); ++s)
    builder.add(all.segments[s], all.descriptors.row(static_cast<Eigen::Index>(s)).transpose());
  run.map = builder.build();
  return run;
}

}  // namespace semsegmap
