#include "semsegmap/viz/scene_export.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace semsegmap::viz {

namespace {

using Json = nlohmann::ordered_json;

std::string base64(const void* data, size_t bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const uint8_t*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  for (size_t i = 0; i < bytes; i += 3) {
    const uint32_t b = (uint32_t{p[i]} << 16) | (i + 1 < bytes ? uint32_t{p[i + 1]} << 8 : 0u) |
                       (i + 2 < bytes ? uint32_t{p[i + 2]} : 0u);
    out += kAlphabet[(b >> 18) & 63];
    out += kAlphabet[(b >> 12) & 63];
    out += i + 1 < bytes ? kAlphabet[(b >> 6) & 63] : '=';
    out += i + 2 < bytes ? kAlphabet[b & 63] : '=';
  }
  return out;
}

// The page reads these as typed arrays of the same element type (x86 and every browser's
// machine are little-endian, as the map file is).
template <typename T>
std::string base64(const std::vector<T>& v) {
  return base64(v.data(), v.size() * sizeof(T));
}

// Millimetres: what the page shows, without the noise digits of a double.
double mm(double v) {
  return std::round(v * 1000.0) / 1000.0;
}

Json xyz(const Eigen::Vector3d& p, const Eigen::Vector3d& origin) {
  const Eigen::Vector3d q = p - origin;
  return Json::array({mm(q.x()), mm(q.y()), mm(q.z())});
}

void appendXyz(std::vector<float>& flat, const Eigen::Vector3d& p, const Eigen::Vector3d& o) {
  for (int k = 0; k < 3; ++k) flat.push_back(static_cast<float>(p[k] - o[k]));
}

Json optionalNumber(const std::optional<double>& v) {
  return v ? Json(mm(*v)) : Json(nullptr);
}

// The centre of the map's bounding box in whole metres (an empty map: zero).
Eigen::Vector3d sceneOrigin(const TargetMap& map) {
  if (map.segments.empty()) return Eigen::Vector3d::Zero();
  Eigen::Vector3f lo = map.segments[0].centroid, hi = lo;
  for (const MapSegment& s : map.segments) {
    lo = lo.cwiseMin(s.centroid);
    hi = hi.cwiseMax(s.centroid);
  }
  return ((lo + hi).cast<double>() / 2.0).array().round();
}

Json classesJson(const ClassTable& classes) {
  Json out = Json::array();
  for (const SemanticClass& c : classes.classes())
    out.push_back({{"id", c.id},
                   {"name", c.name},
                   {"color", {c.color_rgb[0], c.color_rgb[1], c.color_rgb[2]}}});
  return out;
}

// Points in groups (one per segment) as 16-bit offsets from their group's centroid: "counts"
// (uint32 per group), "scale" (metres per unit) and "offsets" (int16 x y z per point).
Json pointGroupsJson(const std::vector<Eigen::Vector3f>& centroids,
                     const std::vector<const std::vector<Eigen::Vector3f>*>& groups) {
  float largest = 0.0f;
  for (size_t g = 0; g < groups.size(); ++g)
    for (const Eigen::Vector3f& p : *groups[g])
      largest = std::max(largest, (p - centroids[g]).cwiseAbs().maxCoeff());
  // A millimetre at least; a wider segment (a long wall) gets coarser steps, never clipped ones.
  const double scale = std::max(0.001, static_cast<double>(largest) / 32767.0);
  std::vector<uint32_t> counts;
  std::vector<int16_t> offsets;
  for (size_t g = 0; g < groups.size(); ++g) {
    counts.push_back(static_cast<uint32_t>(groups[g]->size()));
    for (const Eigen::Vector3f& p : *groups[g])
      for (int k = 0; k < 3; ++k)
        offsets.push_back(static_cast<int16_t>(std::lround((p[k] - centroids[g][k]) / scale)));
  }
  return {{"counts", base64(counts)}, {"scale", scale}, {"offsets", base64(offsets)}};
}

Json mapJson(const SceneInputs& in, const Eigen::Vector3d& origin) {
  const TargetMap& map = *in.map;
  std::vector<float> centroids;
  std::vector<uint16_t> classes;
  std::vector<uint32_t> sizes;
  std::vector<Eigen::Vector3f> local_centroids;
  std::vector<const std::vector<Eigen::Vector3f>*> groups;
  size_t points = 0;
  for (const MapSegment& s : map.segments) {
    appendXyz(centroids, s.centroid.cast<double>(), origin);
    classes.push_back(s.majority_class);
    sizes.push_back(s.n_points);
    local_centroids.push_back(s.centroid);
    groups.push_back(&s.points);
    points += s.points.size();
  }
  Json j = {
      {"name", in.map_name},     {"descriptor", map.descriptor},   {"segments", map.size()},
      {"stored_points", points}, {"centroids", base64(centroids)}, {"classes", base64(classes)},
      {"sizes", base64(sizes)}};
  // Each segment's session (uint16), none for the map of one run: all its segments are session 0.
  std::vector<uint16_t> sessions;
  if (!map.sessions.empty())
    for (const MapSegment& s : map.segments) sessions.push_back(s.session);
  j["sessions"] = map.sessions.empty() ? Json(nullptr) : Json(base64(sessions));
  j["points"] = points > 0 ? pointGroupsJson(local_centroids, groups) : Json(nullptr);
  return j;
}

// The drives the map was merged from, in order: each one's name, its number of entries and its
// trajectory (float32 xyz; null when it has none, as the first, which defines the map's frame).
// The map of one run is one session, "this run".
Json sessionsJson(const TargetMap& map, const Eigen::Vector3d& origin) {
  Json out = Json::array();
  if (map.sessions.empty()) {
    out.push_back({{"name", "this run"}, {"entries", map.size()}, {"trajectory", nullptr}});
    return out;
  }
  std::vector<size_t> entries(map.sessions.size(), 0);
  for (size_t i = 0; i < map.segments.size(); ++i) {
    const size_t session = map.segments[i].session;
    if (session >= entries.size())
      throw std::runtime_error((map.source.empty() ? std::string("the map") : map.source) +
                               ": segment " + std::to_string(i) + " is of session " +
                               std::to_string(session) + ", but the map has " +
                               std::to_string(entries.size()) + " sessions");
    ++entries[session];
  }
  for (size_t k = 0; k < map.sessions.size(); ++k) {
    std::vector<float> trajectory;
    for (const Pose& T_map_base : map.sessions[k].trajectory)
      appendXyz(trajectory, T_map_base.translation(), origin);
    out.push_back({{"name", map.sessions[k].name},
                   {"entries", entries[k]},
                   {"trajectory", trajectory.empty() ? Json(nullptr) : Json(base64(trajectory))}});
  }
  return out;
}

// The robot's position in the map at every trajectory row from the first localization on: its
// odometry carried by the latest localization, T_map_base = T_map_odom * T_odom_base with
// T_map_odom = T_map_base(l) * T_odom_base(l)^-1 at that localization's frame.
std::vector<float> estimatedPositions(const LocalizationFolder& f, const Eigen::Vector3d& origin,
                                      size_t* first_row) {
  std::unordered_map<size_t, const LocalizationRow*> at_frame;
  for (const LocalizationRow& l : f.localizations) at_frame[l.frame] = &l;
  std::vector<float> flat;
  std::optional<Pose> T_map_odom;
  for (size_t i = 0; i < f.trajectory.size(); ++i) {
    const TrajectoryRow& row = f.trajectory[i];
    const auto l = at_frame.find(row.frame);
    if (l != at_frame.end()) T_map_odom = l->second->T_map_base * row.T_odom_base.inverse();
    if (!T_map_odom) continue;
    if (flat.empty()) *first_row = i;
    appendXyz(flat, (*T_map_odom * row.T_odom_base).translation(), origin);
  }
  return flat;
}

Json localizationRecordJson(const LocalizationRow& l, const std::vector<const MatchRow*>& matches,
                            const Eigen::Vector3d& origin) {
  const auto v = toXyzQuat(l.T_map_base);
  Json pairs = Json::array();
  for (const MatchRow* m : matches) {
    Json pair = xyz(m->local.cast<double>(), origin);
    for (const auto& t : xyz(m->target.cast<double>(), origin)) pair.push_back(t);
    pairs.push_back(std::move(pair));
  }
  // The dataset's own frame number and time beside the run's index; null where it has none.
  return {{"frame", l.frame},
          {"dataset_frame", l.dataset_frame ? Json(*l.dataset_frame) : Json(nullptr)},
          {"time", optionalNumber(l.timestamp_s)},
          {"position", xyz(l.T_map_base.translation(), origin)},
          {"quaternion", {v[3], v[4], v[5], v[6]}},
          {"inliers", l.inliers},
          {"error_m", optionalNumber(l.translation_error_m)},
          {"error_deg", optionalNumber(l.rotation_error_deg)},
          {"refinement_m", optionalNumber(l.refinement_m)},
          {"matches", std::move(pairs)}};
}

Json trajectoryJson(const LocalizationFolder& f, const Eigen::Vector3d& origin) {
  std::vector<size_t> frames;
  std::vector<float> gt;
  bool all_gt = !f.trajectory.empty();
  for (const TrajectoryRow& row : f.trajectory) {
    frames.push_back(row.frame);
    all_gt = all_gt && row.T_world_base.has_value();
    if (row.T_world_base) appendXyz(gt, row.T_world_base->translation(), origin);
  }
  size_t first_row = 0;
  const std::vector<float> estimate = estimatedPositions(f, origin, &first_row);
  Json j = {{"frames", frames},
            {"ground_truth", all_gt ? Json(base64(gt)) : Json(nullptr)},
            {"estimate", base64(estimate)},
            {"estimate_first_row", first_row}};
  return j;
}

std::string folderName(const std::filesystem::path& dir) {
  return dir.filename().empty() ? dir.parent_path().filename().string() : dir.filename().string();
}

Json localizationJson(const LocalizationFolder& f, const Eigen::Vector3d& origin) {
  std::unordered_map<size_t, std::vector<const MatchRow*>> matches;
  for (const MatchRow& m : f.matches) matches[m.frame].push_back(&m);
  Json records = Json::array();
  bool gt = false;
  for (const LocalizationRow& l : f.localizations) {
    records.push_back(localizationRecordJson(l, matches[l.frame], origin));
    gt = gt || l.translation_error_m.has_value();
  }
  return {{"name", folderName(f.dir)},
          {"dataset", f.dataset},
          {"has_ground_truth", gt},
          {"has_matches", f.has_matches},
          {"records", std::move(records)},
          {"trajectory", f.has_trajectory ? trajectoryJson(f, origin) : Json(nullptr)}};
}

Json slamJson(const SlamFolder& f, const Eigen::Vector3d& origin) {
  const auto positions = [&](const std::vector<StampedPose>& poses) {
    std::vector<float> flat;
    for (const StampedPose& p : poses) appendXyz(flat, p.T.translation(), origin);
    return base64(flat);
  };
  Json loops = Json::array();
  for (const LoopRow& l : f.loops)
    loops.push_back({{"frame", l.frame},
                     {"old_frame", l.old_frame},
                     {"inliers", l.inliers},
                     {"correction_m", mm(l.correction_m)}});
  return {{"name", folderName(f.dir)},
          {"trajectory", positions(f.trajectory)},
          {"odometry", positions(f.odometry)},
          {"loops", std::move(loops)}};
}

// The points of segments.ply grouped by segment (they are written segment after segment), each
// group's centroid the mean of its points.
Json segmentsJson(const SegmentFolder& f, const Eigen::Vector3d& origin,
                  const ClassTable& classes) {
  std::vector<std::vector<Eigen::Vector3f>> groups;
  std::vector<int64_t> ids;
  std::vector<uint16_t> point_classes;
  std::vector<uint8_t> rgb;
  for (size_t i = 0; i < f.points.size(); ++i) {
    const SegmentPoint& p = f.points[i];
    if (i == 0 || p.segment != f.points[i - 1].segment) {
      groups.emplace_back();
      ids.push_back(p.segment);
    }
    groups.back().push_back(p.p);
    point_classes.push_back(p.class_id);
    rgb.insert(rgb.end(), p.rgb.begin(), p.rgb.end());
  }
  std::vector<Eigen::Vector3f> centroids;
  std::vector<const std::vector<Eigen::Vector3f>*> group_ptrs;
  std::vector<float> flat;
  for (const auto& g : groups) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3f& p : g) sum += p.cast<double>();
    centroids.push_back((sum / static_cast<double>(g.size())).cast<float>());
    appendXyz(flat, centroids.back().cast<double>(), origin);
    group_ptrs.push_back(&g);
  }
  std::unordered_map<std::string, ClassId> class_of;
  for (const SemanticClass& c : classes.classes()) class_of[c.name] = c.id;
  std::vector<uint16_t> segment_classes;
  for (const SegmentRow& s : f.segments) segment_classes.push_back(class_of[s.class_name]);
  return {{"name", folderName(f.dir)},
          {"segments", f.segments.size()},
          {"groups", groups.size()},
          {"ids", ids},
          {"points_total", f.points.size()},
          {"centroids", base64(flat)},
          {"points", pointGroupsJson(centroids, group_ptrs)},
          {"point_classes", base64(point_classes)},
          {"rgb", base64(rgb)}};
}

}  // namespace

