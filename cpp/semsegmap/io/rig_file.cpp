#include "semsegmap/io/rig_file.h"

#include <limits>
#include <stdexcept>

#include "semsegmap/io/yaml_fields.h"

namespace semsegmap {

namespace {

// A list of numbers, flat or as rows: [[a, b], [c, d]] and [a, b, c, d] both give a b c d.
std::vector<double> flatNumbers(const YamlFields& p, const YAML::Node& node,
                                const std::string& name) {
  if (!node.IsSequence()) p.fail(name + ": expected a list of numbers, got " + p.describe(node));
  std::vector<double> values;
  for (size_t i = 0; i < node.size(); ++i) {
    const std::string at = name + "[" + std::to_string(i) + "]";
    if (node[i].IsSequence()) {
      for (size_t j = 0; j < node[i].size(); ++j)
        values.push_back(p.toNumber(node[i][j], at + "[" + std::to_string(j) + "]"));
    } else {
      values.push_back(p.toNumber(node[i], at));
    }
  }
  return values;
}

// A rigid transform: a 4x4 matrix (rows or 16 numbers, last row 0 0 0 1), or a translation
// with a quaternion whose order is in its key.
Pose parseTransform(const YamlFields& p, const YAML::Node& node, const std::string& name) {
  if (node.IsSequence()) {
    const std::vector<double> m = flatNumbers(p, node, name);
    if (m.size() != 16)
      p.fail(name + ": expected a 4x4 matrix, got " + std::to_string(m.size()) + " numbers");
    Eigen::Matrix4d M;
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) M(r, c) = m[static_cast<size_t>(4 * r + c)];
    if ((M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
      p.fail(name + ": the last row of a rigid transform is 0 0 0 1");
    Pose T = Pose::Identity();
    T.matrix() = M;
    return T;
  }
  p.expectMap(node, name);
  p.checkKeys(node, name, {"translation", "quaternion_xyzw", "quaternion_wxyz"});
  const std::vector<double> t =
      flatNumbers(p, p.child(node, name, "translation"), name + ".translation");
  if (t.size() != 3) p.fail(name + ".translation: expected [x, y, z]");
  const bool xyzw = node["quaternion_xyzw"].IsDefined();
  if (xyzw == node["quaternion_wxyz"].IsDefined())
    p.fail(name + ": give exactly one of quaternion_xyzw and quaternion_wxyz");
  const char* key = xyzw ? "quaternion_xyzw" : "quaternion_wxyz";
  const std::vector<double> q = flatNumbers(p, node[key], name + "." + key);
  if (q.size() != 4) p.fail(name + "." + key + ": expected four numbers");
  const Eigen::Quaterniond quat = xyzw ? Eigen::Quaterniond(q[3], q[0], q[1], q[2])
                                       : Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  if (quat.norm() < 1e-9) p.fail(name + "." + key + ": the quaternion has zero length");
  Pose T = Pose::Identity();
  T.linear() = quat.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return T;
}

// T_a_b from whichever of "T_a_b" and "T_b_a" the mapping has (exactly one, or none when
// optional); false when absent.
bool parseDirected(const YamlFields& p, const YAML::Node& map, const std::string& where,
                   const std::string& a, const std::string& b, Pose& T_a_b) {
  const std::string forward = "T_" + a + "_" + b, backward = "T_" + b + "_" + a;
  const bool has_forward = map[forward].IsDefined(), has_backward = map[backward].IsDefined();
  if (has_forward && has_backward)
    p.fail(YamlFields::field(where, forward.c_str()) + ": give " + forward + " or " + backward +
           ", not both");
  if (has_forward)
    T_a_b = parseTransform(p, map[forward], YamlFields::field(where, forward.c_str()));
  if (has_backward)
    T_a_b = parseTransform(p, map[backward], YamlFields::field(where, backward.c_str())).inverse();
  return has_forward || has_backward;
}

std::string optionalText(const YamlFields& p, const YAML::Node& map, const std::string& where,
                         const char* key) {
  return map[key] ? p.text(map, where, key) : std::string();
}

void parseIntrinsics(const YamlFields& p, const YAML::Node& node, const std::string& w,
                     Camera& cam) {
  if (node["K"]) {
    if (node["fx"] || node["fy"] || node["cx"] || node["cy"])
      p.fail(w + ": give K or fx fy cx cy, not both");
    const std::vector<double> K = flatNumbers(p, node["K"], w + ".K");
    if (K.size() != 9 || K[1] != 0.0 || K[3] != 0.0 || K[6] != 0.0 || K[7] != 0.0 || K[8] != 1.0)
      p.fail(w + ".K: expected the 3x3 matrix [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]");
    cam.fx = K[0];
    cam.cx = K[2];
    cam.fy = K[4];
    cam.cy = K[5];
    return;
  }
  cam.fx = p.number(node, w, "fx");
  cam.fy = p.number(node, w, "fy");
  cam.cx = p.number(node, w, "cx");
  cam.cy = p.number(node, w, "cy");
}

void parseLens(const YamlFields& p, const YAML::Node& node, const std::string& w, Camera& cam) {
  if (!node["model"]) {
    if (node["distortion"]) p.fail(w + ".distortion: give the model it belongs to (model: radtan)");
    return;
  }
  try {
    cam.model = parseCameraModel(p.text(node, w, "model"));
  } catch (const std::invalid_argument& e) {
    p.fail(YamlFields::field(w, "model") + ": " + e.what());
  }
  if (cam.model == CameraModel::kPinhole) return;
  const std::vector<double> d = flatNumbers(p, p.child(node, w, "distortion"), w + ".distortion");
  // OpenCV writes radial-tangential as 4, 5 (or more, for models this project lacks) numbers.
  const size_t expected_max = cam.model == CameraModel::kEquidistant ? 4 : 5;
  if (d.size() < 4 || d.size() > expected_max)
    p.fail(w + ".distortion: expected " +
           (cam.model == CameraModel::kEquidistant ? std::string("k1 k2 k3 k4")
                                                   : std::string("k1 k2 p1 p2 [k3]")) +
           ", got " + std::to_string(d.size()) + " numbers");
  for (size_t i = 0; i < d.size(); ++i) cam.distortion[i] = d[i];
}

Camera parseCamera(const YamlFields& p, const YAML::Node& node, const std::string& w,
                   RigFile& rig) {
  p.expectMap(node, w);
  p.checkKeys(node, w,
              {"name", "topic", "folder", "width", "height", "K", "fx", "fy", "cx", "cy", "model",
               "distortion", "T_camera_lidar", "T_lidar_camera"});
  Camera cam;
  cam.name = p.text(node, w, "name");
  cam.width = static_cast<int>(p.integer(node, w, "width", 1, kMaxCameraSide));
  cam.height = static_cast<int>(p.integer(node, w, "height", 1, kMaxCameraSide));
  parseIntrinsics(p, node, w, cam);
  parseLens(p, node, w, cam);
  if (!parseDirected(p, node, w, "camera", "lidar", cam.T_camera_lidar))
    p.fail(w + ": missing the extrinsic (T_camera_lidar or T_lidar_camera)");
  rig.camera_topics.push_back(optionalText(p, node, w, "topic"));
  const std::string folder = optionalText(p, node, w, "folder");
  rig.camera_folders.push_back(folder.empty() ? cam.name : folder);
  return cam;
}

void parseLidar(const YamlFields& p, const YAML::Node& node, RigFile& rig) {
  const std::string w = "lidar";
  p.expectMap(node, w);
  p.checkKeys(
      node, w,
      {"topic", "folder", "T_base_lidar", "T_lidar_base", "columns", "rows", "hfov_deg",
       "vfov_up_deg", "vfov_down_deg", "min_range_m", "max_range_m", "range_noise_m", "dropout"});
  rig.lidar_topic = optionalText(p, node, w, "topic");
  rig.lidar_folder = optionalText(p, node, w, "folder");
  rig.base_is_lidar = !parseDirected(p, node, w, "base", "lidar", rig.rig.T_base_lidar);
  readOptionalLidarModel(p, node, w, rig.rig.lidar);
}

}  // namespace

RigFile readRigFile(const std::filesystem::path& path) {
  const YamlFields p(path);
  const YAML::Node root = loadYamlFile(path);
  p.checkKeys(root, "", {"rig_format_version", "name", "rate_hz", "lidar", "cameras"});
  const long long version = p.integer(root, "", "rig_format_version", 0, YamlFields::kMaxInt);
  if (version != 1)
    p.fail("rig_format_version is " + std::to_string(version) + ", this build reads version 1");
  RigFile rig;
  rig.name = optionalText(p, root, "", "name");
  rig.rig.rate_hz = root["rate_hz"] ? p.number(root, "", "rate_hz") : 10.0;
  rig.rig.lidar.hfov_deg = 360.0;  // a spinning LiDAR unless the file says otherwise
  if (root["lidar"]) parseLidar(p, root["lidar"], rig);
  if (root["cameras"]) {
    const YAML::Node cameras = root["cameras"];
    if (!cameras.IsSequence()) p.fail("cameras: expected a list");
    for (size_t i = 0; i < cameras.size(); ++i)
      rig.rig.cameras.push_back(
          parseCamera(p, cameras[i], "cameras[" + std::to_string(i) + "]", rig));
  }
  for (size_t i = 0; i < rig.rig.cameras.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (rig.rig.cameras[i].name == rig.rig.cameras[j].name)
        p.fail("cameras[" + std::to_string(i) + "].name: '" + rig.rig.cameras[i].name +
               "' is used twice");
  try {
    rig.rig.validate();
  } catch (const std::invalid_argument& e) {
    p.fail(e.what());
  }
  return rig;
}

}  // namespace semsegmap
