#include "semsegmap/io/rosbag_reader.h"

#include "semsegmap/io/kitti_calib.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/stamped_pose.h"
#include "semsegmap/core/time_association.h"
#include "semsegmap/io/ros_decode.h"
#include "semsegmap/io/ros_tf.h"
#include "semsegmap/io/rosbag_storage.h"

namespace semsegmap {

using rosmsg::BagTopic;
using rosmsg::MessageRef;

namespace {

// Enough bytes for any message's header (stamp and frame_id), read without the payload.
constexpr size_t kHeaderPrefixBytes = 1024;
// Odometry poses further apart than this are not interpolated across.
constexpr double kOdometryMaxGapS = 1.0;

std::string join(const std::vector<std::string>& items, const char* sep = ", ") {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : sep) + s;
  return out;
}

bool isImageType(const std::string& type) {
  return type == rosmsg::kImage || type == rosmsg::kCompressedImage;
}

// ".../image_raw/compressed" -> ".../image_raw": the topic a compressed stream republishes.
std::string uncompressedTopic(const std::string& topic) {
  const std::string suffix = "/compressed";
  if (topic.size() > suffix.size() &&
      topic.compare(topic.size() - suffix.size(), suffix.size(), suffix) == 0)
    return topic.substr(0, topic.size() - suffix.size());
  return topic;
}

}  // namespace

namespace {

// One key=value of a spec into the options; `bad` throws naming the key.
template <typename Bad>
void setOption(RosbagOptions& o, const std::string& key, const std::string& value, Bad&& bad) {
  if (key == "lidar") {
    o.lidar_topic = value;
  } else if (key == "camera") {
    std::vector<std::string> topics;
    for (size_t a = 0, b; a <= value.size(); a = b + 1) {
      b = std::min(value.find(';', a), value.size());
      if (b > a) topics.push_back(value.substr(a, b - a));
    }
    if (topics.size() == 1 && topics[0] == "none") topics.clear();
    o.camera_topics = topics;
  } else if (key == "odometry") {
    o.odometry_topic = value;
  } else if (key == "base_frame") {
    o.base_frame = value;
  } else if (key == "odom_frame") {
    o.odom_frame = value;
  } else if (key == "tolerance") {
    char* stop = nullptr;
    const double t = std::strtod(value.c_str(), &stop);
    if (*stop != '\0' || !(t > 0) || !std::isfinite(t))
      bad("expected a positive number of seconds, got '" + value + "'");
    o.tolerance_s = t;
  } else {
    bad("unknown key (lidar, camera, odometry, base_frame, odom_frame, tolerance)");
  }
}

}  // namespace

namespace {

std::string parentNamespace(const std::string& topic) {
  const size_t slash = topic.find_last_of('/');
  return slash == std::string::npos ? std::string() : topic.substr(0, slash);
}

}  // namespace

std::string cameraInfoTopic(const std::string& image_topic) {
  return parentNamespace(uncompressedTopic(image_topic)) + "/camera_info";
}

std::string cameraNameOfTopic(const std::string& image_topic) {
  const std::string ns = parentNamespace(uncompressedTopic(image_topic));
  return ns.empty() || ns == "/" ? image_topic : ns.substr(ns[0] == '/' ? 1 : 0);
}

RosbagOptions parseRosbagOptions(const std::string& text) {
  RosbagOptions o;
  std::vector<std::string> seen;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find(',', start);
    if (end == std::string::npos) end = text.size();
    const std::string item = text.substr(start, end - start);
    start = end + 1;
    const size_t eq = item.find('=');
    const std::string key = item.substr(0, eq);
    auto bad = [&](const std::string& why) {
      throw std::invalid_argument("rosbag option '" + key + "': " + why);
    };
    if (eq == std::string::npos) bad("expected key=value");
    const std::string value = item.substr(eq + 1);
    if (value.empty()) bad("empty value");
    if (std::find(seen.begin(), seen.end(), key) != seen.end()) bad("given twice");
    seen.push_back(key);
    setOption(o, key, value, bad);
  }
  return o;
}

struct RosbagReader::Stream {
  std::string topic;
  std::vector<MessageRef> refs;
  std::vector<double> stamps;  // header stamps, in the order of refs
  std::string frame_id;        // of the first message
};

