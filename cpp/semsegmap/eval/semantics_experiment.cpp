#include "semsegmap/eval/semantics_experiment.h"

#include <algorithm>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "semsegmap/enrich/enricher.h"
#include "semsegmap/local_map/local_map.h"
#include "semsegmap/pipeline/pipeline.h"

namespace semsegmap {

void SemanticScores::add(ClassId truth, bool has_class, ClassId predicted) {
  if (truth == cls::kUnknown) return;  // no ground truth for this point
  ++points;
  if (!has_class) return;
  ++classified;
  correct += predicted == truth;
  confusion.add(truth, predicted);
}

SemanticScores& SemanticScores::operator+=(const SemanticScores& o) {
  points += o.points;
  classified += o.classified;
  correct += o.correct;
  confusion += o.confusion;
  return *this;
}

namespace {

double ratio(size_t a, size_t b) {
  return b == 0 ? 0.0 : static_cast<double>(a) / b;
}

}  // namespace

double SemanticScores::accuracy() const {
  return ratio(correct, classified);
}
double SemanticScores::classifiedShare() const {
  return ratio(classified, points);
}
double SemanticScores::correctShare() const {
  return ratio(correct, points);
}

double SemanticScores::iou(ClassId id) const {
  return confusion.iou(id);
}

namespace {

void checkSource(const FrameSource& source) {
  const DatasetInfo& info = source.info();
  const std::string where = "eval semantics: dataset " + info.name;
  if (info.rig.cameras.empty())
    throw std::runtime_error(where + " has no camera: there are no camera classes to measure");
  if (!info.has_point_labels || !info.point_labels_have_classes)
    throw std::runtime_error(where + " has no per-point ground-truth classes to measure against");
  if (!info.has_ground_truth_poses && !info.has_odometry)
    throw std::runtime_error(where +
                             " has no poses (ground truth or odometry) for the voxel votes");
}

// The frame's ground truth, taken off it: what is left gives classes from the cameras only (the
// enricher would otherwise fall back to the point labels, and measure the truth against itself).
std::vector<PointLabel> takeTruth(Frame& frame, const std::string& dataset) {
  const std::string where = "eval semantics: " + dataset + " frame " + std::to_string(frame.index);
  if (frame.point_labels.size() != frame.points.size())
    throw std::runtime_error(where + " has " + std::to_string(frame.point_labels.size()) +
                             " ground-truth labels for " + std::to_string(frame.points.size()) +
                             " points");
  // A network on a budget may leave a scan without labels yet (Frame::camera_semantics): its
  // points count as not classified.
  bool labelled = frame.camera_semantics;
  for (const CameraFrame& c : frame.cameras) labelled |= !c.label.empty();
  if (!labelled)
    throw std::runtime_error(where +
                             " has no label image in any camera (give --labels DIR, or a "
                             "--config whose semantics: section names a network)");
  std::vector<PointLabel> truth = std::move(frame.point_labels);
  frame.point_labels.clear();
  return truth;
}

// The vote map: the config's voxels, every classified point kept (ground and dynamic classes
// are what the camera is measured on too, so they vote like the others).
LocalMapConfig voteMapConfig(const LocalMapConfig& c) {
  LocalMapConfig v = c;
  v.remove_dynamic_classes = false;
  v.remove_ground_classes = false;
  v.remove_unknown_class = false;
  v.remove_unobserved = false;
  v.geometric_ground_removal = false;
  v.min_points_per_voxel = 1;
  return v;
}

// Per frame: the enriched points against the truth; then after fusing the classified points
// into the vote map, every point's voxel majority against the truth.
SemanticsFrame scoreFrame(const Frame& frame, const std::vector<PointLabel>& truth,
                          const EnrichedCloud& cloud, const Pose& T_map_lidar, LocalMap& votes) {
  SemanticsFrame out;
  out.frame = frame.index;
  EnrichedCloud classified;
  for (size_t i = 0; i < cloud.size(); ++i) {
    out.per_frame.add(truth[i].class_id, cloud[i].has_class, cloud[i].class_id);
    if (cloud[i].has_class) classified.push_back(cloud[i]);
  }
  const Eigen::Vector2d robot_xy = T_map_lidar.translation().head<2>();
  votes.update(classified, T_map_lidar, robot_xy);
  const Eigen::Matrix3f R = T_map_lidar.linear().cast<float>();
  const Eigen::Vector3f t = T_map_lidar.translation().cast<float>();
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Eigen::Vector3f p = R * Eigen::Vector3f(cloud[i].x, cloud[i].y, cloud[i].z) + t;
    const Voxel* v = votes.find(packVoxelKey(votes.voxelIndex(p)));
    const bool has_votes = v != nullptr && v->hasClass();
    out.after_votes.add(truth[i].class_id, has_votes, has_votes ? v->semanticClass() : 0);
  }
  return out;
}

void countSegments(const std::vector<Segment>& segments, SemanticsEvaluation& e) {
  for (const Segment& s : segments) {
    ++e.segments;
    const EnrichedCloud& points = s.last().points;
    e.segments_with_class += std::any_of(points.begin(), points.end(),
                                         [](const EnrichedPoint& p) { return p.has_class; });
  }
}

}  // namespace

