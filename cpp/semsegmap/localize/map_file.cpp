#include "semsegmap/localize/map_file.h"

#include <array>
#include <cstring>
#include <stdexcept>

#include <Eigen/Core>

#include "semsegmap/io/atomic_file.h"

namespace semsegmap {

namespace {

constexpr char kMagic[8] = {'S', 'S', 'M', 'M', 'A', 'P', '\r', '\n'};
constexpr uint32_t kFlagFloat16 = 1u << 0;
constexpr uint32_t kFlagPoints = 1u << 1;

class Writer {
 public:
  template <typename T>
  void put(T v) {
    const size_t at = bytes.size();
    bytes.resize(at + sizeof(T));
    std::memcpy(&bytes[at], &v, sizeof(T));
  }
  void putString(const std::string& s) {
    if (s.size() > 255) throw std::invalid_argument("map header string longer than 255 bytes");
    put<uint8_t>(static_cast<uint8_t>(s.size()));
    bytes += s;
  }
  void putHalf(float v) { put(Eigen::numext::bit_cast<uint16_t>(Eigen::half(v))); }
  std::string bytes;
};

class Reader {
 public:
  Reader(const std::filesystem::path& path, const std::string& bytes, size_t end)
      : path_(path), bytes_(bytes), end_(end) {}
  template <typename T>
  T get(const char* what) {
    need(sizeof(T), what);
    T v;
    std::memcpy(&v, &bytes_[at_], sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  std::string getString(const char* what) {
    const size_t n = get<uint8_t>(what);
    need(n, what);
    std::string s = bytes_.substr(at_, n);
    at_ += n;
    return s;
  }
  float getHalf(const char* what) {
    return static_cast<float>(
        Eigen::half(Eigen::half_impl::raw_uint16_to_half(get<uint16_t>(what))));
  }
  void need(size_t n, const char* what) const {
    if (at_ + n > end_)
      throw std::runtime_error(path_.string() + ": truncated map file (ends inside " + what + ")");
  }
  size_t position() const { return at_; }

 private:
  const std::filesystem::path& path_;
  const std::string& bytes_;
  size_t end_;
  size_t at_ = 0;
};

}  // namespace

uint64_t fnv1a64(const char* data, size_t size) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i < size; ++i) {
    h ^= static_cast<unsigned char>(data[i]);
    h *= 1099511628211ull;
  }
  return h;
}

uint64_t saveTargetMap(const std::filesystem::path& path, const TargetMap& map,
                       const MapWriteOptions& options) {
  if (static_cast<size_t>(map.descriptors.rows()) != map.segments.size())
    throw std::invalid_argument(path.string() + ": map has " + std::to_string(map.segments.size()) +
                                " segments but " + std::to_string(map.descriptors.rows()) +
                                " descriptors");
  bool points = false;
  for (const MapSegment& s : map.segments) points = points || !s.points.empty();
  Writer w;
  w.bytes.append(kMagic, sizeof(kMagic));
  w.put<uint32_t>(kMapFormatVersion);
  w.put<uint32_t>((options.float16 ? kFlagFloat16 : 0u) | (points ? kFlagPoints : 0u));
  w.putString(map.descriptor);
  w.putString(map.fingerprint);
  w.put<uint32_t>(static_cast<uint32_t>(map.dimension()));
  w.put<uint64_t>(map.segments.size());
  for (size_t i = 0; i < map.segments.size(); ++i) {
    const MapSegment& s = map.segments[i];
    for (int k = 0; k < 3; ++k) w.put<float>(s.centroid[k]);
    w.put<uint32_t>(s.n_points);
    w.put<uint16_t>(s.majority_class);
    for (int k = 0; k < map.dimension(); ++k) {
      const float v = map.descriptors(static_cast<Eigen::Index>(i), k);
      if (options.float16)
        w.putHalf(v);
      else
        w.put<float>(v);
    }
  }
  if (points)
    for (const MapSegment& s : map.segments) {
      if (s.points.size() > 65535) throw std::invalid_argument("more than 65535 picture points");
      w.put<uint16_t>(static_cast<uint16_t>(s.points.size()));
      // Offsets from the centroid: float16 keeps centimetres within tens of metres.
      for (const Eigen::Vector3f& p : s.points)
        for (int k = 0; k < 3; ++k) w.putHalf(p[k] - s.centroid[k]);
    }
  w.put<uint64_t>(fnv1a64(w.bytes.data(), w.bytes.size()));
  writeBytesAtomically(path, w.bytes);
  return w.bytes.size();
}

TargetMap loadTargetMap(const std::filesystem::path& path) {
  const std::string bytes = readFileBytes(path);
  const std::string where = path.string() + ": ";
  if (bytes.size() < sizeof(kMagic) || std::memcmp(bytes.data(), kMagic, sizeof(kMagic)) != 0)
    throw std::runtime_error(where + "not a semsegmap map file (bad magic)");
  if (bytes.size() < sizeof(kMagic) + 4 + 8)
    throw std::runtime_error(where + "truncated map file (no header)");
  Reader r(path, bytes, bytes.size() - sizeof(uint64_t));
  r.get<std::array<char, 8>>("magic");
  const uint32_t version = r.get<uint32_t>("header");
  if (version != kMapFormatVersion)
    throw std::runtime_error(where + "map format version " + std::to_string(version) +
                             ", this build reads version " + std::to_string(kMapFormatVersion) +
                             " (rebuild the map with `semsegmap map`)");
  uint64_t stored;
  std::memcpy(&stored, &bytes[bytes.size() - sizeof(stored)], sizeof(stored));
  if (fnv1a64(bytes.data(), bytes.size() - sizeof(stored)) != stored)
    throw std::runtime_error(where + "checksum mismatch: the map file is truncated or corrupt");
  const uint32_t flags = r.get<uint32_t>("header");
  if (flags & ~(kFlagFloat16 | kFlagPoints))
    throw std::runtime_error(where + "unknown header flags " + std::to_string(flags));
  TargetMap map;
  map.descriptor = r.getString("header");
  map.fingerprint = r.getString("header");
  const uint32_t dim = r.get<uint32_t>("header");
  const uint64_t n = r.get<uint64_t>("header");
  const size_t per_segment = 12 + 4 + 2 + dim * ((flags & kFlagFloat16) ? 2 : 4);
  if (dim == 0 || dim > 4096) throw std::runtime_error(where + "implausible descriptor dimension");
  if (n > bytes.size())
    throw std::runtime_error(where + "truncated map file (ends inside the segments)");
  r.need(n * per_segment, "the segments");  // before allocating n of anything
  map.segments.resize(n);
  map.descriptors.resize(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(dim));
  for (size_t i = 0; i < n; ++i) {
    MapSegment& s = map.segments[i];
    for (int k = 0; k < 3; ++k) s.centroid[k] = r.get<float>("a segment");
    s.n_points = r.get<uint32_t>("a segment");
    s.majority_class = r.get<uint16_t>("a segment");
    for (uint32_t k = 0; k < dim; ++k)
      map.descriptors(static_cast<Eigen::Index>(i), k) =
          (flags & kFlagFloat16) ? r.getHalf("a descriptor") : r.get<float>("a descriptor");
  }
  if (flags & kFlagPoints)
    for (MapSegment& s : map.segments) {
      const size_t count = r.get<uint16_t>("the points");
      r.need(count * 6, "the points");
      s.points.resize(count);
      for (Eigen::Vector3f& p : s.points)
        for (int k = 0; k < 3; ++k) p[k] = s.centroid[k] + r.getHalf("the points");
    }
  if (r.position() != bytes.size() - sizeof(stored))
    throw std::runtime_error(where + "trailing bytes after the segments");
  return map;
}

void checkMapCompatible(const std::filesystem::path& path, const TargetMap& map,
                        const std::string& descriptor, const std::string& fingerprint,
                        int dimension) {
  const std::string where = path.string() + ": ";
  if (map.descriptor != descriptor)
    throw std::runtime_error(where + "map built with " + map.descriptor +
                             " descriptors, the configuration uses " + descriptor);
  if (map.dimension() != dimension)
    throw std::runtime_error(where + "map descriptors have dimension " +
                             std::to_string(map.dimension()) + ", the describer gives " +
                             std::to_string(dimension));
  if (map.fingerprint != fingerprint)
    throw std::runtime_error(where + "map built with model " + map.fingerprint +
                             ", the configuration's model is " + fingerprint +
                             " (rebuild the map with this model)");
}

}  // namespace semsegmap
