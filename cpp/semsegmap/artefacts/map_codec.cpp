#include "semsegmap/artefacts/map_codec.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace semsegmap {

namespace {
// A scan context grid finer than this is corrupt, refused before allocating it.
constexpr uint16_t kMaxScanContextBins = 1024;
}  // namespace

void putHalf(BinaryWriter& w, float v) {
  w.put(Eigen::numext::bit_cast<uint16_t>(Eigen::half(v)));
}
float getHalf(BinaryReader& r, const char* field) {
  return static_cast<float>(
      Eigen::half(Eigen::half_impl::raw_uint16_to_half(r.get<uint16_t>(field))));
}

// A NaN centroid or descriptor matches nothing and a NaN distance sorts anywhere: such a map
// localized nothing and reported "mean error 0.00 m" instead of failing. Empty when all is finite.
std::string firstNonFinite(const TargetMap& map) {
  for (size_t i = 0; i < map.segments.size(); ++i) {
    const MapSegment& s = map.segments[i];
    const std::string segment = "segment " + std::to_string(i) + ": non-finite ";
    if (!s.centroid.allFinite()) return segment + "centroid";
    if (!map.descriptors.row(static_cast<Eigen::Index>(i)).allFinite())
      return segment + "descriptor";
    for (const Eigen::Vector3f& p : s.points)
      if (!p.allFinite()) return segment + "point";
  }
  return {};
}

// A pose as float64 x, y, z and a float32 unit quaternion w, x, y, z (40 bytes).
void putPose(BinaryWriter& w, const Pose& T) {
  const Eigen::Vector3d t = T.translation();
  const Eigen::Quaterniond q(T.linear());
  for (int k = 0; k < 3; ++k) w.put<double>(t[k]);
  for (double v : {q.w(), q.x(), q.y(), q.z()}) w.put<float>(static_cast<float>(v));
}

// `what` names the pose in the error ("scan context 3").
Pose getPose(BinaryReader& r, const std::string& what) {
  Pose T = Pose::Identity();
  for (int k = 0; k < 3; ++k) T.translation()[k] = r.get<double>(what.c_str());
  double q[4];
  for (double& v : q) v = r.get<float>(what.c_str());
  const Eigen::Quaterniond rotation(q[0], q[1], q[2], q[3]);
  if (!T.translation().allFinite() || !(std::abs(rotation.norm() - 1.0) < 1e-3))
    r.fail(what + ": not a pose");
  T.linear() = rotation.normalized().toRotationMatrix();
  return T;
}

// The scan contexts (flag bit 2): the grid, then per scan its frame and its bins as float16.
void putScanContexts(BinaryWriter& w, const ScanContextDatabase& db) {
  const ScanContextConfig& c = db.config();
  w.put<uint16_t>(static_cast<uint16_t>(c.rings));
  w.put<uint16_t>(static_cast<uint16_t>(c.sectors));
  w.put<float>(static_cast<float>(c.max_radius_m));
  w.put<float>(static_cast<float>(c.height_offset_m));
  w.put<uint64_t>(db.size());
  for (const ScanContextDatabase::MappedScan& s : db.scans()) {
    putPose(w, s.T_world_scan);
    for (Eigen::Index i = 0; i < s.context.bins.size(); ++i) putHalf(w, s.context.bins(i));
  }
}

ScanContextDatabase getScanContexts(BinaryReader& r) {
  ScanContextConfig c;
  c.rings = r.get<uint16_t>("the scan contexts");
  c.sectors = r.get<uint16_t>("the scan contexts");
  c.max_radius_m = r.get<float>("the scan contexts");
  c.height_offset_m = r.get<float>("the scan contexts");
  if (c.rings == 0 || c.sectors == 0 || c.rings > kMaxScanContextBins ||
      c.sectors > kMaxScanContextBins || !(c.max_radius_m > 0) || !std::isfinite(c.max_radius_m) ||
      !std::isfinite(c.height_offset_m))
    r.fail("implausible scan context grid " + std::to_string(c.rings) + " x " +
           std::to_string(c.sectors));
  const size_t bins = c.rings * c.sectors;
  const uint64_t n = r.getCount(24 + 16 + 2 * bins, "the scan contexts");
  ScanContextDatabase db(c);
  for (uint64_t i = 0; i < n; ++i) {
    const Pose T = getPose(r, "scan context " + std::to_string(i));
    Eigen::MatrixXf b(c.rings, c.sectors);
    for (Eigen::Index k = 0; k < b.size(); ++k) b(k) = getHalf(r, "a scan context");
    if (!b.allFinite() || (b.array() < 0).any())
      r.fail("scan context " + std::to_string(i) + ": a non-finite or negative bin");
    db.add(scanContextOfBins(std::move(b)), T);
  }
  return db;
}

// Every segment's session exists and its keyframe lies within that session's trajectory (a
// session without one, the map's first, has keyframe 0 alone). Empty when all do.
std::string firstOutOfSession(const TargetMap& map) {
  for (size_t i = 0; i < map.segments.size(); ++i) {
    const MapSegment& s = map.segments[i];
    const std::string segment = "segment " + std::to_string(i) + ": ";
    if (s.session >= map.sessions.size())
      return segment + "session " + std::to_string(s.session) + " of " +
             std::to_string(map.sessions.size());
    const size_t frames = map.sessions[s.session].trajectory.size();
    if (s.keyframe >= std::max<size_t>(frames, 1))
      return segment + "keyframe " + std::to_string(s.keyframe) + " of a trajectory of " +
             std::to_string(frames);
  }
  return {};
}

void putPoints(BinaryWriter& w, const MapSegment& s) {
  for (const Eigen::Vector3f& p : s.points)
    for (int k = 0; k < 3; ++k) putHalf(w, p[k] - s.centroid[k]);
}

void getPoints(BinaryReader& r, size_t count, MapSegment& s) {
  r.need(count, 6, "the points");
  s.points.resize(count);
  for (Eigen::Vector3f& p : s.points)
    for (int k = 0; k < 3; ++k) p[k] = s.centroid[k] + getHalf(r, "the points");
}

std::string firstUnsavable(const TargetMap& map) {
  if (static_cast<size_t>(map.descriptors.rows()) != map.segments.size())
    return "map has " + std::to_string(map.segments.size()) + " segments but " +
           std::to_string(map.descriptors.rows()) + " descriptors";
  if (map.sessions.size() > 65535) return "more than 65535 sessions";
  for (size_t i = 0; i < map.segments.size(); ++i)
    if (map.segments[i].points.size() > 65535)
      return "segment " + std::to_string(i) + ": more than 65535 picture points";
  if (std::string bad = firstNonFinite(map); !bad.empty()) return bad;
  if (map.sessions.empty()) return {};
  return firstOutOfSession(map);
}

}  // namespace semsegmap
