// The node's parameters and what it publishes, apart from how it gets its input.
#pragma once

#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <optional>
#include <string>

#include "node_rig.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/pipeline/live_session.h"

namespace semsegmap::ros_node {

// ~parameters, mirroring the command line and the config file (docs/ros.md).
struct NodeParams {
  std::string config;  // the pipeline configuration, the one the map was built with
  // "localize" against `map`, or "map": build one from the topics and write it to `map` on the
  // ~save_map service and at shutdown.
  std::string mode = "localize";
  std::string map;             // the target map (localize), or where the map is written (map)
  RigTopics topics;            // lidar_topic, camera_topics, base_frame, lidar_rate_hz
  std::string odometry_topic;  // nav_msgs/Odometry; empty: LiDAR odometry on the scans
  std::string odom_frame = "odom";
  std::string map_frame = "map";
  bool relocalize = false;    // localization.relocalization.enabled, as localize --relocalize
  int max_queued_frames = 2;  // frames waiting for the pipeline; more drops the oldest
  // Floors under a published pose's covariance, which the localization estimates from its own
  // evidence (localize/pose_covariance.h): position and rotation standard deviations.
  double position_sigma_m = 0.1;
  double rotation_sigma_deg = 1.0;
};

// Reads ~config and ~map (required: throws naming the missing one) and the rest with defaults.
NodeParams readParams(const ros::NodeHandle& pnh);

class NodeOutput {
 public:
  NodeOutput(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  // The map's segment centroids as a latched PointCloud2 (x y z, class as intensity) in map_frame.
  void publishMap(const TargetMap& map, const std::string& map_frame);
  // map -> odom (and odom -> base when the node runs the odometry), and the pose with its
  // configured covariance, stamped with the scan's time.
  void publishPose(const LivePose& p, double stamp_s, const NodeParams& params);
  // Hz of frames worked on, latency, drops, the age of the last localization: once a second.
  void publishDiagnostics(const LiveStats& s, std::optional<double> last_pose_stamp_s);

 private:
  // The local segments that localized: their centroids carried into the map (a cloud), and a
  // line from each to the map segment it matched (RViz markers).
  void publishMatches(const LivePose& p, double stamp_s, const std::string& map_frame);
  ros::Publisher pose_, map_cloud_, diagnostics_, local_segments_, matches_;
  tf2_ros::TransformBroadcaster tf_;
  ros::WallTime last_diagnostics_;
  size_t processed_before_ = 0;
};

}  // namespace semsegmap::ros_node
