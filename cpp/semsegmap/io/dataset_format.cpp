#include "semsegmap/io/dataset_format.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/yaml_fields.h"

namespace semsegmap {
namespace fs = std::filesystem;

// The .bin files are defined as little-endian; copying floats byte-for-byte is only right on a
// little-endian host, which every platform this project targets is.
static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the .bin readers assume little-endian");
static_assert(std::numeric_limits<float>::is_iec559, "the .bin files hold IEEE-754 float32");

const char* const kFramesCsvHeader =
    "index,timestamp_s,odom_x,odom_y,odom_z,odom_qx,odom_qy,odom_qz,odom_qw,"
    "gt_x,gt_y,gt_z,gt_qx,gt_qy,gt_qz,gt_qw";

std::string imageSizeText(int width, int height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string frameFileName(size_t index, const std::string& extension) {
  char digits[32];
  std::snprintf(digits, sizeof(digits), "%06zu", index);
  // Accept "png" and ".png" alike; callers have written both.
  return std::string(digits) + (extension.rfind('.', 0) == 0 ? "" : ".") + extension;
}

void checkLabelClasses(const fs::path& path, const std::vector<PointLabel>& labels,
                       const ClassTable& classes) {
  std::vector<bool> known(65536, false);
  for (const auto& c : classes.classes()) known[c.id] = true;
  for (size_t i = 0; i < labels.size(); ++i)
    if (!known[labels[i].class_id])
      throw std::runtime_error(path.string() + ": point " + std::to_string(i) + " has class " +
                               std::to_string(labels[i].class_id) +
                               ", which is not in the class table");
}

void checkLabelClasses(const fs::path& path, const Image& label_image, const ClassTable& classes) {
  bool known[256] = {};
  for (const auto& c : classes.classes())
    if (c.id < 256) known[c.id] = true;
  for (int y = 0; y < label_image.height; ++y)
    for (int x = 0; x < label_image.width; ++x) {
      const uint8_t id = *label_image.at(x, y);
      if (!known[id])
        throw std::runtime_error(path.string() + ": pixel (" + std::to_string(x) + ", " +
                                 std::to_string(y) + ") has class " + std::to_string(id) +
                                 ", which is not in the class table");
    }
}

// ---------------------------------------------------------------------------------------------
// meta.yaml

namespace {

void emitDouble(YAML::Emitter& out, const fs::path& path, const char* field, double value) {
  // A non-finite value would be written but then rejected on reading; refuse it here instead.
  if (!std::isfinite(value))
    throw std::invalid_argument(path.string() + ": " + field + " is not a finite number");
  out << formatExactDouble(value);
}

void emitPose(YAML::Emitter& out, const fs::path& path, const char* field, const Pose& T) {
  out << YAML::Flow << YAML::BeginSeq;
  for (double v : toXyzQuat(T)) emitDouble(out, path, field, v);
  out << YAML::EndSeq;
}

// Only T_base_lidar is required: the beam pattern, ranges and noise describe the simulated
// sensor and are kept for the simulator and the contact sheet; a real recording leaves them
// out and gets the defaults, which nothing downstream of the scans reads.
LidarModel parseLidar(const YamlFields& p, const YAML::Node& node, Pose& T_base_lidar) {
  const std::string w = "lidar";
  p.expectMap(node, w);
  p.checkKeys(node, w,
              {"columns", "rows", "hfov_deg", "vfov_up_deg", "vfov_down_deg", "min_range_m",
               "max_range_m", "range_noise_m", "dropout", "T_base_lidar"});
  LidarModel lidar;
  readOptionalLidarModel(p, node, w, lidar);
  T_base_lidar = p.pose(node, w, "T_base_lidar");
  return lidar;
}

Camera parseCamera(const YamlFields& p, const YAML::Node& node, const std::string& w) {
  p.expectMap(node, w);
  p.checkKeys(
      node, w,
      {"name", "width", "height", "fx", "fy", "cx", "cy", "model", "distortion", "T_camera_lidar"});
  Camera cam;
  cam.name = p.text(node, w, "name");
  // Sizes are range-checked by SensorRig::validate(), which says what is expected.
  cam.width =
      static_cast<int>(p.integer(node, w, "width", -YamlFields::kMaxInt, YamlFields::kMaxInt));
  cam.height =
      static_cast<int>(p.integer(node, w, "height", -YamlFields::kMaxInt, YamlFields::kMaxInt));
  cam.fx = p.number(node, w, "fx");
  cam.fy = p.number(node, w, "fy");
  cam.cx = p.number(node, w, "cx");
  cam.cy = p.number(node, w, "cy");
  if (node["model"]) {  // optional: rectified pinhole images need neither key
    try {
      cam.model = parseCameraModel(p.text(node, w, "model"));
    } catch (const std::invalid_argument& e) {
      p.fail(YamlFields::field(w, "model") + ": " + e.what());
    }
    cam.distortion = p.numbers<5>(node, w, "distortion");
  }
  cam.T_camera_lidar = p.pose(node, w, "T_camera_lidar");
  return cam;
}

// A sensor more than this far from the base (or the LiDAR from a camera) is no rig: such a pose
// (1e308, say) is finite, so it passed, and the run found 0 segments with exit 0.
constexpr double kMaxExtrinsicM = 100.0;

void checkExtrinsic(const YamlFields& p, const std::string& field, const Pose& T) {
  const Eigen::Vector3d t = T.translation();
  if (!(t.stableNorm() <= kMaxExtrinsicM))  // stableNorm: 1e308 does not overflow to inf
    p.fail(field + ": translation [" + formatExactDouble(t.x()) + ", " + formatExactDouble(t.y()) +
           ", " + formatExactDouble(t.z()) + "] m: more than " + formatExactDouble(kMaxExtrinsicM) +
           " m is no sensor rig");
  if (!T.linear().allFinite()) p.fail(field + ": rotation is not finite");
}

SemanticClass parseClass(const YamlFields& p, const YAML::Node& node, const std::string& w) {
  p.expectMap(node, w);
  p.checkKeys(node, w, {"id", "name", "color", "dynamic", "ground"});
  SemanticClass c;
  c.id = static_cast<ClassId>(p.integer(node, w, "id", 0, std::numeric_limits<ClassId>::max()));
  c.name = p.text(node, w, "name");
  c.color_rgb = p.color(node, w, "color");
  c.dynamic = p.flag(node, w, "dynamic");
  c.ground = p.flag(node, w, "ground");
  return c;
}

}  // namespace

void writeMetaYaml(const fs::path& path, const DatasetInfo& info) {
  try {
    info.rig.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path.string() + ": " + e.what());
  }
  const SensorRig& rig = info.rig;
  const LidarModel& lidar = rig.lidar;

  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "format_version" << YAML::Value << kDatasetFormatVersion;
  // Quoted so that a name like "true" or "123" reads back as the same string.
  out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << info.name;
  out << YAML::Key << "rate_hz" << YAML::Value;
  emitDouble(out, path, "rate_hz", rig.rate_hz);
  out << YAML::Key << "has_ground_truth_poses" << YAML::Value << info.has_ground_truth_poses;
  out << YAML::Key << "has_point_labels" << YAML::Value << info.has_point_labels;
  out << YAML::Key << "has_odometry" << YAML::Value << info.has_odometry;
  // Only when true: a dataset converted from SemanticKITTI keeps saying that its odometry is
  // its ground truth, and other datasets read in builds that do not know the key.
  if (info.odometry_is_ground_truth)
    out << YAML::Key << "odometry_is_ground_truth" << YAML::Value << true;
  if (info.first_transient_instance > 0)
    out << YAML::Key << "first_transient_instance" << YAML::Value << info.first_transient_instance;

  out << YAML::Key << "lidar" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "columns" << YAML::Value << lidar.columns;
  out << YAML::Key << "rows" << YAML::Value << lidar.rows;
  const std::pair<const char*, double> lidar_numbers[] = {{"hfov_deg", lidar.hfov_deg},
                                                          {"vfov_up_deg", lidar.vfov_up_deg},
                                                          {"vfov_down_deg", lidar.vfov_down_deg},
                                                          {"min_range_m", lidar.min_range_m},
                                                          {"max_range_m", lidar.max_range_m},
                                                          {"range_noise_m", lidar.range_noise_m},
                                                          {"dropout", lidar.dropout}};
  for (const auto& [key, value] : lidar_numbers) {
    out << YAML::Key << key << YAML::Value;
    emitDouble(out, path, key, value);
  }
  out << YAML::Key << "T_base_lidar" << YAML::Value;
  emitPose(out, path, "lidar.T_base_lidar", rig.T_base_lidar);
  out << YAML::EndMap;

  out << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const auto& cam : rig.cameras) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << cam.name;
    out << YAML::Key << "width" << YAML::Value << cam.width;
    out << YAML::Key << "height" << YAML::Value << cam.height;
    const std::pair<const char*, double> intrinsics[] = {
        {"fx", cam.fx}, {"fy", cam.fy}, {"cx", cam.cx}, {"cy", cam.cy}};
    for (const auto& [key, value] : intrinsics) {
      out << YAML::Key << key << YAML::Value;
      emitDouble(out, path, key, value);
    }
    if (cam.model != CameraModel::kPinhole) {
      out << YAML::Key << "model" << YAML::Value << cameraModelName(cam.model);
      out << YAML::Key << "distortion" << YAML::Value << YAML::Flow << YAML::BeginSeq;
      const size_t n = cam.model == CameraModel::kEquidistant ? 4 : 5;
      for (size_t i = 0; i < n; ++i) emitDouble(out, path, "distortion", cam.distortion[i]);
      out << YAML::EndSeq;
    }
    out << YAML::Key << "T_camera_lidar" << YAML::Value;
    emitPose(out, path, "T_camera_lidar", cam.T_camera_lidar);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;

