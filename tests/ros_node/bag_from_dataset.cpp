// bag_from_dataset SPEC OUT.bag: any dataset the project reads (the shared KITTI raw sample, say)
// written as a ROS 1 bag, as a robot's drivers would record it, for the node's test to play:
// /points (PointCloud2 x y z intensity float32 in frame `lidar`), per camera k
// /camera_k/image_raw (rgb8) with /camera_k/camera_info, the rig in /tf_static (base_link ->
// lidar -> camera_k). No odometry topic. Times are the dataset's plus 1.3e9 s: ROS time 0 means
// "the latest" to TF, and made-up times start there.
#include <geometry_msgs/TransformStamped.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include <Eigen/Geometry>

#include "semsegmap/datasets/open_dataset.h"

namespace {

using namespace semsegmap;
constexpr double kEpoch = 1.3e9;

geometry_msgs::TransformStamped stamped(const Pose& T, const std::string& parent,
                                        const std::string& child) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(kEpoch);
  t.header.frame_id = parent;
  t.child_frame_id = child;
  t.transform.translation.x = T.translation().x();
  t.transform.translation.y = T.translation().y();
  t.transform.translation.z = T.translation().z();
  const Eigen::Quaterniond q(T.linear());
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

sensor_msgs::PointCloud2 cloudOf(const Frame& f, const ros::Time& stamp) {
  sensor_msgs::PointCloud2 c;
  c.header.stamp = stamp;
  c.header.frame_id = "lidar";
  c.height = 1;
  c.width = static_cast<uint32_t>(f.points.size());
  const char* names[] = {"x", "y", "z", "intensity"};
  for (uint32_t k = 0; k < 4; ++k) {
    sensor_msgs::PointField field;
    field.name = names[k];
    field.offset = 4 * k;
    field.datatype = sensor_msgs::PointField::FLOAT32;
    field.count = 1;
    c.fields.push_back(field);
  }
  c.point_step = 16;
  c.row_step = c.point_step * c.width;
  c.data.resize(c.row_step);
  std::memcpy(c.data.data(), f.points.data(), c.data.size());  // LidarPoint is x y z intensity
  c.is_dense = true;
  return c;
}

sensor_msgs::CameraInfo infoOf(const Camera& camera, const ros::Time& stamp,
                               const std::string& frame) {
  sensor_msgs::CameraInfo info;
  info.header.stamp = stamp;
  info.header.frame_id = frame;
  info.width = static_cast<uint32_t>(camera.width);
  info.height = static_cast<uint32_t>(camera.height);
  info.distortion_model = "plumb_bob";
  info.D = camera.model == CameraModel::kRadialTangential
               ? std::vector<double>(camera.distortion.begin(), camera.distortion.end())
               : std::vector<double>(5, 0.0);
  info.K = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  return info;
}

sensor_msgs::Image imageOf(const semsegmap::Image& rgb, const ros::Time& stamp,
                           const std::string& frame) {
  sensor_msgs::Image image;
  image.header.stamp = stamp;
  image.header.frame_id = frame;
  image.width = static_cast<uint32_t>(rgb.width);
  image.height = static_cast<uint32_t>(rgb.height);
  image.encoding = "rgb8";
  image.step = image.width * 3;
  image.data = rgb.data;
  return image;
}

void write(FrameSource& source, const std::string& out) {
  const SensorRig& rig = source.info().rig;
  rosbag::Bag bag(out, rosbag::bagmode::Write);
  tf2_msgs::TFMessage tf;
  tf.transforms.push_back(stamped(rig.T_base_lidar, "base_link", "lidar"));
  for (size_t k = 0; k < rig.cameras.size(); ++k)
    tf.transforms.push_back(
        stamped(rig.cameras[k].T_camera_lidar.inverse(), "lidar", "camera_" + std::to_string(k)));
  bag.write("/tf_static", ros::Time(kEpoch), tf);
  for (size_t i = 0; i < source.size(); ++i) {
    const Frame f = source.frame(i);
    const ros::Time stamp(kEpoch + f.timestamp_s);
    bag.write("/points", stamp, cloudOf(f, stamp));
    for (size_t k = 0; k < f.cameras.size(); ++k) {
      if (f.cameras[k].rgb.empty()) continue;
      const std::string frame = "camera_" + std::to_string(k), topic = "/" + frame;
      bag.write(topic + "/camera_info", stamp, infoOf(rig.cameras[k], stamp, frame));
      bag.write(topic + "/image_raw", stamp, imageOf(f.cameras[k].rgb, stamp, frame));
    }
  }
  bag.close();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bag_from_dataset SPEC OUT.bag\n");
    return 2;
  }
  try {
    auto source = openDataset(argv[1]);
    write(*source, argv[2]);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bag_from_dataset: %s\n", e.what());
    return 1;
  }
  return 0;
}