nlohmann::ordered_json sceneJson(const SceneInputs& in) {
  if (!in.map) throw std::invalid_argument("sceneJson needs a target map");
  const Eigen::Vector3d origin = sceneOrigin(*in.map);
  Json j = {{"format", "semsegmap-scene"},
            {"version", kSceneVersion},
            {"title", in.title},
            {"colouring", in.colouring},
            {"origin", {origin.x(), origin.y(), origin.z()}},
            {"classes", classesJson(in.classes)},
            {"map", mapJson(in, origin)},
            {"sessions", sessionsJson(*in.map, origin)}};
  j["localization"] = in.localization ? localizationJson(*in.localization, origin) : Json(nullptr);
  j["slam"] = in.slam ? slamJson(*in.slam, origin) : Json(nullptr);
  j["segments"] = in.segments ? segmentsJson(*in.segments, origin, in.classes) : Json(nullptr);
  return j;
}

std::string viewerPage(std::string_view page_template, const nlohmann::ordered_json& scene) {
  const size_t at = page_template.find(kScenePlaceholder);
  if (at == std::string_view::npos)
    throw std::runtime_error("the viewer's page has no place for the scene (" +
                             std::string(kScenePlaceholder) + "): a broken build of viewer/");
  const std::string text = scene.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::string page(page_template.substr(0, at));
  page.reserve(page_template.size() + text.size() + text.size() / 64);
  // '<' can only be inside a JSON string, where \u003c means the same: "</script>" or "<!--" in
  // a name cannot end or confuse the element.
  for (const char c : text) {
    if (c == '<')
      page += "\\u003c";
    else
      page += c;
  }
  page += page_template.substr(at + kScenePlaceholder.size());
  return page;
}

}  // namespace semsegmap::viz
