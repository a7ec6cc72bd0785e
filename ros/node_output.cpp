#include "node_output.h"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <visualization_msgs/Marker.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <Eigen/Geometry>

namespace semsegmap::ros_node {

namespace {

std::string required(const ros::NodeHandle& pnh, const std::string& name) {
  std::string value;
  if (!pnh.getParam(name, value) || value.empty())
    throw std::runtime_error("parameter " + pnh.resolveName(name) + " is required");
  return value;
}

geometry_msgs::Transform transformOf(const Pose& T) {
  geometry_msgs::Transform t;
  t.translation.x = T.translation().x();
  t.translation.y = T.translation().y();
  t.translation.z = T.translation().z();
  const Eigen::Quaterniond q(T.linear());
  t.rotation.x = q.x();
  t.rotation.y = q.y();
  t.rotation.z = q.z();
  t.rotation.w = q.w();
  return t;
}

geometry_msgs::TransformStamped stamped(const Pose& T, double stamp_s, const std::string& parent,
                                        const std::string& child) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(stamp_s);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform = transformOf(T);
  return t;
}

diagnostic_msgs::KeyValue keyValue(const std::string& key, double value) {
  diagnostic_msgs::KeyValue kv;
  kv.key = key;
  kv.value = std::to_string(value);
  return kv;
}

// Points x y z with an intensity each, in `frame`.
sensor_msgs::PointCloud2 cloudOf(const std::vector<std::pair<Eigen::Vector3f, float>>& points,
                                 const std::string& frame, const ros::Time& stamp) {
  sensor_msgs::PointCloud2 cloud;
  cloud.header.frame_id = frame;
  cloud.header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier modifier(cloud);
  modifier.setPointCloud2Fields(
      4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
      sensor_msgs::PointField::FLOAT32, "intensity", 1, sensor_msgs::PointField::FLOAT32);
  modifier.resize(points.size());
  sensor_msgs::PointCloud2Iterator<float> x(cloud, "x"), i(cloud, "intensity");
  for (const auto& [p, value] : points) {
    x[0] = p.x();
    x[1] = p.y();
    x[2] = p.z();
    *i = value;
    ++x;
    ++i;
  }
  return cloud;
}

}  // namespace

NodeParams readParams(const ros::NodeHandle& pnh) {
  NodeParams p;
  p.config = required(pnh, "config");
  p.map = required(pnh, "map");
  pnh.param<std::string>("mode", p.mode, "localize");
  if (p.mode != "localize" && p.mode != "map")
    throw std::runtime_error("~mode: expected localize or map, got '" + p.mode + "'");
  const std::filesystem::path folder = std::filesystem::path(p.map).parent_path();
  if (p.mode == "map" && !folder.empty() && !std::filesystem::is_directory(folder))
    throw std::runtime_error("~map " + p.map + ": no folder " + folder.string() +
                             " to write the map into");
  pnh.param<std::string>("lidar_topic", p.topics.lidar, "points");
  pnh.param<std::vector<std::string>>("camera_topics", p.topics.cameras, {});
  pnh.param<std::string>("base_frame", p.topics.base_frame, "base_link");
  pnh.param("lidar_rate_hz", p.topics.lidar_rate_hz, 10.0);
  pnh.param<std::string>("odometry_topic", p.odometry_topic, "");
  pnh.param<std::string>("odom_frame", p.odom_frame, "odom");
  pnh.param<std::string>("map_frame", p.map_frame, "map");
  pnh.param("relocalize", p.relocalize, false);
  pnh.param("max_queued_frames", p.max_queued_frames, 2);
  pnh.param("position_sigma_m", p.position_sigma_m, 0.1);
  pnh.param("rotation_sigma_deg", p.rotation_sigma_deg, 1.0);
  if (p.max_queued_frames < 1) throw std::runtime_error("~max_queued_frames must be at least 1");
  if (!(p.position_sigma_m > 0 && p.rotation_sigma_deg > 0))
    throw std::runtime_error("~position_sigma_m and ~rotation_sigma_deg must be positive");
  return p;
}

NodeOutput::NodeOutput(ros::NodeHandle& /*nh*/, ros::NodeHandle& pnh)
    : pose_(pnh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 100)),
      map_cloud_(pnh.advertise<sensor_msgs::PointCloud2>("map_segments", 1, /*latch=*/true)),
      diagnostics_(pnh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10)),
      local_segments_(pnh.advertise<sensor_msgs::PointCloud2>("local_segments", 10)),
      matches_(pnh.advertise<visualization_msgs::Marker>("matches", 10)) {}