SemanticsEvaluation evaluateSemantics(FrameSource& source, const SemanticsEvalConfig& config,
                                      const SemanticsProgress& progress) {
  checkSource(source);
  const DatasetInfo& info = source.info();
  SemanticsEvaluation e;
  e.dataset = info.name;
  e.classes = info.classes;
  const PoseSource poses =
      info.has_ground_truth_poses ? PoseSource::kGroundTruth : PoseSource::kOdometry;
  Pipeline pipeline(config.pipeline, info, poses);
  LocalMap votes(voteMapConfig(config.pipeline.local_map), info.classes);
  const size_t n =
      config.max_frames == 0 ? source.size() : std::min(config.max_frames, source.size());
  for (size_t k = 0; k < n; ++k) {
    if (config.stop.stopRequested()) {
      e.interrupted = true;
      break;
    }
    Frame frame = source.frame(k);
    const std::vector<PointLabel> truth = takeTruth(frame, info.name);
    const FrameResult result = pipeline.process(frame);
    countSegments(result.segmentation.finished, e);
    const EnrichedCloud cloud = enrichFrame(frame, info.rig, config.pipeline.enrichment);
    const Pose T_map_lidar = result.T_local_base * info.rig.T_base_lidar;
    e.frames.push_back(scoreFrame(frame, truth, cloud, T_map_lidar, votes));
    e.per_frame += e.frames.back().per_frame;
    e.after_votes += e.frames.back().after_votes;
    if (progress) progress(k + 1, n);
  }
  countSegments(pipeline.finish(), e);
  return e;
}

namespace {

nlohmann::ordered_json toJson(const SemanticScores& s, const ClassTable& classes) {
  nlohmann::ordered_json j = {{"points", s.points},
                              {"classified", s.classified},
                              {"correct", s.correct},
                              {"accuracy", s.accuracy()},
                              {"classified_share", s.classifiedShare()},
                              {"correct_share", s.correctShare()}};
  nlohmann::ordered_json iou = nlohmann::ordered_json::object();
  for (const SemanticClass& c : classes.classes())
    if (c.id != cls::kUnknown && s.iou(c.id) >= 0) iou[c.name] = s.iou(c.id);
  j["iou"] = iou;
  return j;
}

}  // namespace

nlohmann::ordered_json toJson(const SemanticsEvaluation& e) {
  nlohmann::ordered_json j;
  j["dataset"] = e.dataset;
  j["frames"] = e.frames.size();
  j["interrupted"] = e.interrupted;  // `frames` are those done before Ctrl-C
  j["per_frame"] = toJson(e.per_frame, e.classes);
  j["after_votes"] = toJson(e.after_votes, e.classes);
  j["segments"] = {{"count", e.segments},
                   {"with_class", e.segments_with_class},
                   {"with_class_share", ratio(e.segments_with_class, e.segments)}};
  j["per_frame_results"] = nlohmann::ordered_json::array();
  for (const SemanticsFrame& f : e.frames)
    j["per_frame_results"].push_back({{"frame", f.frame},
                                      {"per_frame", toJson(f.per_frame, e.classes)},
                                      {"after_votes", toJson(f.after_votes, e.classes)}});
  return j;
}

std::string semanticsTable(const SemanticsEvaluation& e) {
  std::ostringstream s;
  char line[160];
  s << "camera classes on " << e.dataset << ", " << e.frames.size() << " frames, "
    << e.per_frame.points << " points with ground truth\n";
  s << "                 accuracy  classified  correct of all\n";
  for (const auto& [name, sc] :
       {std::pair<const char*, const SemanticScores*>{"per frame", &e.per_frame},
        {"after votes", &e.after_votes}}) {
    std::snprintf(line, sizeof(line), "  %-13s %8.1f %%  %8.1f %%  %11.1f %%\n", name,
                  100 * sc->accuracy(), 100 * sc->classifiedShare(), 100 * sc->correctShare());
    s << line;
  }
  std::snprintf(line, sizeof(line), "  map segments with a class: %zu of %zu\n",
                e.segments_with_class, e.segments);
  s << line << "  IoU per class (per frame / after votes):";
  for (const SemanticClass& c : e.classes.classes()) {
    const double a = e.per_frame.iou(c.id), b = e.after_votes.iou(c.id);
    // The truth is never unknown, so a network's unknown is only ever wrong: no IoU of its own.
    if (c.id == cls::kUnknown || (a < 0 && b < 0)) continue;
    std::snprintf(line, sizeof(line), " %s %.2f/%.2f", c.name.c_str(), std::max(a, 0.0),
                  std::max(b, 0.0));
    s << line;
  }
  s << "\n";
  return s.str();
}

}  // namespace semsegmap