struct RosbagReader::CameraStream {
  std::string topic;
  bool compressed = false;
  Stream stream;
  Association match;  // per frame, the image
};

RosbagReader::RosbagReader(const std::filesystem::path& bag, RosbagOptions options)
    : path_(bag), options_(std::move(options)), tf_(std::make_unique<rosmsg::TfBuffer>()) {
  bag_ = rosmsg::openBagStorage(bag);
  info_.name = "rosbag:" + bag.filename().string();
  info_.origin.kind = "rosbag";
  chooseLidar();
  readTransforms();
  findBaseFrame();
  info_.origin.lidar =
      "topic " + lidar_topic_ + ", frame " + lidar_frame_ + ", base frame " + base_frame_;
  chooseCameras();
  findOdometry();
  describeLidar();
  associateImages();
  try {
    info_.rig.validate();
  } catch (const std::invalid_argument& e) {
    fail(e.what());
  }
}

RosbagReader::~RosbagReader() = default;

void RosbagReader::fail(const std::string& what) const {
  throw std::runtime_error(path_.string() + ": " + what);
}

void RosbagReader::note(const std::string& what) const {
  semsegmap::note(path_.string() + ": " + what);
}

std::vector<std::string> RosbagReader::cameraTopics() const {
  std::vector<std::string> out;
  for (const CameraStream& c : cameras_) out.push_back(c.topic);
  return out;
}

// The messages of a topic with their header stamps, read from the first bytes of each message.
RosbagReader::Stream RosbagReader::indexTopic(const std::string& topic, bool need_messages) {
  Stream s;
  s.topic = topic;
  s.refs = bag_->messages(topic);
  if (need_messages && s.refs.empty()) fail("topic " + topic + " has no messages");
  s.stamps.reserve(s.refs.size());
  for (const MessageRef& ref : s.refs) {
    const rosmsg::Header h = rosmsg::parseHeader(bag_->readPrefix(topic, ref, kHeaderPrefixBytes));
    if (s.stamps.empty()) s.frame_id = rosmsg::tfFrameName(h.frame_id);
    s.stamps.push_back(h.stamp_s);
  }
  // Association wants sorted stamps; a driver's stamps may step back a little against the
  // receive order, so the messages are put in stamp order.
  std::vector<size_t> order(s.refs.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return s.stamps[a] < s.stamps[b]; });
  Stream sorted{s.topic, {}, {}, s.frame_id};
  for (size_t i : order) {
    sorted.refs.push_back(s.refs[i]);
    sorted.stamps.push_back(s.stamps[i]);
  }
  return sorted;
}

namespace {

const BagTopic* findTopic(const std::vector<BagTopic>& topics, const std::string& name) {
  for (const BagTopic& t : topics)
    if (t.name == name) return &t;
  return nullptr;
}

std::vector<std::string> topicsOfType(const std::vector<BagTopic>& topics,
                                      const std::string& type) {
  std::vector<std::string> out;
  for (const BagTopic& t : topics)
    if (t.type == type) out.push_back(t.name);
  return out;
}

}  // namespace

void RosbagReader::chooseLidar() {
  const auto& topics = bag_->topics();
  if (!options_.lidar_topic.empty()) {
    const BagTopic* t = findTopic(topics, options_.lidar_topic);
    if (!t) fail("no topic " + options_.lidar_topic + " (lidar=)");
    if (t->type != rosmsg::kPointCloud2)
      fail("topic " + t->name + " is a " + t->type + ", not a sensor_msgs/PointCloud2 (lidar=)");
    lidar_topic_ = t->name;
  } else {
    const std::vector<std::string> clouds = topicsOfType(topics, rosmsg::kPointCloud2);
    if (clouds.empty()) fail("no sensor_msgs/PointCloud2 topic: the bag has no LiDAR scans");
    if (clouds.size() > 1)
      fail("several sensor_msgs/PointCloud2 topics (" + join(clouds) +
           "); choose the LiDAR with lidar=TOPIC");
    lidar_topic_ = clouds.front();
  }
  scans_all_ = std::make_unique<Stream>(indexTopic(lidar_topic_, true));
  lidar_frame_ = scans_all_->frame_id;
  if (lidar_frame_.empty()) fail("the scans on " + lidar_topic_ + " have no header.frame_id");
}