  // One line per class keeps the table readable at a glance.
  out << YAML::Key << "classes" << YAML::Value << YAML::BeginSeq;
  for (const auto& c : info.classes.classes()) {
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "id" << YAML::Value << c.id;
    out << YAML::Key << "name" << YAML::Value << YAML::DoubleQuoted << c.name;
    out << YAML::Key << "color" << YAML::Value << YAML::Flow << YAML::BeginSeq
        << static_cast<int>(c.color_rgb[0]) << static_cast<int>(c.color_rgb[1])
        << static_cast<int>(c.color_rgb[2]) << YAML::EndSeq;
    out << YAML::Key << "dynamic" << YAML::Value << c.dynamic;
    out << YAML::Key << "ground" << YAML::Value << c.ground;
    out << YAML::EndMap;
  }
  out << YAML::EndSeq;
  out << YAML::EndMap;

  if (!out.good())
    throw std::runtime_error(path.string() + ": YAML emitter: " + out.GetLastError());
  writeFileAtomically(path, [&out](std::ostream& s) { s << out.c_str() << '\n'; });
}

DatasetInfo readMetaYaml(const fs::path& path) {
  const YamlFields p(path);
  const YAML::Node root = loadYamlFile(path);
  if (!root.IsMap()) p.fail("expected a YAML mapping at the top level");

  // The version comes first: a newer file may well have keys this build does not know.
  const long long version =
      p.integer(root, "", "format_version", 0, std::numeric_limits<int>::max());
  if (version != kDatasetFormatVersion)
    p.fail("format_version is " + std::to_string(version) + ", but this build reads version " +
           std::to_string(kDatasetFormatVersion));
  p.checkKeys(root, "",
              {"format_version", "name", "rate_hz", "has_ground_truth_poses", "has_point_labels",
               "has_odometry", "odometry_is_ground_truth", "first_transient_instance", "lidar",
               "cameras", "classes"});

  DatasetInfo info;
  info.name = p.text(root, "", "name");
  info.rig.rate_hz = p.number(root, "", "rate_hz");
  info.has_ground_truth_poses = p.flag(root, "", "has_ground_truth_poses");
  info.has_point_labels = p.flag(root, "", "has_point_labels");
  // Optional: datasets written before the key existed always had odometry in frames.csv.
  info.has_odometry = root["has_odometry"] ? p.flag(root, "", "has_odometry") : true;
  if (root["odometry_is_ground_truth"])
    info.odometry_is_ground_truth = p.flag(root, "", "odometry_is_ground_truth");
  if (root["first_transient_instance"])  // optional: datasets without traffic ids lack it
    info.first_transient_instance = static_cast<uint16_t>(
        p.integer(root, "", "first_transient_instance", 0, std::numeric_limits<uint16_t>::max()));
  info.rig.lidar = parseLidar(p, p.child(root, "", "lidar"), info.rig.T_base_lidar);

  const YAML::Node cameras = p.child(root, "", "cameras");
  if (!cameras.IsSequence()) p.fail("cameras: expected a list");
  for (size_t i = 0; i < cameras.size(); ++i)
    info.rig.cameras.push_back(parseCamera(p, cameras[i], "cameras[" + std::to_string(i) + "]"));

  const YAML::Node classes = p.child(root, "", "classes");
  if (!classes.IsSequence()) p.fail("classes: expected a list");
  std::vector<SemanticClass> table;
  for (size_t i = 0; i < classes.size(); ++i)
    table.push_back(parseClass(p, classes[i], "classes[" + std::to_string(i) + "]"));

  checkExtrinsic(p, "lidar.T_base_lidar", info.rig.T_base_lidar);
  for (size_t i = 0; i < info.rig.cameras.size(); ++i)
    checkExtrinsic(p, "cameras[" + std::to_string(i) + "].T_camera_lidar",
                   info.rig.cameras[i].T_camera_lidar);
  try {
    info.classes = ClassTable(std::move(table));
    info.rig.validate();
  } catch (const std::invalid_argument& e) {
    p.fail(e.what());
  }
  return info;
}