void NodeOutput::publishMap(const TargetMap& map, const std::string& map_frame) {
  std::vector<std::pair<Eigen::Vector3f, float>> points;
  for (const MapSegment& s : map.segments)
    points.emplace_back(s.centroid, static_cast<float>(s.majority_class));
  map_cloud_.publish(cloudOf(points, map_frame, ros::Time::now()));
}

void NodeOutput::publishMatches(const LivePose& p, double stamp_s, const std::string& map_frame) {
  std::vector<std::pair<Eigen::Vector3f, float>> local;
  visualization_msgs::Marker lines;
  lines.header.frame_id = map_frame;
  lines.header.stamp = ros::Time(stamp_s);
  lines.ns = "semsegmap_matches";
  lines.type = visualization_msgs::Marker::LINE_LIST;
  lines.action = visualization_msgs::Marker::ADD;
  lines.pose.orientation.w = 1.0;
  lines.scale.x = 0.1;
  lines.color.g = lines.color.a = 1.0f;
  for (const auto& [from, to] : p.record.matches) {
    local.emplace_back(from, 0.0f);
    for (const Eigen::Vector3f& e : {from, to}) {
      geometry_msgs::Point point;
      point.x = e.x();
      point.y = e.y();
      point.z = e.z();
      lines.points.push_back(point);
    }
  }
  local_segments_.publish(cloudOf(local, map_frame, ros::Time(stamp_s)));
  matches_.publish(lines);
}

void NodeOutput::publishPose(const LivePose& p, double stamp_s, const NodeParams& params) {
  std::vector<geometry_msgs::TransformStamped> transforms = {
      stamped(p.T_map_odom, stamp_s, params.map_frame, params.odom_frame)};
  // Without an odometry topic the node's LiDAR odometry is the robot's odom -> base.
  if (params.odometry_topic.empty())
    transforms.push_back(
        stamped(p.T_odom_base, stamp_s, params.odom_frame, params.topics.base_frame));
  tf_.sendTransform(transforms);
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.stamp = ros::Time(stamp_s);
  pose.header.frame_id = params.map_frame;
  const geometry_msgs::Transform t = transformOf(p.record.T_map_base);
  pose.pose.pose.position.x = t.translation.x;
  pose.pose.pose.position.y = t.translation.y;
  pose.pose.pose.position.z = t.translation.z;
  pose.pose.pose.orientation = t.rotation;
  const double var_m = params.position_sigma_m * params.position_sigma_m;
  const double sigma_rad = params.rotation_sigma_deg * M_PI / 180.0;
  // The estimate's own covariance (ROS order already), each variance at least the floor's.
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) pose.pose.covariance[i * 6 + j] = p.record.covariance(i, j);
  for (int k = 0; k < 6; ++k)
    pose.pose.covariance[k * 7] =
        std::max(pose.pose.covariance[k * 7], k < 3 ? var_m : sigma_rad * sigma_rad);
  pose_.publish(pose);
  publishMatches(p, stamp_s, params.map_frame);
}

void NodeOutput::publishDiagnostics(const LiveStats& s, std::optional<double> last_pose_stamp_s) {
  const ros::WallTime now = ros::WallTime::now();
  const double elapsed = (now - last_diagnostics_).toSec();
  if (elapsed < 1.0) return;
  diagnostic_msgs::DiagnosticStatus status;
  status.name = "semsegmap";
  status.hardware_id = "semsegmap";
  status.level = s.dropped > 0 ? diagnostic_msgs::DiagnosticStatus::WARN
                               : diagnostic_msgs::DiagnosticStatus::OK;
  status.message = s.dropped > 0 ? "frames dropped: the pipeline falls behind" : "ok";
  const double hz = last_diagnostics_.isZero()
                        ? 0.0
                        : static_cast<double>(s.processed - processed_before_) / elapsed;
  status.values = {
      keyValue("frames_hz", hz),
      keyValue("latency_mean_ms", s.mean_latency_ms),
      keyValue("latency_max_ms", s.max_latency_ms),
      keyValue("scans", static_cast<double>(s.assembly.scans)),
      keyValue("dropped", static_cast<double>(s.dropped)),
      keyValue("pictures_missing", static_cast<double>(s.assembly.missing_pictures)),
      keyValue("scans_without_odometry", static_cast<double>(s.assembly.without_odometry)),
      keyValue("localized", static_cast<double>(s.localized))};
  if (last_pose_stamp_s)
    status.values.push_back(
        keyValue("last_localization_age_s", ros::Time::now().toSec() - *last_pose_stamp_s));
  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = ros::Time::now();
  array.status.push_back(status);
  diagnostics_.publish(array);
  last_diagnostics_ = now;
  processed_before_ = s.processed;
}

}  // namespace semsegmap::ros_node