void RosbagReader::readTransforms() {
  for (const BagTopic& t : bag_->topics()) {
    if (t.type != rosmsg::kTfMessage) continue;
    // /tf_static is latched: its transforms hold at every time.
    const bool is_static =
        t.name.size() >= 9 && t.name.compare(t.name.size() - 9, 9, "tf_static") == 0;
    for (const MessageRef& ref : bag_->messages(t.name)) {
      try {
        tf_->add(rosmsg::parseTfMessage(bag_->read(t.name, ref)), is_static);
      } catch (const std::invalid_argument& e) {
        fail(t.name + ": " + e.what());
      }
    }
  }
}

void RosbagReader::findBaseFrame() {
  const double t0 = scans_all_->stamps.front();
  std::string why;
  if (!options_.base_frame.empty()) {
    base_frame_ = rosmsg::tfFrameName(options_.base_frame);
    const auto T = tf_->lookup(base_frame_, lidar_frame_, t0, &why);
    if (!T) fail("base_frame=" + base_frame_ + ": " + why);
    info_.rig.T_base_lidar = *T;
    return;
  }
  if (const auto T = tf_->lookup("base_link", lidar_frame_, t0)) {
    base_frame_ = "base_link";
    info_.rig.T_base_lidar = *T;
    return;
  }
  base_frame_ = lidar_frame_;
  info_.rig.T_base_lidar = Pose::Identity();
  note("no transform from the LiDAR frame '" + lidar_frame_ +
       "' to base_link; the LiDAR frame is the base (base_frame=FRAME chooses one)");
}

void RosbagReader::chooseCameras() {
  std::vector<std::string> chosen;
  if (options_.camera_topics) {
    chosen = *options_.camera_topics;
  } else {
    const auto& topics = bag_->topics();
    for (const BagTopic& t : topics) {
      if (!isImageType(t.type)) continue;
      // image_transport republishes a raw stream compressed; the camera is the raw one.
      const BagTopic* raw = findTopic(topics, uncompressedTopic(t.name));
      if (t.type == rosmsg::kCompressedImage && raw && raw != &t && raw->type == rosmsg::kImage)
        continue;
      chosen.push_back(t.name);
    }
  }
  for (const std::string& topic : chosen) addCamera(topic);
}

void RosbagReader::addCamera(const std::string& topic) {
  const auto& topics = bag_->topics();
  const BagTopic* t = findTopic(topics, topic);
  if (!t) fail("no topic " + topic + " (camera=)");
  if (!isImageType(t->type))
    fail("topic " + topic + " is a " + t->type +
         ", not a sensor_msgs/Image or CompressedImage (camera=)");
  const std::string info_topic = cameraInfoTopic(topic);
  const BagTopic* info = findTopic(topics, info_topic);
  if (!info || info->type != rosmsg::kCameraInfo)
    fail("image topic " + topic + " has no sensor_msgs/CameraInfo on " + info_topic +
         " (choose cameras with camera=TOPIC[;TOPIC] or camera=none)");
  const std::vector<MessageRef> info_refs = bag_->messages(info_topic);
  if (info_refs.empty()) fail("topic " + info_topic + " has no messages");
  const rosmsg::CameraInfo ci = rosmsg::parseCameraInfo(bag_->read(info_topic, info_refs.front()));
  Camera cam = rosmsg::cameraFromInfo(ci, path_.string() + ": " + info_topic);
  cam.name = cameraNameOfTopic(topic);

  CameraStream c;
  c.topic = topic;
  c.compressed = t->type == rosmsg::kCompressedImage;
  c.stream = indexTopic(topic, true);
  std::string frame = rosmsg::tfFrameName(ci.header.frame_id);
  if (frame.empty()) frame = c.stream.frame_id;
  if (frame.empty())
    fail("camera " + topic + ": neither its CameraInfo nor its images name a frame_id");
  std::string why;
  const auto T = tf_->lookup(frame, lidar_frame_, scans_all_->stamps.front(), &why);
  if (!T) fail("camera " + topic + ": " + why);
  cam.T_camera_lidar = *T;
  info_.rig.cameras.push_back(cam);
  info_.origin.cameras.push_back("topic " + topic + ", " + info_topic + ", frame " + frame);
  cameras_.push_back(std::move(c));
}