// ---------------------------------------------------------------------------------------------
// LiDAR scans and point labels

void writeLidarBin(const fs::path& path, const std::vector<LidarPoint>& points) {
  std::string bytes(points.size() * 16, '\0');
  for (size_t i = 0; i < points.size(); ++i) {
    const LidarPoint& p = points[i];
    // Refused here because the reader refuses it: a dataset must always read back.
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) ||
        !std::isfinite(p.intensity))
      throw std::invalid_argument(path.string() + ": point " + std::to_string(i) +
                                  " has a non-finite coordinate or intensity");
    const float values[4] = {p.x, p.y, p.z, p.intensity};
    std::memcpy(&bytes[i * 16], values, 16);
  }
  writeBytesAtomically(path, bytes);
}

std::vector<LidarPoint> readLidarBin(const fs::path& path) {
  const std::string bytes = readFileBytes(path);
  if (bytes.size() % 16 != 0)
    throw std::runtime_error(path.string() + ": truncated (" + std::to_string(bytes.size()) +
                             " bytes is not a multiple of 16)");
  std::vector<LidarPoint> points(bytes.size() / 16);
  for (size_t i = 0; i < points.size(); ++i) {
    float v[4];
    std::memcpy(v, &bytes[i * 16], 16);
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
      throw std::runtime_error(path.string() + ": point " + std::to_string(i) +
                               " has a non-finite coordinate");
    if (!std::isfinite(v[3]))
      throw std::runtime_error(path.string() + ": point " + std::to_string(i) +
                               " has a non-finite intensity");
    points[i] = {v[0], v[1], v[2], v[3]};
  }
  return points;
}

