// semsegmap_node (ROS 1): the live core (pipeline/live_session.h) on a robot's topics. A thin
// shell, as a ROS 2 node would be the same against rclcpp (docs/ros.md): messages arrive as
// serialized bytes and are decoded by the bag reader's own parsers (io/ros_serialization.h,
// io/ros_decode.h), so that a topic and a bag of it give the same frames; the rig comes from the
// first scan, the CameraInfos and TF; poses are published as the map -> odom transform, a
// PoseWithCovarianceStamped and diagnostics; the map's segments as a latched cloud for RViz.
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_broadcaster.h>
#include <topic_tools/shape_shifter.h>

#include <csignal>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "node_output.h"
#include "node_rig.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/datasets/semantic_sources.h"
#include "semsegmap/io/ros_decode.h"
#include "semsegmap/io/rosbag_reader.h"
#include "semsegmap/pipeline/input_modalities.h"
#include "semsegmap/pipeline/live_session.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::ros_node {

namespace {

using Shape = topic_tools::ShapeShifter;

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) {
  g_stop = 1;
}

rosmsg::SerializedMessage bytesOf(const Shape& msg, const std::string& topic) {
  rosmsg::SerializedMessage m;
  m.bytes.resize(msg.size());
  ros::serialization::OStream out(reinterpret_cast<uint8_t*>(m.bytes.data()),
                                  static_cast<uint32_t>(m.bytes.size()));
  msg.write(out);
  m.format = rosmsg::WireFormat::kRos1;
  m.file = "semsegmap_node";
  m.topic = topic;
  return m;
}

struct Message {
  enum Kind { kScan, kPicture, kCameraInfo, kOdometry, kTf, kTfStatic } kind;
  size_t camera = 0;
  rosmsg::SerializedMessage bytes;
  bool compressed = false;
};

class Node {
 public:
  Node(ros::NodeHandle& nh, ros::NodeHandle& pnh) : params_(readParams(pnh)), out_(nh, pnh) {
    config_ = loadPipelineConfig(params_.config);
    if (params_.relocalize) config_.localization.relocalization.enabled = true;
    if (mapping()) {
      save_ = pnh.advertiseService("save_map", &Node::onSaveMap, this);
      ROS_INFO("semsegmap: mapping into %s (~save_map, and at shutdown), waiting for %s",
               params_.map.c_str(), params_.topics.lidar.c_str());
    } else {
      map_ = std::make_shared<const TargetMap>(loadTargetMap(params_.map));
      out_.publishMap(*map_, params_.map_frame);
      ROS_INFO("semsegmap: map %s (%zu segments), waiting for %s", params_.map.c_str(),
               map_->size(), params_.topics.lidar.c_str());
    }
    rig_.emplace(params_.topics);
    subscribe(nh);
  }

  // Publishes the poses found since, and the diagnostics once a second.
  void spinOnce() {
    for (const LivePose& p : live_ ? live_->poll() : std::vector<LivePose>{}) publish(p);
    if (live_) out_.publishDiagnostics(live_->stats(), last_pose_stamp_);
  }

  void finish() {
    if (!live_) {
      ROS_WARN("semsegmap: stopped before the rig was known (%s)", missing_.c_str());
      return;
    }
    live_->finish();
    spinOnce();
    if (mapping_) saveMap(mapping_->finish().map, "the map");
    const LiveStats s = live_->stats();
    ROS_INFO(
        "semsegmap: received %zu scans, %zu worked on, %zu dropped, %zu without odometry, "
        "%zu localized; latency %.1f ms on average, %.1f at most",
        s.assembly.scans, s.processed, s.dropped, s.assembly.without_odometry, s.localized,
        s.mean_latency_ms, s.max_latency_ms);
  }

