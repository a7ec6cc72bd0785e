// Layout (little-endian, core/binary_io.h):
//   "SSMTRAIN" u32 version | str provenance | u32 n, n x (str source, str world) |
//   u64 n, n x observation | u64 FNV-1a of every byte before it
// str = u32 length + bytes; observation = u16 instance, u16 class, u16 source, i64 segment,
//   u32 n_points, u32 frame index, f32 purity, 3 x f32 centroid, u32 count, count x 6 f32, count x
//   u16 class, count x u8 modalities (1: has colour, 2: has a class).
#include "semsegmap/artefacts/training_cache.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <system_error>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/binary_io.h"

namespace semsegmap {

namespace {

constexpr std::string_view kCacheMagic("SSMTRAIN", 8);
// 3: the checksum covers the whole file (core/binary_io.h), as in the other formats.
// 4: a point's byte holds whether it has a class besides whether it has colour (unobserved
// points); a cache of another version is extracted again.
// 5: an observation's frame index (its segment's growth over time, eval/completeness).
constexpr uint32_t kVersion = 5;
constexpr size_t kFixedObservationBytes = 2 + 2 + 2 + 8 + 4 + 4 + 4 + 12 + 4;
constexpr size_t kPointBytes = 6 * 4 + 2 + 1;

void putObservation(BinaryWriter& w, const TrainingObservation& o) {
  w.put(o.instance);
  w.put(o.majority_class);
  w.put(o.source);
  w.put(o.segment);
  w.put(o.n_points);
  w.put(o.frame_index);
  w.put(o.purity);
  for (int k = 0; k < 3; ++k) w.put(o.centroid[k]);
  w.put(static_cast<uint32_t>(o.size()));
  w.putArray(o.xyzhsv);
  w.putArray(o.classes);
  w.putArray(o.modalities);
}

TrainingObservation getObservation(BinaryReader& r, size_t sources) {
  TrainingObservation o;
  o.instance = r.get<uint16_t>("an observation");
  o.majority_class = r.get<ClassId>("an observation");
  o.source = r.get<uint16_t>("an observation");
  if (o.source >= sources) r.fail("corrupt training cache (bad source index)");
  o.segment = r.get<int64_t>("an observation");
  o.n_points = r.get<uint32_t>("an observation");
  o.frame_index = r.get<uint32_t>("an observation");
  o.purity = r.get<float>("an observation");
  for (int k = 0; k < 3; ++k) o.centroid[k] = r.get<float>("an observation");
  const uint32_t n = r.get<uint32_t>("an observation");
  r.need(n, kPointBytes, "the points of an observation");
  o.xyzhsv = r.getArray<float>(6 * size_t{n}, "the points of an observation");
  o.classes = r.getArray<ClassId>(n, "the points of an observation");
  o.modalities = r.getArray<uint8_t>(n, "the points of an observation");
  const auto finite = [](float v) { return std::isfinite(v); };
  if (!std::isfinite(o.purity) || !o.centroid.allFinite() ||
      !std::all_of(o.xyzhsv.begin(), o.xyzhsv.end(), finite))
    r.fail("corrupt training cache (a non-finite value in the observation of segment " +
           std::to_string(o.segment) + ")");
  return o;
}

}  // namespace

void writeTrainingCache(const std::filesystem::path& path, const TrainingSet& set,
                        const std::string& provenance) {
  BinaryWriter w;
  w.putBytes(kCacheMagic.data(), kCacheMagic.size());
  w.put(kVersion);
  w.putString32(provenance);
  w.put(static_cast<uint32_t>(set.sources.size()));
  for (size_t i = 0; i < set.sources.size(); ++i) {
    w.putString32(set.sources[i]);
    w.putString32(i < set.source_worlds.size() ? set.source_worlds[i] : set.sources[i]);
  }
  w.put(static_cast<uint64_t>(set.observations.size()));
  for (const TrainingObservation& o : set.observations) putObservation(w, o);
  w.putChecksum();
  writeBytesAtomically(path, w.bytes());
}

std::optional<TrainingSet> readTrainingCache(const std::filesystem::path& path,
                                             const std::string& provenance) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return std::nullopt;
  const std::string bytes = readFileBytes(path);
  BinaryReader r(path, bytes, "training cache");
  r.expectMagic(kCacheMagic);
  // An older layout is not an error: the data is simply extracted again.
  if (r.get<uint32_t>("the header") != kVersion) return std::nullopt;
  r.checksummed();
  if (r.getString32("the provenance") != provenance) return std::nullopt;
  TrainingSet set;
  const uint32_t n_sources = r.get<uint32_t>("the sources");
  r.need(n_sources, 8, "the sources");
  for (uint32_t i = 0; i < n_sources; ++i) {
    set.sources.push_back(r.getString32("the sources"));
    set.source_worlds.push_back(r.getString32("the sources"));
  }
  const uint64_t n = r.getCount(kFixedObservationBytes, "the observations");
  set.observations.reserve(n);
  for (uint64_t i = 0; i < n; ++i) set.observations.push_back(getObservation(r, n_sources));
  r.expectEnd("the observations");
  return set;
}

}  // namespace semsegmap
