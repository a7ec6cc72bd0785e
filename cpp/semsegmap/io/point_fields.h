// Points stored as records of named fields: sensor_msgs/PointCloud2, PCD and PLY all describe a
// point by fields (name, byte offset, datatype, count) inside a fixed-size record. One decoder
// turns any such layout into LiDAR points and per-point times, so that every reader accepts the
// same layouts: x y z as float32 or float64, an intensity of any type, padding, extra fields.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "semsegmap/core/frame.h"

namespace semsegmap {

// The datatype numbering of sensor_msgs/PointField, which PCL's PCLPointField shares.
enum class FieldType : uint8_t {
  kInt8 = 1,
  kUint8 = 2,
  kInt16 = 3,
  kUint16 = 4,
  kInt32 = 5,
  kUint32 = 6,
  kFloat32 = 7,
  kFloat64 = 8
};

struct PointFieldSpec {
  std::string name;
  uint32_t offset = 0;
  FieldType type = FieldType::kFloat32;
  uint32_t count = 1;
};

struct DecodedPoints {
  std::vector<LidarPoint> points;
  // Per-point times in seconds as stored (relative or absolute), empty without a time field.
  std::vector<double> times;
  std::string intensity_field;  // the field intensity was read from; empty: none (0)
  std::string time_field;       // the field times were read from; empty: none
  size_t dropped_invalid = 0;   // points with a NaN or infinite coordinate (organized clouds)
  int rings = 0;                // 1 + the largest "ring" value; 0 without a ring field
};

// Decodes `n_points` records of `point_step` bytes from `data` (`size` bytes), little-endian.
// Intensity comes from "intensity", "reflectivity" or "i"; the time from "t", "time",
// "timestamp", "offset_time" or "time_offset" (floats are seconds, integers nanoseconds, and so
// are floats beyond 1e15).
// Throws std::runtime_error "<what>: <problem>" (what names the file or topic) when x, y or z
// is missing, a field lies outside the record, or the data is shorter than the records.
DecodedPoints decodePointFields(const std::vector<PointFieldSpec>& fields, size_t point_step,
                                const uint8_t* data, size_t size, size_t n_points,
                                const std::string& what);

// Times relative to the scan: absolute times (beyond 1e6 s: clock times, as some drivers write)
// become seconds after `scan_stamp_s` (after the earliest point when the stamp is 0); relative ones
// are kept. Returns float seconds, Frame::point_times' type.
std::vector<float> relativePointTimes(const std::vector<double>& times, double scan_stamp_s);

}  // namespace semsegmap