 private:
  void subscribe(ros::NodeHandle& nh) {
    const auto on = [&](const std::string& topic, Message::Kind kind, size_t camera) {
      subs_.push_back(
          nh.subscribe<Shape>(topic, 100, [this, topic, kind, camera](const Shape::ConstPtr& msg) {
            receive({kind, camera, bytesOf(*msg, topic),
                     msg->getDataType() == rosmsg::kCompressedImage});
          }));
    };
    on(params_.topics.lidar, Message::kScan, 0);
    for (size_t c = 0; c < params_.topics.cameras.size(); ++c) {
      on(params_.topics.cameras[c], Message::kPicture, c);
      on(cameraInfoTopic(params_.topics.cameras[c]), Message::kCameraInfo, c);
    }
    if (!params_.odometry_topic.empty()) on(params_.odometry_topic, Message::kOdometry, 0);
    on("/tf", Message::kTf, 0);
    on("/tf_static", Message::kTfStatic, 0);
  }

  void receive(Message m) {
    if (m.kind == Message::kCameraInfo) {
      if (!live_) rig_->addCameraInfo(m.camera, m.bytes);
      return;
    }
    if (m.kind == Message::kTf || m.kind == Message::kTfStatic) {
      if (!live_) rig_->addTransforms(m.bytes, m.kind == Message::kTfStatic);
      return;
    }
    if (!live_) {
      if (m.kind == Message::kScan) rig_->addScan(m.bytes);
      waiting_.push_back(std::move(m));  // handed over once the rig is known
      if (waiting_.size() > kMaxWaiting) waiting_.erase(waiting_.begin());
      start();
      return;
    }
    feed(m);
  }

  void start() {
    const std::optional<DatasetInfo> info = rig_->rig(missing_);
    if (!info) {
      ROS_INFO_THROTTLE(5, "semsegmap: waiting for %s", missing_.c_str());
      return;
    }
    FrontEndStages stages;
    if (params_.odometry_topic.empty()) {
      stages.lidar_odometry = loadOdometryConfig(params_.config);
      ROS_INFO("semsegmap: no odometry topic: LiDAR odometry on the scans, published as %s -> %s",
               params_.odom_frame.c_str(), params_.topics.base_frame.c_str());
    }
    DatasetInfo with = *info;
    with.has_odometry = !params_.odometry_topic.empty();
    addSegmentationNetwork(with, stages);
    const DescriptorChoice choice = chooseDescriptor(config_.descriptor, inputModalitiesOf(with));
    if (!choice.note.empty()) ROS_INFO("semsegmap: %s", choice.note.c_str());
    describer_ = makeDescriber(choice.descriptor);
    LiveConfig live;
    live.assembly.cameras = with.rig.cameras.size();
    live.assembly.odometry = with.has_odometry;
    live.max_queued_frames = params_.max_queued_frames;
    live_ = std::make_unique<LiveSession>(live, process(with, stages));
    for (const Message& m : waiting_) feed(m);
    waiting_.clear();
  }

  bool mapping() const { return params_.mode == "map"; }

  // The config's semantics: network labels the pictures that come without labels, on its own
  // thread within its budget (semantics/live_labeler.h): a scan never waits for it. A shipped
  // class map's name is looked up in class_maps/ beside the config, as in the source tree.
  void addSegmentationNetwork(const DatasetInfo& info, FrontEndStages& stages) {
    const SemanticsConfig semantics = loadSemanticsConfig(params_.config);
    if (semantics.model.empty()) return;
    const auto class_maps = std::filesystem::path(params_.config).parent_path() / "class_maps";
    stages.network = loadSegmentationNetwork(semantics, info, class_maps);
    stages.labelling = FrontEndStages::Labelling::kLive;
    ROS_INFO(
        "semsegmap: segmentation network %s beside the scans (%.2f cores, at most %.1f "
        "pictures a second per camera)",
        semantics.model.c_str(), semantics.budget_cores, semantics.rate_hz);
  }

  // What the worker does with a frame: localize it, or add it to the map (under the lock that
  // ~save_map takes to copy the map so far).
  LiveSession::Process process(const DatasetInfo& info, const FrontEndStages& stages) {
    if (!mapping()) {
      session_ = std::make_unique<LocalizationSession>(config_, info, map_, describer_,
                                                       MapSettingsCheck::kRefuse, stages);
      session_->keepHistory(false);  // poses are published, not kept: days of them would pile up
      return localizingProcess(*session_);
    }
    mapping_ =
        std::make_unique<MappingSession>(config_, info, PoseSource::kOdometry, describer_, stages);
    return [this](const Frame& frame) {
      std::lock_guard<std::mutex> lock(mapping_mutex_);
      mapping_->process(frame);
      return std::vector<LivePose>{};
    };
  }

