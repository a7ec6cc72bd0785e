// semsegmap info: what a dataset or bag holds and what its reader picked (the topics, files and
// pose files, and how poses were matched), in a few lines, before a long run on it. The readers
// say where each part comes from (DatasetInfo::origin); frame 0 is read for what only a scan
// shows. --json FILE writes the same as JSON.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "semsegmap/core/json.h"

namespace semsegmap::app {

namespace {

using Json = nlohmann::ordered_json;

std::string fixed(double value, int decimals) {
  char text[64];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  const std::string shown = text;
  // "-0.00" for a rounding error below zero reads as a sign that means something.
  if (shown[0] == '-' && shown.find_first_not_of("-0.") == std::string::npos)
    return shown.substr(1);
  return shown;
}

// The translation in metres and roll, pitch, yaw in degrees (R = Rz(yaw) Ry(pitch) Rx(roll)),
// the way extrinsics are usually read off a drawing of the rig.
Json poseJson(const Pose& T) {
  const Eigen::Matrix3d R = T.linear();
  const double deg = 180.0 / M_PI;
  const double pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  double roll = std::atan2(R(2, 1), R(2, 2)), yaw = std::atan2(R(1, 0), R(0, 0));
  if (std::abs(R(2, 0)) > 1.0 - 1e-9) {  // pitch +-90: only roll -+ yaw is defined; yaw 0
    yaw = 0.0;
    roll = std::atan2(-R(2, 0) * R(0, 1), R(1, 1));
  }
  const Eigen::Vector3d t = T.translation();
  return {{"xyz_m", {t.x(), t.y(), t.z()}}, {"rpy_deg", {roll * deg, pitch * deg, yaw * deg}}};
}

std::string poseText(const Json& pose) {
  auto three = [](const Json& v, int decimals) {
    return fixed(v[0], decimals) + " " + fixed(v[1], decimals) + " " + fixed(v[2], decimals);
  };
  return "xyz " + three(pose["xyz_m"], 3) + " m, rpy " + three(pose["rpy_deg"], 2) + " deg";
}

// A text for the JSON: null when empty (the dataset has no such part).
Json textOrNull(const std::string& text) {
  return text.empty() ? Json(nullptr) : Json(text);
}

Json framesJson(FrameSource& source) {
  const size_t n = source.size();
  const double first = n > 0 ? source.frameTime(0) : 0.0;
  const double last = n > 0 ? source.frameTime(n - 1) : 0.0;
  return {{"count", n},
          {"first_time_s", first},
          {"last_time_s", last},
          {"span_s", last - first},
          {"times_from_data", source.info().has_frame_times}};
}

Json lidarJson(const DatasetInfo& info, const Frame& first) {
  Json j = {{"source", textOrNull(info.origin.lidar)},
            {"points_in_frame_0", first.points.size()},
            {"point_times", !first.point_times.empty()},
            {"rate_hz", info.rig.rate_hz}};
  if (!info.rig.T_base_lidar.isApprox(Pose::Identity()))
    j["T_base_lidar"] = poseJson(info.rig.T_base_lidar);
  return j;
}

Json cameraJson(const DatasetInfo& info, const Frame& first, size_t k) {
  const Camera& c = info.rig.cameras[k];
  const bool labelled = k < first.cameras.size() && !first.cameras[k].label.empty();
  Json j = {{"name", c.name},
            {"source", textOrNull(k < info.origin.cameras.size() ? info.origin.cameras[k] : "")},
            {"width", c.width},
            {"height", c.height},
            {"model", cameraModelName(c.model)},
            {"fx", c.fx},
            {"fy", c.fy},
            {"cx", c.cx},
            {"cy", c.cy}};
  if (c.model != CameraModel::kPinhole) j["distortion"] = c.distortion;
  j["T_camera_lidar"] = poseJson(c.T_camera_lidar);
  // Its inverse, where the camera sits on the LiDAR: easier to check against the rig, and its
  // angles are not in gimbal lock as a forward-looking camera's T_camera_lidar is.
  j["T_lidar_camera"] = poseJson(c.T_camera_lidar.inverse());
  j["label_image_in_frame_0"] = labelled;
  return j;
}

Json describe(const std::string& spec, FrameSource& source) {
  const DatasetInfo& info = source.info();
  const Frame first = source.frame(0);
  Json j = {{"spec", spec}, {"name", info.name}, {"kind", textOrNull(info.origin.kind)}};
  j["frames"] = framesJson(source);
  j["lidar"] = lidarJson(info, first);
  j["cameras"] = Json::array();
  for (size_t k = 0; k < info.rig.cameras.size(); ++k)
    j["cameras"].push_back(cameraJson(info, first, k));
  j["odometry"] = {{"source", info.has_odometry ? textOrNull(info.origin.odometry) : nullptr},
                   {"is_ground_truth", info.odometry_is_ground_truth}};
  j["ground_truth"] = {
      {"source", info.has_ground_truth_poses ? textOrNull(info.origin.ground_truth) : nullptr}};
  j["labels"] = {
      {"images", textOrNull(info.origin.label_images)},
      {"per_point", info.has_point_labels ? textOrNull(info.origin.point_labels) : nullptr},
      {"per_point_classes", info.has_point_labels && info.point_labels_have_classes}};
  return j;
}

// A part the dataset has but whose reader said nothing about its origin.
std::string sourceText(const Json& source) {
  return source.is_null() ? "(the dataset's)" : source.get<std::string>();
}

void printFrames(const Json& f) {
  std::printf("frames: %zu over %s s (%s to %s%s)\n", f["count"].get<size_t>(),
              fixed(f["span_s"], 2).c_str(), fixed(f["first_time_s"], 3).c_str(),
              fixed(f["last_time_s"], 3).c_str(),
              f["times_from_data"].get<bool>() ? "" : ", times made up from the rate");
}

void printSensors(const Json& j) {
  const Json& l = j["lidar"];
  std::printf(
      "lidar: %s; %zu points in frame 0%s, %s Hz%s\n", sourceText(l["source"]).c_str(),
      l["points_in_frame_0"].get<size_t>(),
      l["point_times"].get<bool>() ? " with per-point times" : "", fixed(l["rate_hz"], 1).c_str(),
      l.contains("T_base_lidar") ? ("; on the base at " + poseText(l["T_base_lidar"])).c_str()
                                 : "");
  for (const Json& c : j["cameras"]) {
    std::string lens = c["model"].get<std::string>() + " fx " + fixed(c["fx"], 2) + " fy " +
                       fixed(c["fy"], 2) + " cx " + fixed(c["cx"], 2) + " cy " + fixed(c["cy"], 2);
    if (c.contains("distortion"))
      for (const Json& k : c["distortion"]) lens += " " + fixed(k, 4);
    std::printf("camera %s: %s; %dx%d %s; T_camera_lidar %s; T_lidar_camera %s\n",
                c["name"].get<std::string>().c_str(), sourceText(c["source"]).c_str(),
                c["width"].get<int>(), c["height"].get<int>(), lens.c_str(),
                poseText(c["T_camera_lidar"]).c_str(), poseText(c["T_lidar_camera"]).c_str());
  }
  if (j["cameras"].empty()) std::printf("cameras: none (geometry only)\n");
}

void printPosesAndLabels(const Json& j) {
  const Json& odometry = j["odometry"]["source"];
  std::printf("odometry: %s\n",
              odometry.is_null()
                  ? "none (give --odometry FILE, or --odometry lidar)"
                  : (odometry.get<std::string>() + (j["odometry"]["is_ground_truth"].get<bool>()
                                                        ? ", the ground truth serving as odometry"
                                                        : ""))
                        .c_str());
  const Json& truth = j["ground_truth"]["source"];
  std::printf("ground truth: %s\n", truth.is_null() ? "none" : truth.get<std::string>().c_str());
  const Json& l = j["labels"];
  std::string labels;
  if (!l["images"].is_null()) {
    size_t labelled = 0;
    for (const Json& c : j["cameras"]) labelled += c["label_image_in_frame_0"].get<bool>();
    labels = "images " + l["images"].get<std::string>() + " (" + std::to_string(labelled) + " of " +
             std::to_string(j["cameras"].size()) + " cameras in frame 0)";
  }
  if (!l["per_point"].is_null())
    labels += (labels.empty() ? "" : "; ") + std::string("per point ") +
              l["per_point"].get<std::string>() +
              (l["per_point_classes"].get<bool>() ? "" : " (no classes)");
  std::printf("labels: %s\n", labels.empty() ? "none" : labels.c_str());
}

int runInfo(const CliArgs& a) {
  auto source = openDatasetArg(a);
  const Json j = describe(a.get("dataset"), *source);
  std::printf("dataset: %s, read as %s\n", j["name"].get<std::string>().c_str(),
              sourceText(j["kind"]).c_str());
  printFrames(j["frames"]);
  printSensors(j);
  printPosesAndLabels(j);
  if (a.has("json")) {
    writeJsonAtomically(a.get("json"), j);
    std::printf("wrote %s\n", a.get("json").c_str());
  }
  return 0;
}

}  // namespace

const CommandSpec& infoCommand() {
  static const CommandSpec command{
      "info",
      "what a dataset or bag holds and what its reader picked: frames, sensors, poses, labels",
      datasetOptions("the dataset or bag to describe",
                     {{"json", Value::kText, "FILE", "", "also write what is printed as JSON"}}),
      kDatasetNotes, runInfo};
  return command;
}

}  // namespace semsegmap::app