void writePointTimesBin(const fs::path& path, const std::vector<float>& times) {
  for (size_t i = 0; i < times.size(); ++i)
    if (!std::isfinite(times[i]))
      throw std::invalid_argument(path.string() + ": point " + std::to_string(i) +
                                  " has a non-finite time");
  std::string bytes(times.size() * 4, '\0');
  if (!times.empty()) std::memcpy(&bytes[0], times.data(), bytes.size());
  writeBytesAtomically(path, bytes);
}

std::vector<float> readPointTimesBin(const fs::path& path) {
  const std::string bytes = readFileBytes(path);
  if (bytes.size() % 4 != 0)
    throw std::runtime_error(path.string() + ": truncated (" + std::to_string(bytes.size()) +
                             " bytes is not a multiple of 4)");
  std::vector<float> times(bytes.size() / 4);
  if (!times.empty()) std::memcpy(times.data(), bytes.data(), bytes.size());
  for (size_t i = 0; i < times.size(); ++i)
    if (!std::isfinite(times[i]))
      throw std::runtime_error(path.string() + ": point " + std::to_string(i) +
                               " has a non-finite time");
  return times;
}

void writeLabelBin(const fs::path& path, const std::vector<PointLabel>& labels) {
  std::string bytes(labels.size() * 4, '\0');
  for (size_t i = 0; i < labels.size(); ++i) {
    const uint32_t word = static_cast<uint32_t>(labels[i].class_id) |
                          (static_cast<uint32_t>(labels[i].instance_id) << 16);
    std::memcpy(&bytes[i * 4], &word, 4);
  }
  writeBytesAtomically(path, bytes);
}

std::vector<PointLabel> readLabelBin(const fs::path& path) {
  const std::string bytes = readFileBytes(path);
  if (bytes.size() % 4 != 0)
    throw std::runtime_error(path.string() + ": truncated (" + std::to_string(bytes.size()) +
                             " bytes is not a multiple of 4)");
  std::vector<PointLabel> labels(bytes.size() / 4);
  for (size_t i = 0; i < labels.size(); ++i) {
    uint32_t word = 0;
    std::memcpy(&word, &bytes[i * 4], 4);
    labels[i].class_id = static_cast<ClassId>(word & 0xffffu);
    labels[i].instance_id = static_cast<uint16_t>(word >> 16);
  }
  return labels;
}

}  // namespace semsegmap