  bool onSaveMap(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& response) {
    if (!mapping_) {
      response.message = "no map yet: " + missing_;
      return true;
    }
    TargetMap so_far;
    {
      std::lock_guard<std::mutex> lock(mapping_mutex_);
      so_far = mapping_->mapSoFar();
    }
    saveMap(so_far, "the segments finished so far");
    response.success = true;
    response.message = std::to_string(so_far.size()) + " segments to " + params_.map;
    return true;
  }

  // Written to a temporary name and renamed (saveTargetMap): a map already there is replaced
  // whole or not at all.
  void saveMap(const TargetMap& map, const char* what) const {
    const uint64_t bytes = saveTargetMap(params_.map, map);
    ROS_INFO("semsegmap: saved %s, %zu segments (%llu bytes), to %s", what, map.size(),
             static_cast<unsigned long long>(bytes), params_.map.c_str());
  }

  void feed(const Message& m) {
    const std::string& where = m.bytes.topic;
    if (m.kind == Message::kScan) {
      const rosmsg::PointCloud2 cloud = rosmsg::parsePointCloud2(m.bytes);
      rosmsg::DecodedCloud points = rosmsg::decodePointCloud2(cloud, where);
      live_->addScan(
          {cloud.header.stamp_s, std::move(points.points), std::move(points.point_times)});
    } else if (m.kind == Message::kPicture) {
      const double t = rosmsg::parseHeader(m.bytes).stamp_s;
      Image rgb = m.compressed
                      ? rosmsg::decodeCompressedImage(rosmsg::parseCompressedImage(m.bytes), where)
                      : rosmsg::decodeImage(rosmsg::parseImage(m.bytes), where);
      live_->addPicture(m.camera, {t, std::move(rgb), {}});
    } else if (m.kind == Message::kOdometry) {
      live_->addOdometry(rosmsg::stampedPoseOf(rosmsg::parseOdometry(m.bytes)));
    }
  }

  void publish(const LivePose& p) {
    const double t = p.record.timestamp_s.value_or(0.0);
    out_.publishPose(p, t, params_);
    last_pose_stamp_ = t;
  }

  static constexpr size_t kMaxWaiting = 200;  // scans and pictures while the rig is unknown
  NodeParams params_;
  NodeOutput out_;
  PipelineConfig config_;
  std::shared_ptr<const TargetMap> map_;
  std::optional<RigBuilder> rig_;
  std::string missing_ = "the first scan";
  std::vector<Message> waiting_;
  std::vector<ros::Subscriber> subs_;
  std::shared_ptr<Describer> describer_;
  std::unique_ptr<LocalizationSession> session_;
  std::unique_ptr<MappingSession> mapping_;
  std::mutex mapping_mutex_;
  ros::ServiceServer save_;
  std::unique_ptr<LiveSession> live_;
  std::optional<double> last_pose_stamp_;
};

}  // namespace

}  // namespace semsegmap::ros_node

int main(int argc, char** argv) {
  using namespace semsegmap::ros_node;
  // Our own SIGINT handler: the queued frames are worked off and their poses published before
  // the node leaves the ROS graph.
  ros::init(argc, argv, "semsegmap", ros::init_options::NoSigintHandler);
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  ros::NodeHandle nh, pnh("~");
  try {
    Node node(nh, pnh);
    ros::Rate rate(100);
    while (ros::ok() && !g_stop) {
      ros::spinOnce();
      node.spinOnce();
      rate.sleep();
    }
    ros::spinOnce();
    node.finish();
    ros::WallDuration(0.5).sleep();  // the last poses reach their subscribers
  } catch (const std::exception& e) {
    ROS_FATAL("semsegmap: %s", e.what());
    ros::shutdown();
    return 1;
  }
  ros::shutdown();
  return 0;
}
