#include "semsegmap/pipeline/pipeline.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "semsegmap/core/diagnostics.h"

namespace semsegmap {

namespace {
double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

StageTimes& StageTimes::operator+=(const StageTimes& o) {
  enrich_ms += o.enrich_ms;
  local_map_ms += o.local_map_ms;
  segment_ms += o.segment_ms;
  describe_ms += o.describe_ms;
  localize_ms += o.localize_ms;
  return *this;
}

PoseSource parsePoseSource(const std::string& name) {
  if (name == "gt") return PoseSource::kGroundTruth;
  if (name == "odom") return PoseSource::kOdometry;
  throw std::invalid_argument("unknown pose source '" + name + "' (expected gt or odom)");
}

Pipeline::Pipeline(const PipelineConfig& config, const DatasetInfo& info, PoseSource poses,
                   std::shared_ptr<Describer> describer, const FrontEndStages& stages)
    : config_(config),
      info_(infoWithStages(info, stages)),
      poses_(poses),
      preparation_(stages, info),
      local_map_(config.local_map, info.classes),
      segmenter_(config.segmentation),
      describer_(std::move(describer)) {
  // Refused up front: without odometry every T_odom_base is the identity, and a run on them
  // would stack all scans in one place and still exit 0.
  if (poses == PoseSource::kOdometry && !info_.has_odometry)
    throw std::runtime_error(
        "dataset " + info.name + " has no odometry: give " + optionText("odometry", "FILE") +
        " (TUM or KITTI poses) or " + optionText("odometry", "lidar", true) +
        (info.has_ground_truth_poses ? ", or " + optionText("poses", "gt", true) : ""));
}

void Pipeline::describe(const std::vector<SegmentId>& ids, size_t frame_index) {
  const size_t batch = static_cast<size_t>(std::max(1, config_.descriptor.batch));
  for (size_t start = 0; start < ids.size(); start += batch) {
    const size_t end = std::min(ids.size(), start + batch);
    std::vector<DescriptorInput> inputs;
    std::vector<const Segment*> segments;
    for (size_t i = start; i < end; ++i) {
      const Segment* s = segmenter_.segment(ids[i]);
      if (!s || s->observations.empty() || s->last().points.empty()) continue;
      segments.push_back(s);
      inputs.push_back({&s->last().points});
    }
    if (inputs.empty()) continue;
    const Eigen::MatrixXf d = describer_->describe(inputs);
    for (size_t i = 0; i < segments.size(); ++i) {
      const SegmentObservation& o = segments[i]->last();
      DescribedSegment& e = described_[segments[i]->id];
      e.id = segments[i]->id;
      e.centroid = o.centroid.cast<float>();
      e.n_points = static_cast<uint32_t>(o.n_points);
      e.majority_class = o.majority_class;
      e.frame_index = frame_index;
      e.descriptor = d.row(static_cast<Eigen::Index>(i)).transpose();
    }
  }
}

std::vector<Eigen::Vector3f> Pipeline::observedPoints(SegmentId id) const {
  // The described observation is the segment's last one (a segment is described each time it is
  // observed); a segment without it (cannot happen) contributes no points rather than others.
  const DescribedSegment& e = described_.at(id);
  const Segment* s = segmenter_.segment(id);
  if (!s || s->observations.empty() || s->last().n_points != e.n_points) return {};
  std::vector<Eigen::Vector3f> points;
  points.reserve(s->last().points.size());
  for (const EnrichedPoint& p : s->last().points) points.emplace_back(p.x, p.y, p.z);
  return points;
}

LocalSegmentQuery Pipeline::localSegmentQuery() const {
  LocalSegmentQuery q;
  for (const auto& [id, e] : described_) q.ids.push_back(id);
  std::sort(q.ids.begin(), q.ids.end());
  q.descriptors.resize(static_cast<Eigen::Index>(q.ids.size()),
                       q.ids.empty() ? 0 : described_.at(q.ids[0]).descriptor.size());
  for (size_t i = 0; i < q.ids.size(); ++i) {
    const DescribedSegment& e = described_.at(q.ids[i]);
    q.centroids.push_back(e.centroid);
    q.descriptors.row(static_cast<Eigen::Index>(i)) = e.descriptor.transpose();
  }
  return q;
}

Eigen::VectorXf Pipeline::finalDescriptor(const Segment& s) const {
  auto it = described_.find(s.id);
  if (it != described_.end() && it->second.n_points == s.last().n_points)
    return it->second.descriptor;
  // Not described in its final state (cannot happen with the segmenter's current rules, but a
  // finished segment must never leave without its descriptor).
  const DescriptorInput in{&s.last().points};
  return describer_->describe({in}).row(0).transpose();
}

// Frames enough to judge a run's coverage: a robot starting in front of a wall is not a rig.
constexpr size_t kCoverageFrames = 10;
// Below this share of points with a class, the semantic distance and the class histograms have
// next to nothing to work with.
constexpr double kLowCoverage = 0.1;

void Pipeline::checkCameraCoverage(const LocalMapUpdate& update, size_t points, bool at_end) {
  if (coverage_.checked) return;
  if (!at_end) {
    ++coverage_.frames;
    coverage_.points += points;
    coverage_.unobserved += update.points_unobserved;
    if (coverage_.frames < kCoverageFrames) return;
  }
  coverage_.checked = true;
  const size_t classified = coverage_.points - coverage_.unobserved;
  // No class anywhere is LiDAR-only data, geometry by design (the descriptor choice says so).
  if (coverage_.points == 0 || classified == 0) return;
  const double share = static_cast<double>(classified) / static_cast<double>(coverage_.points);
  const std::string seen = "cameras gave a class to " + std::to_string(std::lround(100 * share)) +
                           " % of the points of the first " + std::to_string(coverage_.frames) +
                           " frames";
  if (config_.local_map.remove_unobserved && share < 0.9)
    warn(seen +
         ", and local_map.remove_unobserved drops the rest: set it to false for a rig "
         "whose cameras do not cover the LiDAR (config/lidar-camera.yaml)");
  else if (share < kLowCoverage)
    warn(seen + ": the semantic part of the segmentation and the descriptor is nearly off");
}

FrameResult Pipeline::process(const Frame& given) {
  const Frame& frame = preparation_.prepare(given);
  FrameResult r;
  r.frame_index = frame.index;
  if (poses_ == PoseSource::kGroundTruth) {
    if (!frame.T_world_base)
      throw std::runtime_error("frame " + std::to_string(frame.index) +
                               " has no ground-truth pose (use " +
                               optionText("poses", "odom", true) + ")");
    r.T_local_base = *frame.T_world_base;
  } else {
    r.T_local_base = frame.T_odom_base;
  }

  auto t0 = std::chrono::steady_clock::now();
  const EnrichedCloud cloud = enrichFrame(frame, info_.rig, config_.enrichment);
  r.times.enrich_ms = msSince(t0);
  r.points = cloud.size();
  for (const auto& p : cloud) r.colored_points += p.has_color;

  t0 = std::chrono::steady_clock::now();
  r.map_update = local_map_.update(cloud, r.T_local_base * info_.rig.T_base_lidar,
                                   r.T_local_base.translation().head<2>());
  checkCameraCoverage(r.map_update, cloud.size(), false);
  r.times.local_map_ms = msSince(t0);

  t0 = std::chrono::steady_clock::now();
  r.segmentation = segmenter_.update(local_map_, r.map_update, frame.index, frame.timestamp_s);
  r.times.segment_ms = msSince(t0);
  if (!describer_) return r;

  // Only segments whose observation changed are described again: most of the local map is the
  // same from one frame to the next.
  t0 = std::chrono::steady_clock::now();
  // Absorbed and dropped segments leave the local segments at once: a stale entry would stay in
  // every localization query until the run ends (a long run's queries grew without bound).
  for (const SegmentMerge& m : r.segmentation.merges) described_.erase(m.absorbed);
  for (SegmentId id : r.segmentation.dropped) described_.erase(id);
  describe(r.segmentation.observed, frame.index);
  r.described = r.segmentation.observed.size();
  for (const Segment& s : r.segmentation.finished) {
    r.finished_descriptors.push_back(finalDescriptor(s));
    described_.erase(s.id);
  }
  r.times.describe_ms = msSince(t0);
  return r;
}

std::vector<Segment> Pipeline::finish(std::vector<Eigen::VectorXf>* descriptors) {
  checkCameraCoverage({}, 0, true);
  std::vector<Segment> segments = segmenter_.finishAll();
  if (descriptors) {
    descriptors->clear();
    if (!describer_) throw std::logic_error("Pipeline::finish: descriptors need a describer");
    for (const Segment& s : segments) descriptors->push_back(finalDescriptor(s));
  }
  described_.clear();
  return segments;
}

}  // namespace semsegmap
