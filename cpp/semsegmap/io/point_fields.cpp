#include "semsegmap/io/point_fields.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/core/shown_text.h"

namespace semsegmap {

namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "point records are read little-endian");

size_t typeSize(FieldType t) {
  switch (t) {
    case FieldType::kInt8:
    case FieldType::kUint8:
      return 1;
    case FieldType::kInt16:
    case FieldType::kUint16:
      return 2;
    case FieldType::kInt32:
    case FieldType::kUint32:
    case FieldType::kFloat32:
      return 4;
    case FieldType::kFloat64:
      return 8;
  }
  return 0;
}

template <typename T>
double load(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return static_cast<double>(v);
}

double readValue(FieldType t, const uint8_t* p) {
  switch (t) {
    case FieldType::kInt8:
      return load<int8_t>(p);
    case FieldType::kUint8:
      return load<uint8_t>(p);
    case FieldType::kInt16:
      return load<int16_t>(p);
    case FieldType::kUint16:
      return load<uint16_t>(p);
    case FieldType::kInt32:
      return load<int32_t>(p);
    case FieldType::kUint32:
      return load<uint32_t>(p);
    case FieldType::kFloat32:
      return load<float>(p);
    case FieldType::kFloat64:
      return load<double>(p);
  }
  return 0.0;
}

bool isFloat(FieldType t) {
  return t == FieldType::kFloat32 || t == FieldType::kFloat64;
}

const PointFieldSpec* findField(const std::vector<PointFieldSpec>& fields,
                                std::initializer_list<const char*> names) {
  for (const char* name : names)
    for (const PointFieldSpec& f : fields)
      if (f.name == name) return &f;
  return nullptr;
}

void checkField(const PointFieldSpec& f, size_t point_step, const std::string& what) {
  const size_t size = typeSize(f.type);
  if (size == 0)
    throw std::runtime_error(what + ": field '" + shownText(f.name) +
                             "' has the unknown datatype " +
                             std::to_string(static_cast<int>(f.type)));
  if (f.count == 0 || f.offset + size * f.count > point_step)
    throw std::runtime_error(what + ": field '" + shownText(f.name) + "' at offset " +
                             std::to_string(f.offset) + " does not fit in the " +
                             std::to_string(point_step) + "-byte point record");
}

// The beam of a point: a ring beyond the LiDAR rows a rig can have is a corrupt record (and
// would overflow the conversion to int).
int ringOf(const PointFieldSpec& ring, const uint8_t* record, size_t i, const std::string& what) {
  const double value = readValue(ring.type, record + ring.offset);
  if (!(value >= 0 && value < kMaxLidarRows))
    throw std::runtime_error(what + ": point " + std::to_string(i) + " has the ring " +
                             std::to_string(value) + ", expected 0.." +
                             std::to_string(kMaxLidarRows - 1));
  return static_cast<int>(value);
}

}  // namespace

DecodedPoints decodePointFields(const std::vector<PointFieldSpec>& fields, size_t point_step,
                                const uint8_t* data, size_t size, size_t n_points,
                                const std::string& what) {
  const PointFieldSpec* axis[3] = {findField(fields, {"x"}), findField(fields, {"y"}),
                                   findField(fields, {"z"})};
  for (int k = 0; k < 3; ++k)
    if (!axis[k])
      throw std::runtime_error(what + ": no '" + std::string(1, static_cast<char>('x' + k)) +
                               "' field (fields x, y and z are needed)");
  const PointFieldSpec* intensity = findField(fields, {"intensity", "reflectivity", "i"});
  const PointFieldSpec* time =
      findField(fields, {"t", "time", "timestamp", "offset_time", "time_offset"});
  const PointFieldSpec* ring = findField(fields, {"ring"});
  for (const PointFieldSpec* f : {axis[0], axis[1], axis[2], intensity, time, ring})
    if (f) checkField(*f, point_step, what);
  if (point_step == 0 || n_points > size / point_step)
    throw std::runtime_error(what + ": " + std::to_string(n_points) + " points of " +
                             std::to_string(point_step) + " bytes need more than the " +
                             std::to_string(size) + " bytes of data");
  DecodedPoints out;
  out.intensity_field = intensity ? intensity->name : "";
  out.time_field = time ? time->name : "";
  const bool time_in_ns = time && !isFloat(time->type);
  out.points.reserve(n_points);
  if (time) out.times.reserve(n_points);
  for (size_t i = 0; i < n_points; ++i) {
    const uint8_t* record = data + i * point_step;
    const double x = readValue(axis[0]->type, record + axis[0]->offset);
    const double y = readValue(axis[1]->type, record + axis[1]->offset);
    const double z = readValue(axis[2]->type, record + axis[2]->offset);
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
      ++out.dropped_invalid;  // an organized cloud's "no return"
      continue;
    }
    const double v = intensity ? readValue(intensity->type, record + intensity->offset) : 0.0;
    out.points.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(z),
                          std::isfinite(v) ? static_cast<float>(v) : 0.0f});
    if (ring) out.rings = std::max(out.rings, 1 + ringOf(*ring, record, i, what));
    if (time) {
      const double t = readValue(time->type, record + time->offset);
      if (!std::isfinite(t))
        throw std::runtime_error(what + ": point " + std::to_string(i) + " has the time " +
                                 std::to_string(t) + " (field '" + shownText(time->name) + "')");
      // Floats beyond 1e15 are nanoseconds too: no clock counts seconds that high.
      out.times.push_back(time_in_ns || std::abs(t) > 1e15 ? t * 1e-9 : t);
    }
  }
  return out;
}

std::vector<float> relativePointTimes(const std::vector<double>& times, double scan_stamp_s) {
  if (times.empty()) return {};
  const auto [lo, hi] = std::minmax_element(times.begin(), times.end());
  // A sweep lasts well under a second: values of many days are clock times.
  const bool absolute = *hi > 1e6;
  const double origin = !absolute ? 0.0 : scan_stamp_s > 0.0 ? scan_stamp_s : *lo;
  std::vector<float> out(times.size());
  for (size_t i = 0; i < times.size(); ++i) out[i] = static_cast<float>(times[i] - origin);
  return out;
}

}  // namespace semsegmap
