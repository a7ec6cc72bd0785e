// Typed reading of YAML fields whose every error is one line "<file>: <field>: <what was
// wrong>": meta.yaml and rig files are written by hand, and a message that names the field is
// the difference between a fix and a search.
#pragma once

#include <array>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/core/shown_text.h"

namespace semsegmap {

// Loads a YAML file; a missing file, a directory, a syntax error or an empty file is a
// std::runtime_error naming the file (and the line and column of a syntax error).
YAML::Node loadYamlFile(const std::filesystem::path& path);

class YamlFields {
 public:
  explicit YamlFields(const std::filesystem::path& path) : path_(path.string()) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(path_ + ": " + shownText(what, std::string::npos));
  }

  void expectMap(const YAML::Node& node, const std::string& where) const {
    if (!node.IsMap()) fail(where + ": expected a mapping, got " + describe(node));
  }

  void checkKeys(const YAML::Node& map, const std::string& where,
                 std::initializer_list<const char*> allowed) const {
    for (const auto& entry : map) {
      const std::string key = entry.first.Scalar();
      bool ok = false;
      for (const char* a : allowed) ok = ok || key == a;
      if (!ok)
        fail("unknown key '" + key + "' " + (where.empty() ? "at the top level" : "in " + where));
    }
  }

  YAML::Node child(const YAML::Node& map, const std::string& where, const char* key) const {
    const YAML::Node node = map[key];
    if (!node.IsDefined()) fail(field(where, key) + ": missing");
    return node;
  }

  double number(const YAML::Node& map, const std::string& where, const char* key) const {
    return toNumber(child(map, where, key), field(where, key));
  }

  // The bound of a field read into an int.
  static constexpr long long kMaxInt = std::numeric_limits<int>::max();

  long long integer(const YAML::Node& map, const std::string& where, const char* key, long long lo,
                    long long hi) const {
    return toInteger(child(map, where, key), field(where, key), lo, hi);
  }

  bool flag(const YAML::Node& map, const std::string& where, const char* key) const {
    const YAML::Node node = child(map, where, key);
    bool value = false;
    if (!node.IsScalar() || !YAML::convert<bool>::decode(node, value))
      fail(field(where, key) + ": expected true or false, got " + describe(node));
    return value;
  }

  std::string text(const YAML::Node& map, const std::string& where, const char* key) const {
    const YAML::Node node = child(map, where, key);
    if (!node.IsScalar()) fail(field(where, key) + ": expected a string, got " + describe(node));
    return node.Scalar();
  }

  Pose pose(const YAML::Node& map, const std::string& where, const char* key) const {
    const YAML::Node node = child(map, where, key);
    const std::string name = field(where, key);
    if (!node.IsSequence() || node.size() != 7)
      fail(name + ": expected [x, y, z, qx, qy, qz, qw], got " + describe(node));
    std::array<double, 7> v{};
    for (size_t i = 0; i < 7; ++i) v[i] = toNumber(node[i], name + "[" + std::to_string(i) + "]");
    // Normalising (fromXyzQuat) forgives rounded hand-written quaternions, but not a zero one.
    if (std::sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]) < 1e-9)
      fail(name + ": the quaternion (qx, qy, qz, qw) has zero length");
    return fromXyzQuat(v);
  }

  // A list of up to N numbers (missing ones are 0: four fisheye coefficients fill five).
  template <size_t N>
  std::array<double, N> numbers(const YAML::Node& map, const std::string& where,
                                const char* key) const {
    const YAML::Node node = child(map, where, key);
    const std::string name = field(where, key);
    if (!node.IsSequence() || node.size() > N)
      fail(name + ": expected a list of at most " + std::to_string(N) + " numbers, got " +
           describe(node));
    std::array<double, N> v{};
    for (size_t i = 0; i < node.size(); ++i)
      v[i] = toNumber(node[i], name + "[" + std::to_string(i) + "]");
    return v;
  }

  std::array<uint8_t, 3> color(const YAML::Node& map, const std::string& where,
                               const char* key) const {
    const YAML::Node node = child(map, where, key);
    const std::string name = field(where, key);
    if (!node.IsSequence() || node.size() != 3)
      fail(name + ": expected [r, g, b], got " + describe(node));
    std::array<uint8_t, 3> rgb{};
    for (size_t i = 0; i < 3; ++i)
      rgb[i] =
          static_cast<uint8_t>(toInteger(node[i], name + "[" + std::to_string(i) + "]", 0, 255));
    return rgb;
  }

  static std::string field(const std::string& where, const char* key) {
    return where.empty() ? key : where + "." + key;
  }

  static std::string describe(const YAML::Node& node) {
    if (node.IsScalar()) return "'" + shownText(node.Scalar()) + "'";
    if (node.IsSequence()) return "a list";
    if (node.IsMap()) return "a mapping";
    return "nothing";
  }

  double toNumber(const YAML::Node& node, const std::string& name) const {
    double value = 0;
    if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value))
      fail(name + ": expected a finite number, got " + describe(node));
    return value;
  }

  long long toInteger(const YAML::Node& node, const std::string& name, long long lo,
                      long long hi) const {
    long long value = 0;
    if (!node.IsScalar() || !YAML::convert<long long>::decode(node, value))
      fail(name + ": expected an integer, got " + describe(node));
    if (value < lo || value > hi)
      fail(name + ": " + std::to_string(value) + " is outside [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
    return value;
  }

 private:
  std::string path_;
};

// The beam pattern, ranges and noise of `node` (the `lidar` mapping of meta.yaml or a rig file)
// into `lidar`: each key is optional and keeps the model's value when absent.
void readOptionalLidarModel(const YamlFields& p, const YAML::Node& node, const std::string& where,
                            LidarModel& lidar);

}  // namespace semsegmap