namespace {

// The odometry pose at t: interpolated, or the first or last pose for a scan stamped a little
// before or after them.
std::optional<Pose> odometryAt(const std::vector<StampedPose>& trajectory, double t) {
  constexpr double kEdgeS = 0.1;
  if (trajectory.empty()) return std::nullopt;
  if (t < trajectory.front().timestamp_s && trajectory.front().timestamp_s - t <= kEdgeS)
    return trajectory.front().T;
  if (t > trajectory.back().timestamp_s && t - trajectory.back().timestamp_s <= kEdgeS)
    return trajectory.back().T;
  return poseAt(trajectory, t, kOdometryMaxGapS);
}

}  // namespace

std::vector<std::optional<Pose>> RosbagReader::odometryFromTopic(const std::string& topic) {
  const std::vector<double>& stamps = scans_all_->stamps;
  std::vector<std::optional<Pose>> poses(stamps.size());
  std::vector<StampedPose> trajectory;
  std::string child;
  for (const MessageRef& ref : bag_->messages(topic)) {
    const rosmsg::Odometry o = rosmsg::parseOdometry(bag_->read(topic, ref));
    if (trajectory.empty()) child = rosmsg::tfFrameName(o.child_frame_id);
    try {
      trajectory.push_back(rosmsg::stampedPoseOf(o));
    } catch (const std::invalid_argument& e) {
      fail(topic + ": " + e.what());
    }
  }
  std::sort(trajectory.begin(), trajectory.end(), [](const StampedPose& a, const StampedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  // The odometry may be of another frame than the base (an IMU, the LiDAR): moved by TF.
  Pose T_child_base = Pose::Identity();
  std::string why;
  if (!child.empty() && child != base_frame_) {
    const auto T = tf_->lookup(child, base_frame_, stamps.front(), &why);
    if (!T) fail("odometry " + topic + " is of frame '" + child + "': " + why);
    T_child_base = *T;
  }
  for (size_t i = 0; i < stamps.size(); ++i)
    if (const auto T = odometryAt(trajectory, stamps[i])) poses[i] = *T * T_child_base;
  return poses;
}

void RosbagReader::findOdometry() {
  std::string topic = options_.odometry_topic;
  if (!topic.empty()) {
    const BagTopic* t = findTopic(bag_->topics(), topic);
    if (!t) fail("no topic " + topic + " (odometry=)");
    if (t->type != rosmsg::kOdometry)
      fail("topic " + topic + " is a " + t->type + ", not a nav_msgs/Odometry (odometry=)");
  } else {
    const std::vector<std::string> odoms = topicsOfType(bag_->topics(), rosmsg::kOdometry);
    if (odoms.size() > 1)
      fail("several nav_msgs/Odometry topics (" + join(odoms) +
           "); choose one with odometry=TOPIC");
    if (!odoms.empty()) topic = odoms.front();
  }
  const std::vector<double>& stamps = scans_all_->stamps;
  std::vector<std::optional<Pose>> poses(stamps.size());
  const std::string odom_frame = rosmsg::tfFrameName(options_.odom_frame);
  if (!topic.empty()) {
    poses = odometryFromTopic(topic);
    info_.origin.odometry = "topic " + topic + " (nav_msgs/Odometry)";
  } else if (tf_->hasFrame(odom_frame)) {
    for (size_t i = 0; i < stamps.size(); ++i)
      poses[i] = tf_->lookup(odom_frame, base_frame_, stamps[i]);
    info_.origin.odometry = "TF " + odom_frame + " -> " + base_frame_;
  }
  info_.has_odometry =
      std::any_of(poses.begin(), poses.end(), [](const auto& p) { return p.has_value(); });
  if (!info_.has_odometry) {
    info_.origin.odometry.clear();
    if (!topic.empty()) fail("odometry " + topic + " covers none of the LiDAR scans' times");
    note("no nav_msgs/Odometry topic and no TF chain '" + odom_frame + "' -> '" + base_frame_ +
         "': the bag has no odometry");
  }
  keepFramesWithOdometry(poses);
}

void RosbagReader::keepFramesWithOdometry(const std::vector<std::optional<Pose>>& poses) {
  scans_.clear();
  T_odom_base_.clear();
  for (size_t i = 0; i < poses.size(); ++i) {
    if (info_.has_odometry && !poses[i]) continue;
    scans_.push_back(i);
    if (info_.has_odometry) T_odom_base_.push_back(*poses[i]);
  }
  const size_t dropped = poses.size() - scans_.size();
  if (dropped > 0)
    note(std::to_string(dropped) + " of " + std::to_string(poses.size()) +
         " scans lie outside the odometry and are left out");
}

void RosbagReader::describeLidar() {
  const std::vector<double>& st = scans_all_->stamps;
  std::vector<double> periods;
  for (size_t i = 1; i < st.size(); ++i)
    if (st[i] > st[i - 1]) periods.push_back(st[i] - st[i - 1]);
  info_.rig.rate_hz = 10.0;  // a bag of one scan says nothing; the common rate
  if (!periods.empty()) {
    std::nth_element(periods.begin(), periods.begin() + periods.size() / 2, periods.end());
    info_.rig.rate_hz = 1.0 / periods[periods.size() / 2];
  }
  // The LiDAR model is what the first scan shows: its rings or rows, its vertical extent.
  const auto msg = rosmsg::parsePointCloud2(
      bag_->read(lidar_topic_, scans_all_->refs[scans_.empty() ? 0 : scans_.front()]));
  info_.rig.lidar = rosmsg::lidarModelOf(
      msg, rosmsg::decodePointCloud2(msg, path_.string() + ": " + lidar_topic_));
}

void RosbagReader::associateImages() {
  const double tolerance = options_.tolerance_s.value_or(0.5 / info_.rig.rate_hz);
  std::vector<double> frame_stamps;
  for (size_t k : scans_) frame_stamps.push_back(scans_all_->stamps[k]);
  for (size_t c = 0; c < cameras_.size(); ++c) {
    CameraStream& cam = cameras_[c];
    cam.match = associateNearest(frame_stamps, cam.stream.stamps, tolerance);
    if (cam.match.unmatched > 0)
      note("camera '" + info_.rig.cameras[c].name + "' (" + cam.topic + "): " +
           std::to_string(cam.match.unmatched) + " of " + std::to_string(frame_stamps.size()) +
           " scans have no image within " + std::to_string(tolerance) + " s and go without colour");
  }
}

double RosbagReader::frameTime(size_t index) {
  if (index >= scans_.size()) throwFrameOutOfRange(info_.name, index, scans_.size());
  return scans_all_->stamps[scans_[index]];
}

Frame RosbagReader::frame(size_t index) {
  if (index >= scans_.size()) throwFrameOutOfRange(info_.name, index, scans_.size());
  const size_t k = scans_[index];
  Frame f;
  f.index = index;
  f.timestamp_s = scans_all_->stamps[k];
  const auto msg = rosmsg::parsePointCloud2(bag_->read(lidar_topic_, scans_all_->refs[k]));
  rosmsg::DecodedCloud cloud = rosmsg::decodePointCloud2(msg, path_.string() + ": " + lidar_topic_);
  f.points = std::move(cloud.points);
  // The per-point times are relative to the cloud's stamp, which is the frame's.
  f.point_times = std::move(cloud.point_times);
  f.cameras.resize(cameras_.size());
  for (size_t c = 0; c < cameras_.size(); ++c) {
    const CameraStream& cam = cameras_[c];
    const auto match = cam.match.match[index];
    if (!match) continue;
    const rosmsg::SerializedMessage bytes = bag_->read(cam.topic, cam.stream.refs[*match]);
    const std::string where = path_.string() + ": " + cam.topic;
    Image rgb = cam.compressed
                    ? rosmsg::decodeCompressedImage(rosmsg::parseCompressedImage(bytes), where)
                    : rosmsg::decodeImage(rosmsg::parseImage(bytes), where);
    const Camera& model = info_.rig.cameras[c];
    if (rgb.width != model.width || rgb.height != model.height)
      fail(cam.topic + ": image is " + std::to_string(rgb.width) + "x" +
           std::to_string(rgb.height) + ", its CameraInfo says " + std::to_string(model.width) +
           "x" + std::to_string(model.height));
    f.cameras[c].rgb = std::move(rgb);
  }
  if (info_.has_odometry) f.T_odom_base = T_odom_base_[index];
  return f;
}

}  // namespace semsegmap
