#include "semsegmap/artefacts/map_file.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "semsegmap/artefacts/map_codec.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/binary_io.h"

namespace semsegmap {

namespace {

constexpr std::string_view kMapMagic("SSMMAP\r\n", 8);
constexpr uint32_t kFlagFloat16 = 1u << 0;
constexpr uint32_t kFlagPoints = 1u << 1;
constexpr uint32_t kFlagScanContexts = 1u << 2;
constexpr uint32_t kFlagSessions = 1u << 3;
// A map records a few dozen settings; more is a corrupt count, refused before reading on.
constexpr uint16_t kMaxParameters = 1024;

void putParameters(BinaryWriter& w, const std::filesystem::path& path, const MapParameters& p) {
  if (p.size() > kMaxParameters)
    throw std::invalid_argument(path.string() + ": more than " + std::to_string(kMaxParameters) +
                                " map parameters");
  w.put<uint16_t>(static_cast<uint16_t>(p.size()));
  for (const auto& [key, value] : p) {
    if (key.empty() || key.size() > 255 || value.size() > 255)
      throw std::invalid_argument(path.string() + ": map parameter '" + key +
                                  "': key must be 1..255 bytes, value at most 255");
    w.putString8(key);
    w.putString8(value);
  }
}

MapParameters getParameters(BinaryReader& r) {
  const uint16_t n = r.get<uint16_t>("the parameters");
  if (n > kMaxParameters) r.fail("implausible parameter count " + std::to_string(n));
  r.need(n, 2, "the parameters");  // an empty key and value take 2 bytes
  MapParameters p;
  for (uint16_t i = 0; i < n; ++i) {
    std::string key = r.getString8("the parameters");
    std::string value = r.getString8("the parameters");
    if (key.empty()) r.fail("parameter " + std::to_string(i) + " has an empty key");
    for (const auto& [k, v] : p)
      if (k == key) r.fail("parameter " + key + " appears twice");
    p.emplace_back(std::move(key), std::move(value));
  }
  return p;
}

// The sessions (flag bit 3): each one's name, time and trajectory, then per segment its segment
// id, session and keyframe.
void putSessions(BinaryWriter& w, const TargetMap& map) {
  w.put<uint16_t>(static_cast<uint16_t>(map.sessions.size()));
  for (const MapSession& s : map.sessions) {
    w.putString32(s.name);
    w.put<int64_t>(s.merged_unix_s);
    w.put<uint64_t>(s.trajectory.size());
    for (const Pose& T : s.trajectory) putPose(w, T);
  }
  for (const MapSegment& s : map.segments) {
    w.put<uint32_t>(s.segment);
    w.put<uint16_t>(s.session);
    w.put<uint32_t>(s.keyframe);
  }
}

void getSessions(BinaryReader& r, TargetMap& map) {
  const uint16_t n = r.get<uint16_t>("the sessions");
  if (n == 0) r.fail("a sessions block without sessions");
  map.sessions.resize(n);
  for (MapSession& s : map.sessions) {
    s.name = r.getString32("the sessions");
    s.merged_unix_s = r.get<int64_t>("the sessions");
    const uint64_t poses = r.getCount(40, "the sessions");
    for (uint64_t i = 0; i < poses; ++i)
      s.trajectory.push_back(getPose(r, "session " + s.name + " pose " + std::to_string(i)));
  }
  r.need(map.segments.size(), 10, "the segments' sessions");
  for (MapSegment& s : map.segments) {
    s.segment = r.get<uint32_t>("the segments' sessions");
    s.session = r.get<uint16_t>("the segments' sessions");
    s.keyframe = r.get<uint32_t>("the segments' sessions");
  }
  if (const std::string bad = firstOutOfSession(map); !bad.empty()) r.fail(bad);
}

}  // namespace

uint64_t saveTargetMap(const std::filesystem::path& path, const TargetMap& map,
                       const MapWriteOptions& options) {
  // Refused here because the loader refuses it: a saved map always reads back.
  if (const std::string bad = firstUnsavable(map); !bad.empty())
    throw std::invalid_argument(path.string() + ": " + bad);
  bool points = false;
  for (const MapSegment& s : map.segments) points = points || !s.points.empty();
  BinaryWriter w;
  w.putBytes(kMapMagic.data(), kMapMagic.size());
  w.put<uint32_t>(kMapFormatVersion);
  const bool scan_contexts = map.scan_contexts.size() > 0;
  const bool sessions = !map.sessions.empty();
  w.put<uint32_t>((options.float16 ? kFlagFloat16 : 0u) | (points ? kFlagPoints : 0u) |
                  (scan_contexts ? kFlagScanContexts : 0u) | (sessions ? kFlagSessions : 0u));
  w.putString8(map.descriptor);
  w.putString8(map.fingerprint);
  w.put<uint32_t>(static_cast<uint32_t>(map.dimension()));
  putParameters(w, path, map.parameters);
  w.put<uint64_t>(map.segments.size());
  for (size_t i = 0; i < map.segments.size(); ++i) {
    const MapSegment& s = map.segments[i];
    for (int k = 0; k < 3; ++k) w.put<float>(s.centroid[k]);
    w.put<uint32_t>(s.n_points);
    w.put<uint16_t>(s.majority_class);
    for (int k = 0; k < map.dimension(); ++k) {
      const float v = map.descriptors(static_cast<Eigen::Index>(i), k);
      if (options.float16)
        putHalf(w, v);
      else
        w.put<float>(v);
    }
  }
  if (points)
    for (const MapSegment& s : map.segments) {
      w.put<uint16_t>(static_cast<uint16_t>(s.points.size()));  // firstUnsavable: <= 65535
      putPoints(w, s);
    }
  if (scan_contexts) putScanContexts(w, map.scan_contexts);
  if (sessions) putSessions(w, map);
  w.putChecksum();
  writeBytesAtomically(path, w.bytes());
  return w.bytes().size();
}

TargetMap loadTargetMap(const std::filesystem::path& path) {
  const std::string bytes = readFileBytes(path);
  BinaryReader r(path, bytes, "map file");
  r.expectMagic(kMapMagic);
  const uint32_t version = r.get<uint32_t>("the header");
  if (version == 1)
    r.fail("map format version 1 records no build settings, this build reads version " +
           std::to_string(kMapFormatVersion) + ": rebuild the map with `semsegmap map`");
  if (version != kMapFormatVersion)
    r.fail("map format version " + std::to_string(version) + ", this build reads version " +
           std::to_string(kMapFormatVersion) + " (rebuild the map with `semsegmap map`)");
  r.checksummed();
  const uint32_t flags = r.get<uint32_t>("the header");
  if (flags & ~(kFlagFloat16 | kFlagPoints | kFlagScanContexts | kFlagSessions))
    r.fail("unknown header flags " + std::to_string(flags));
  TargetMap map;
  map.descriptor = r.getString8("the header");
  map.fingerprint = r.getString8("the header");
  const uint32_t dim = r.get<uint32_t>("the header");
  if (dim == 0 || dim > 4096) r.fail("implausible descriptor dimension " + std::to_string(dim));
  map.parameters = getParameters(r);
  const size_t per_segment = 12 + 4 + 2 + dim * ((flags & kFlagFloat16) ? 2 : 4);
  const uint64_t n = r.getCount(per_segment, "the segments");  // before allocating n of anything
  map.segments.resize(n);
  map.descriptors.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(dim));
  for (size_t i = 0; i < n; ++i) {
    MapSegment& s = map.segments[i];
    for (int k = 0; k < 3; ++k) s.centroid[k] = r.get<float>("a segment");
    s.n_points = r.get<uint32_t>("a segment");
    s.majority_class = r.get<uint16_t>("a segment");
    for (uint32_t k = 0; k < dim; ++k)
      map.descriptors(static_cast<Eigen::Index>(i), k) =
          (flags & kFlagFloat16) ? getHalf(r, "a descriptor") : r.get<float>("a descriptor");
  }
  if (flags & kFlagPoints)
    for (MapSegment& s : map.segments) {
      getPoints(r, r.get<uint16_t>("the points"), s);
    }
  if (flags & kFlagScanContexts) map.scan_contexts = getScanContexts(r);
  if (flags & kFlagSessions)
    getSessions(r, map);
  else  // the map of one run: each entry its own segment
    for (size_t i = 0; i < map.segments.size(); ++i)
      map.segments[i].segment = static_cast<uint32_t>(i);
  r.expectEnd("the segments");
  if (const std::string bad = firstNonFinite(map); !bad.empty()) r.fail(bad);
  map.source = path.string();
  return map;
}

}  // namespace semsegmap
