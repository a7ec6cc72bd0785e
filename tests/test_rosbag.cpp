// ROS bags as datasets: message decoding (PointCloud2 layouts, images, CameraInfo, TF), the two
// storages, and RosbagReader end to end. Fixtures are written here with the libraries the reader
// uses: rosbag_storage and the ROS 1 message packages for .bag files, sqlite3 and the CDR writer
// (fastcdr) for ROS 2; from synthetic data and from the real KITTI raw sample in ../shared/data.
#include <gtest/gtest.h>
#include <lz4frame.h>
#include <sqlite3.h>
#include <zstd.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <variant>

#if SEMSEGMAP_WITH_ROS1
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>
#endif

#include "doc_blocks.h"
#include "error_text.h"
#include "fuzz_regressions.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/dataset_reader.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/io/kitti_raw_reader.h"
#include "semsegmap/io/point_fields.h"
#include "semsegmap/io/ros_decode.h"
#include "semsegmap/io/ros_serialization.h"
#include "semsegmap/io/ros_tf.h"
#include "semsegmap/io/rosbag_reader.h"
#include "semsegmap/io/rosbag_storage.h"
#include "sqlite_bag_rows.h"
#include "temp_dir.h"

namespace {

namespace fs = std::filesystem;
namespace rm = semsegmap::rosmsg;
using semsegmap::Camera;
using semsegmap::CameraModel;
using semsegmap::FieldType;
using semsegmap::Frame;
using semsegmap::LidarPoint;
using semsegmap::Pose;
using semsegmap::RosbagOptions;
using semsegmap::RosbagReader;
using semsegmap::test_support::errorOf;
using semsegmap::test_support::TempDir;

// Bag times of the fixtures: ROS 1 refuses a time of 0, so the synthetic clock starts here.
constexpr double kEpoch = 1317000000.0;

// ---- Building messages --------------------------------------------------------------------

struct FieldSpec {
  std::string name;
  uint8_t datatype;
};

constexpr uint8_t dt(FieldType type) {
  return static_cast<uint8_t>(type);
}

size_t sizeOf(uint8_t datatype) {
  static const size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
  return sizes[datatype];
}

void storeAs(uint8_t* p, uint8_t datatype, double v) {
  auto put = [&](auto x) { std::memcpy(p, &x, sizeof(x)); };
  switch (datatype) {
    case dt(FieldType::kInt8):
      put(static_cast<int8_t>(v));
      break;
    case dt(FieldType::kUint8):
      put(static_cast<uint8_t>(v));
      break;
    case dt(FieldType::kInt16):
      put(static_cast<int16_t>(v));
      break;
    case dt(FieldType::kUint16):
      put(static_cast<uint16_t>(v));
      break;
    case dt(FieldType::kInt32):
      put(static_cast<int32_t>(v));
      break;
    case dt(FieldType::kUint32):
      put(static_cast<uint32_t>(v));
      break;
    case dt(FieldType::kFloat32):
      put(static_cast<float>(v));
      break;
    default:
      put(v);
  }
}

// A cloud of height x width points with the given fields, each followed by `padding` unused
// bytes; value(i, field) gives point i's value of a field.
rm::PointCloud2 makeCloud(const std::vector<FieldSpec>& fields, uint32_t height, uint32_t width,
                          const std::function<double(size_t, const std::string&)>& value,
                          uint32_t padding = 0, double stamp = kEpoch,
                          const std::string& frame = "velodyne") {
  rm::PointCloud2 c;
  c.header = {stamp, frame};
  c.height = height;
  c.width = width;
  for (const FieldSpec& f : fields) {
    c.fields.push_back({f.name, c.point_step, f.datatype, 1});
    c.point_step += static_cast<uint32_t>(sizeOf(f.datatype)) + padding;
  }
  c.row_step = c.point_step * width;
  c.data.resize(static_cast<size_t>(c.row_step) * height);
  for (size_t i = 0; i < static_cast<size_t>(height) * width; ++i)
    for (const rm::PointField& f : c.fields)
      storeAs(&c.data[i * c.point_step + f.offset], f.datatype, value(i, f.name));
  return c;
}

rm::PointCloud2 cloudOf(const std::vector<LidarPoint>& points, double stamp,
                        const std::vector<float>& times = {}) {
  std::vector<FieldSpec> fields = {{"x", 7}, {"y", 7}, {"z", 7}, {"intensity", 7}};
  if (!times.empty()) fields.push_back({"time", 7});
  return makeCloud(
      fields, 1, static_cast<uint32_t>(points.size()),
      [&](size_t i, const std::string& f) -> double {
        const LidarPoint& p = points[i];
        return f == "x"      ? p.x
               : f == "y"    ? p.y
               : f == "z"    ? p.z
               : f == "time" ? times[i]
                             : p.intensity;
      },
      0, stamp);
}

rm::Image rgb8Of(const semsegmap::Image& img, double stamp, const std::string& frame) {
  rm::Image m;
  m.header = {stamp, frame};
  m.height = img.height;
  m.width = img.width;
  m.encoding = "rgb8";
  m.step = img.width * 3;
  m.data = img.data;
  return m;
}

// Built field by field: GCC 12 warns (maybe-uninitialized) on a nested aggregate initialiser
// of these structs at -O2, and warnings are errors.
rm::CompressedImage compressedOf(const std::vector<uint8_t>& bytes, const std::string& format,
                                 double stamp, const std::string& frame = "cam") {
  rm::CompressedImage m;
  m.header.stamp_s = stamp;
  m.header.frame_id = frame;
  m.format = format;
  m.data = bytes;
  return m;
}

rm::CameraInfo infoOf(const Camera& cam, double stamp, const std::string& frame) {
  rm::CameraInfo m;
  m.header = {stamp, frame};
  m.width = cam.width;
  m.height = cam.height;
  m.distortion_model = cam.model == CameraModel::kEquidistant ? "equidistant" : "plumb_bob";
  const size_t n = cam.model == CameraModel::kEquidistant ? 4 : 5;
  m.D.assign(cam.distortion.begin(), cam.distortion.begin() + n);
  m.K = {cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1};
  return m;
}

rm::Transform transformOf(const Pose& T) {
  const Eigen::Quaterniond q(T.linear());
  return rm::Transform{{T.translation().x(), T.translation().y(), T.translation().z()},
                       {q.x(), q.y(), q.z(), q.w()}};
}

rm::TransformStamped stampedOf(const std::string& parent, const std::string& child, const Pose& T,
                               double stamp) {
  return rm::TransformStamped{{stamp, parent}, child, transformOf(T)};
}

Pose poseXyzYaw(double x, double y, double z, double yaw) {
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

// ---- Writing bags ----------------------------------------------------------------------------

using AnyMessage = std::variant<rm::PointCloud2, rm::Image, rm::CompressedImage, rm::CameraInfo,
                                rm::Odometry, rm::TfMessage>;
struct BagMessage {
  std::string topic;
  double time;
  AnyMessage message;
};

const char* typeName(const AnyMessage& m) {
  static const char* names[] = {rm::kPointCloud2, rm::kImage,    rm::kCompressedImage,
                                rm::kCameraInfo,  rm::kOdometry, rm::kTfMessage};
  return names[m.index()];
}

std::string ros2TypeName(const std::string& ros1) {
  const size_t slash = ros1.find('/');
  return ros1.substr(0, slash) + "/msg" + ros1.substr(slash);
}

// A ROS 2 .db3 as rosbag2's sqlite3 storage writes it. `empty_topics` are declared with no
// messages; `format` is each topic's serialization_format.
void writeRos2(const fs::path& file, const std::vector<BagMessage>& messages,
               const std::vector<std::pair<std::string, std::string>>& empty_topics = {},
               const std::string& format = "cdr") {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  auto exec = [&](const std::string& sql) {
    char* err = nullptr;
    ASSERT_EQ(sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &err), SQLITE_OK) << err;
  };
  exec(
      "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
      "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL);"
      "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, "
      "timestamp INTEGER NOT NULL, data BLOB NOT NULL);");
  std::map<std::string, int> ids;
  auto topicId = [&](const std::string& name, const std::string& type) {
    if (!ids.count(name)) {
      const int id = static_cast<int>(ids.size()) + 1;
      ids[name] = id;
      exec("INSERT INTO topics VALUES(" + std::to_string(id) + ", '" + name + "', '" +
           ros2TypeName(type) + "', '" + format + "', '')");
    }
    return ids[name];
  };
  for (const auto& [name, type] : empty_topics) topicId(name, type);
  sqlite3_stmt* insert = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", -1,
                     &insert, nullptr);
  for (const BagMessage& m : messages) {
    const std::string bytes = std::visit([](const auto& v) { return rm::toCdr(v); }, m.message);
    sqlite3_bind_int(insert, 1, topicId(m.topic, typeName(m.message)));
    sqlite3_bind_int64(insert, 2, std::llround(m.time * 1e9));
    sqlite3_bind_blob(insert, 3, bytes.data(), static_cast<int>(bytes.size()), SQLITE_TRANSIENT);
    ASSERT_EQ(sqlite3_step(insert), SQLITE_DONE);
    sqlite3_reset(insert);
  }
  sqlite3_finalize(insert);
  sqlite3_close(db);
}

#if SEMSEGMAP_WITH_ROS1
std_msgs::Header ros1Header(const rm::Header& h) {
  std_msgs::Header out;
  out.stamp = ros::Time(h.stamp_s);
  out.frame_id = h.frame_id;
  return out;
}

geometry_msgs::Transform ros1Transform(const rm::Transform& t) {
  geometry_msgs::Transform out;
  out.translation.x = t.translation[0];
  out.translation.y = t.translation[1];
  out.translation.z = t.translation[2];
  out.rotation.x = t.rotation[0];
  out.rotation.y = t.rotation[1];
  out.rotation.z = t.rotation[2];
  out.rotation.w = t.rotation[3];
  return out;
}

// Each plain message as the ROS 1 message packages spell it, written by rosbag itself.
struct Ros1Writer {
  rosbag::Bag& bag;
  const std::string& topic;
  ros::Time time;

  void operator()(const rm::PointCloud2& m) const {
    sensor_msgs::PointCloud2 out;
    out.header = ros1Header(m.header);
    out.height = m.height;
    out.width = m.width;
    for (const rm::PointField& f : m.fields) {
      sensor_msgs::PointField pf;
      pf.name = f.name;
      pf.offset = f.offset;
      pf.datatype = f.datatype;
      pf.count = f.count;
      out.fields.push_back(pf);
    }
    out.is_bigendian = m.is_bigendian;
    out.point_step = m.point_step;
    out.row_step = m.row_step;
    out.data = m.data;
    out.is_dense = m.is_dense;
    bag.write(topic, time, out);
  }
  void operator()(const rm::Image& m) const {
    sensor_msgs::Image out;
    out.header = ros1Header(m.header);
    out.height = m.height;
    out.width = m.width;
    out.encoding = m.encoding;
    out.is_bigendian = m.is_bigendian;
    out.step = m.step;
    out.data = m.data;
    bag.write(topic, time, out);
  }
  void operator()(const rm::CompressedImage& m) const {
    sensor_msgs::CompressedImage out;
    out.header = ros1Header(m.header);
    out.format = m.format;
    out.data = m.data;
    bag.write(topic, time, out);
  }
  void operator()(const rm::CameraInfo& m) const {
    sensor_msgs::CameraInfo out;
    out.header = ros1Header(m.header);
    out.height = m.height;
    out.width = m.width;
    out.distortion_model = m.distortion_model;
    out.D = m.D;
    for (int i = 0; i < 9; ++i) out.K[i] = m.K[i];
    out.R[0] = out.R[4] = out.R[8] = 1.0;
    bag.write(topic, time, out);
  }
  void operator()(const rm::Odometry& m) const {
    nav_msgs::Odometry out;
    out.header = ros1Header(m.header);
    out.child_frame_id = m.child_frame_id;
    const geometry_msgs::Transform t = ros1Transform(m.pose);
    out.pose.pose.position.x = t.translation.x;
    out.pose.pose.position.y = t.translation.y;
    out.pose.pose.position.z = t.translation.z;
    out.pose.pose.orientation = t.rotation;
    bag.write(topic, time, out);
  }
  void operator()(const rm::TfMessage& m) const {
    tf2_msgs::TFMessage out;
    for (const rm::TransformStamped& t : m.transforms) {
      geometry_msgs::TransformStamped ts;
      ts.header = ros1Header(t.header);
      ts.child_frame_id = t.child_frame_id;
      ts.transform = ros1Transform(t.transform);
      out.transforms.push_back(ts);
    }
    bag.write(topic, time, out);
  }
};

void writeRos1(const fs::path& file, const std::vector<BagMessage>& messages,
               rosbag::CompressionType compression = rosbag::compression::Uncompressed) {
  rosbag::Bag bag(file.string(), rosbag::bagmode::Write);
  bag.setCompression(compression);
  for (const BagMessage& m : messages)
    std::visit(Ros1Writer{bag, m.topic, ros::Time(m.time)}, m.message);
  bag.close();
}
#endif

enum class BagKind { kRos1, kRos2 };

std::string kindName(const ::testing::TestParamInfo<BagKind>& p) {
  return p.param == BagKind::kRos1 ? "Ros1" : "Ros2";
}

// Writes the messages as the kind of bag; returns the path to open.
fs::path writeBag(BagKind kind, const fs::path& dir, const std::vector<BagMessage>& messages) {
  if (kind == BagKind::kRos2) {
    writeRos2(dir / "bag.db3", messages);
    return dir / "bag.db3";
  }
#if SEMSEGMAP_WITH_ROS1
  writeRos1(dir / "bag.bag", messages);
#endif
  return dir / "bag.bag";
}

class Bags : public ::testing::TestWithParam<BagKind> {
 protected:
  void SetUp() override {
    if (GetParam() == BagKind::kRos1 && !SEMSEGMAP_WITH_ROS1)
      GTEST_SKIP() << "this build reads no ROS 1 bags (SEMSEGMAP_WITH_ROS1=OFF)";
  }
};

}  // namespace

// ---- PointCloud2 layouts -------------------------------------------------------------------

namespace {

// Point i of the layout tests: distinct, exactly representable coordinates.
double coord(size_t i, const std::string& f) {
  return f == "x" ? 1.0 + i : f == "y" ? -2.0 - 0.5 * i : 0.25 * i;
}

}  // namespace

TEST(PointCloud2, PaddedFloat32WithIntensity) {
  const auto msg = makeCloud(
      {{"x", 7}, {"y", 7}, {"z", 7}, {"intensity", 7}}, 1, 5,
      [](size_t i, const std::string& f) { return f == "intensity" ? 10.0 * i : coord(i, f); },
      /*padding=*/4);
  ASSERT_EQ(msg.point_step, 32u);  // each field padded to 8 bytes, as PCL's aligned points are
  const auto cloud = rm::decodePointCloud2(msg, "t");
  ASSERT_EQ(cloud.points.size(), 5u);
  for (size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(cloud.points[i].x, coord(i, "x"));
    EXPECT_EQ(cloud.points[i].y, coord(i, "y"));
    EXPECT_EQ(cloud.points[i].z, coord(i, "z"));
    EXPECT_EQ(cloud.points[i].intensity, 10.0f * i);
  }
  EXPECT_TRUE(cloud.point_times.empty());
}

TEST(PointCloud2, Float64WithoutIntensityAndPointStepBeyondFields) {
  auto msg = makeCloud({{"x", 8}, {"y", 8}, {"z", 8}}, 1, 4, coord);
  // A larger point_step than the fields need (trailing bytes the driver uses for itself).
  rm::PointCloud2 wide = msg;
  wide.point_step = msg.point_step + 12;
  wide.row_step = wide.point_step * wide.width;
  wide.data.assign(wide.row_step, 0xEE);
  for (size_t i = 0; i < 4; ++i)
    std::memcpy(&wide.data[i * wide.point_step], &msg.data[i * msg.point_step], msg.point_step);
  const auto cloud = rm::decodePointCloud2(wide, "t");
  ASSERT_EQ(cloud.points.size(), 4u);
  EXPECT_EQ(cloud.points[3].x, 4.0f);
  EXPECT_EQ(cloud.points[3].y, -3.5f);
  EXPECT_EQ(cloud.points[3].intensity, 0.0f);  // no intensity field: 0
}

TEST(PointCloud2, ReflectivityOfAnyDatatypeAndRings) {
  const auto msg = makeCloud(
      {{"x", 7}, {"y", 7}, {"z", 7}, {"reflectivity", 4}, {"ring", 4}}, 1, 6,
      [](size_t i, const std::string& f) {
        return f == "reflectivity" ? 1000.0 + i : f == "ring" ? double(i % 3) : coord(i, f);
      });
  const auto cloud = rm::decodePointCloud2(msg, "t");
  ASSERT_EQ(cloud.points.size(), 6u);
  EXPECT_EQ(cloud.points[5].intensity, 1005.0f);
  EXPECT_EQ(cloud.rings, 3);
}

TEST(PointCloud2, OrganizedCloudDropsAndCountsNaNPoints) {
  const auto msg =
      makeCloud({{"x", 7}, {"y", 7}, {"z", 7}}, 4, 3, [](size_t i, const std::string& f) {
        return i % 4 == 1 && f == "y" ? std::nan("") : coord(i, f);
      });
  const auto cloud = rm::decodePointCloud2(msg, "t");
  EXPECT_EQ(cloud.dropped_invalid, 3u);  // points 1, 5, 9
  ASSERT_EQ(cloud.points.size(), 9u);
  EXPECT_EQ(cloud.points[1].x, coord(2, "x"));  // point 1 gone, point 2 moved up
}

TEST(PointCloud2, RowStepWithRowPadding) {
  auto msg = makeCloud({{"x", 7}, {"y", 7}, {"z", 7}}, 2, 2, coord);
  rm::PointCloud2 padded = msg;
  padded.row_step = msg.row_step + 8;
  padded.data.assign(padded.row_step * 2, 0);
  for (int r = 0; r < 2; ++r)
    std::memcpy(&padded.data[r * padded.row_step], &msg.data[r * msg.row_step], msg.row_step);
  const auto cloud = rm::decodePointCloud2(padded, "t");
  ASSERT_EQ(cloud.points.size(), 4u);
  EXPECT_EQ(cloud.points[2].x, coord(2, "x"));
}

// Per-point times in the drivers' units all come out as seconds after the header stamp.
TEST(PointCloud2, PerPointTimesInEachUnit) {
  struct Case {
    const char* name;
    uint8_t datatype;
    std::function<double(size_t)> raw;
  };
  const double stamp = kEpoch + 0.5;
  const std::vector<Case> cases = {
      {"t", dt(FieldType::kUint32), [](size_t i) { return 1e6 * i; }},            // Ouster: ns
      {"time", dt(FieldType::kFloat32), [](size_t i) { return 0.001 * i; }},      // Velodyne: s
      {"offset_time", dt(FieldType::kUint32), [](size_t i) { return 1e6 * i; }},  // Livox: ns
      {"timestamp", dt(FieldType::kFloat64), [&](size_t i) { return stamp + 0.001 * i; }},  // Hesai
      {"timestamp", dt(FieldType::kFloat64), [&](size_t i) { return (stamp + 0.001 * i) * 1e9; }},
  };
  for (const Case& c : cases) {
    const auto msg = makeCloud(
        {{"x", 7}, {"y", 7}, {"z", 7}, {c.name, c.datatype}}, 1, 8,
        [&](size_t i, const std::string& f) { return f == c.name ? c.raw(i) : coord(i, f); }, 0,
        stamp);
    const auto cloud = rm::decodePointCloud2(msg, "t");
    ASSERT_EQ(cloud.point_times.size(), 8u) << c.name;
    for (size_t i = 0; i < 8; ++i)
      EXPECT_NEAR(cloud.point_times[i], 0.001 * i, 2e-6) << c.name << " " << i;
  }
}

TEST(PointCloud2, RefusesWhatItCannotRead) {
  auto msg = makeCloud({{"x", 7}, {"y", 7}, {"z", 7}}, 1, 3, coord);
  rm::PointCloud2 big = msg;
  big.is_bigendian = true;
  EXPECT_MENTIONS(errorOf([&] { rm::decodePointCloud2(big, "bag.bag: /points"); }),
                  "bag.bag: /points: big-endian");
  rm::PointCloud2 no_z = makeCloud({{"x", 7}, {"y", 7}}, 1, 3, coord);
  EXPECT_MENTIONS(errorOf([&] { rm::decodePointCloud2(no_z, "w"); }), "no 'z' field");
  rm::PointCloud2 short_data = msg;
  short_data.data.resize(msg.data.size() - 1);
  EXPECT_MENTIONS(errorOf([&] { rm::decodePointCloud2(short_data, "w"); }), "data holds");
  rm::PointCloud2 outside = msg;
  outside.fields[2].offset = msg.point_step - 2;
  EXPECT_MENTIONS(errorOf([&] { rm::decodePointCloud2(outside, "w"); }), "field 'z' at offset");
}

// ---- Images and calibration ------------------------------------------------------------------

namespace {

semsegmap::Image testImage(int w, int h, int seed = 0) {
  semsegmap::Image img(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      uint8_t* p = img.at(x, y);
      p[0] = static_cast<uint8_t>(x * 7 + seed);
      p[1] = static_cast<uint8_t>(y * 11 + 3 * seed);
      p[2] = static_cast<uint8_t>(x * y + seed);
    }
  return img;
}

// The message of `img` in another encoding, rows padded by `pad` bytes.
rm::Image encode(const semsegmap::Image& img, const std::string& encoding, uint32_t pad = 0) {
  const std::map<std::string, std::vector<int>> order = {
      {"rgb8", {0, 1, 2}}, {"bgr8", {2, 1, 0}}, {"rgba8", {0, 1, 2, -1}}, {"bgra8", {2, 1, 0, -1}}};
  const std::vector<int>& o = order.at(encoding);
  rm::Image m = rgb8Of(img, kEpoch, "cam");
  m.encoding = encoding;
  m.step = img.width * static_cast<uint32_t>(o.size()) + pad;
  m.data.assign(static_cast<size_t>(m.step) * img.height, 0);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (size_t c = 0; c < o.size(); ++c)
        m.data[y * m.step + x * o.size() + c] = o[c] < 0 ? 255 : img.at(x, y)[o[c]];
  return m;
}

}  // namespace

TEST(Images, ColourEncodingsWithRowPaddingDecodeToTheSameRgb) {
  const semsegmap::Image img = testImage(13, 7);
  for (const char* enc : {"rgb8", "bgr8", "rgba8", "bgra8"})
    EXPECT_EQ(rm::decodeImage(encode(img, enc, 5), "w"), img) << enc;
}

TEST(Images, MonoBecomesGreyRgb) {
  rm::Image m;
  m.width = 4;
  m.height = 2;
  m.encoding = "mono8";
  m.step = 4;
  m.data = {0, 50, 100, 150, 200, 250, 1, 2};
  const semsegmap::Image out = rm::decodeImage(m, "w");
  ASSERT_EQ(out.channels, 3);
  EXPECT_EQ(out.at(2, 0)[0], 100);
  EXPECT_EQ(out.at(2, 0)[1], 100);
  EXPECT_EQ(out.at(2, 0)[2], 100);
}

// A uniform colour mosaicked in each Bayer pattern demosaics back to that colour: the patterns
// are not mixed up (a swapped pattern gives the colour with red and blue exchanged).
TEST(Images, BayerPatternsDemosaicToTheRightColours) {
  const uint8_t rgb[3] = {200, 120, 40};
  const std::map<std::string, std::string> patterns = {{"bayer_rggb8", "RGGB"},
                                                       {"bayer_bggr8", "BGGR"},
                                                       {"bayer_gbrg8", "GBRG"},
                                                       {"bayer_grbg8", "GRBG"}};
  for (const auto& [encoding, layout] : patterns) {
    rm::Image m;
    m.width = m.step = 16;
    m.height = 16;
    m.encoding = encoding;
    m.data.resize(256);
    for (int y = 0; y < 16; ++y)
      for (int x = 0; x < 16; ++x) {
        const char c = layout[(y % 2) * 2 + x % 2];
        m.data[y * 16 + x] = rgb[c == 'R' ? 0 : c == 'G' ? 1 : 2];
      }
    const semsegmap::Image out = rm::decodeImage(m, "w");
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(out.at(8, 8)[c], rgb[c], 2) << encoding << " channel " << c;
  }
}

TEST(Images, RefusesUnknownEncodingsAndShortData) {
  rm::Image m = encode(testImage(4, 4), "rgb8");
  m.encoding = "16UC1";
  EXPECT_MENTIONS(errorOf([&] { rm::decodeImage(m, "bag.db3: /cam/image_raw"); }),
                  "bag.db3: /cam/image_raw: image encoding '16UC1' is not supported");
  rm::Image short_data = encode(testImage(4, 4), "rgb8");
  short_data.data.pop_back();
  EXPECT_MENTIONS(errorOf([&] { rm::decodeImage(short_data, "w"); }), "does not fit");
}

TEST(Images, CompressedPngIsExactAndJpegClose) {
  const semsegmap::Image img = testImage(32, 24);
  cv::Mat bgr(img.height, img.width, CV_8UC3);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(img.at(x, y)[2], img.at(x, y)[1], img.at(x, y)[0]);
  for (const char* format : {"png", "jpeg"}) {
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(cv::imencode(std::string(".") + (format == std::string("png") ? "png" : "jpg"), bgr,
                             bytes, {cv::IMWRITE_JPEG_QUALITY, 100}));
    const rm::CompressedImage m = compressedOf(bytes, format, kEpoch);
    const semsegmap::Image out = rm::decodeCompressedImage(m, "w");
    ASSERT_EQ(out.width, 32);
    ASSERT_EQ(out.height, 24);
    if (std::string(format) == "png") {
      EXPECT_EQ(out, img);
    } else {
      double err = 0;
      for (size_t i = 0; i < img.data.size(); ++i) err += std::abs(out.data[i] - img.data[i]);
      EXPECT_LT(err / img.data.size(), 6.0);
    }
  }
  const rm::CompressedImage broken = compressedOf({1, 2, 3, 4}, "jpeg", kEpoch);
  EXPECT_MENTIONS(errorOf([&] { rm::decodeCompressedImage(broken, "w: /c"); }),
                  "w: /c: compressed image");
}

TEST(CameraInfo, LensModels) {
  rm::CameraInfo m;
  m.width = 640;
  m.height = 480;
  m.K = {500, 0, 320, 0, 505, 240, 0, 0, 1};
  m.distortion_model = "plumb_bob";
  m.D = {-0.3, 0.1, 0.001, -0.002, 0.01};
  Camera cam = rm::cameraFromInfo(m, "w");
  EXPECT_EQ(cam.model, CameraModel::kRadialTangential);
  EXPECT_EQ(cam.fx, 500);
  EXPECT_EQ(cam.fy, 505);
  EXPECT_EQ(cam.cx, 320);
  EXPECT_EQ(cam.cy, 240);
  EXPECT_EQ(cam.distortion[4], 0.01);

  m.distortion_model = "rational_polynomial";
  m.D = {-0.3, 0.1, 0.001, -0.002, 0.01, 0, 0, 0};
  EXPECT_EQ(rm::cameraFromInfo(m, "w").distortion[3], -0.002);
  m.D[6] = 0.5;
  EXPECT_MENTIONS(errorOf([&] { rm::cameraFromInfo(m, "b.bag: /cam/camera_info"); }),
                  "b.bag: /cam/camera_info: rational_polynomial with non-zero k4 k5 k6");

  m.distortion_model = "equidistant";
  m.D = {0.1, 0.01, -0.001, 0.0005};
  cam = rm::cameraFromInfo(m, "w");
  EXPECT_EQ(cam.model, CameraModel::kEquidistant);
  EXPECT_EQ(cam.distortion[3], 0.0005);

  m.distortion_model = "plumb_bob";
  m.D.assign(5, 0.0);
  EXPECT_EQ(rm::cameraFromInfo(m, "w").model, CameraModel::kPinhole);
  m.distortion_model = "fov";
  EXPECT_MENTIONS(errorOf([&] { rm::cameraFromInfo(m, "w"); }), "distortion_model 'fov'");
  m.distortion_model = "plumb_bob";
  m.K[0] = 0;
  EXPECT_MENTIONS(errorOf([&] { rm::cameraFromInfo(m, "w"); }), "no positive focal lengths");
}

// ---- TF ----------------------------------------------------------------------------------------

TEST(Tf, ChainsStaticAndInterpolatedDynamicTransforms) {
  rm::TfBuffer tf;
  const Pose T_base_lidar = poseXyzYaw(0.5, 0, 1.8, 0.1);
  const Pose T_lidar_cam = poseXyzYaw(0.1, -0.2, 0, -0.3);
  tf.add(stampedOf("base_link", "velodyne", T_base_lidar, 0), true);
  tf.add(stampedOf("/velodyne", "camera", T_lidar_cam, 0), true);  // ROS 1's leading slash
  tf.add(stampedOf("odom", "base_link", poseXyzYaw(0, 0, 0, 0), 10.0), false);
  tf.add(stampedOf("odom", "base_link", poseXyzYaw(2, 0, 0, 0.2), 11.0), false);

  const auto T_cam_base = tf.lookup("camera", "base_link", 0);
  ASSERT_TRUE(T_cam_base);
  EXPECT_TRUE(T_cam_base->isApprox((T_base_lidar * T_lidar_cam).inverse(), 1e-12));
  const auto T_odom_cam = tf.lookup("odom", "camera", 10.5);
  ASSERT_TRUE(T_odom_cam);
  const Pose expected = poseXyzYaw(1, 0, 0, 0.1) * T_base_lidar * T_lidar_cam;
  EXPECT_TRUE(T_odom_cam->isApprox(expected, 1e-9));
  EXPECT_TRUE(tf.isStatic("camera", "base_link"));
  EXPECT_FALSE(tf.isStatic("odom", "camera"));

  std::string why;
  EXPECT_FALSE(tf.lookup("odom", "camera", 20.0, &why));
  EXPECT_MENTIONS(why, "'odom' -> 'base_link' has no sample around");
  EXPECT_FALSE(tf.lookup("map", "camera", 10.5, &why));
  EXPECT_MENTIONS(why, "no transform between 'map' and 'camera'");
  EXPECT_MENTIONS(why, "not in the tree: 'map'");
}

// ---- Wire formats ------------------------------------------------------------------------------

// A ROS 2 TFMessage written byte by byte from the CDR rules (not with fastcdr): the reader's
// layout of ROS 2 messages, alignment included, is checked against the standard, not against
// its own writer.
TEST(WireFormat, HandWrittenCdrTfMessage) {
  std::string b = {0, 1, 0, 0};  // encapsulation: CDR little-endian
  auto align = [&](size_t n) {
    while ((b.size() - 4) % n) b.push_back(0);
  };
  auto u32 = [&](uint32_t v) {
    align(4);
    b.append(reinterpret_cast<const char*>(&v), 4);
  };
  auto f64 = [&](double v) {
    align(8);
    b.append(reinterpret_cast<const char*>(&v), 8);
  };
  auto str = [&](const std::string& s) {
    u32(static_cast<uint32_t>(s.size() + 1));
    b += s;
    b.push_back('\0');
  };
  u32(1);           // one transform
  u32(1317000001);  // stamp.sec
  u32(500000000);   // stamp.nanosec
  str("odom");
  str("base_link");
  for (double v : {1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0}) f64(v);
  const rm::TfMessage m = rm::parseTfMessage({b, rm::WireFormat::kCdr, "x.db3", "/tf"});
  ASSERT_EQ(m.transforms.size(), 1u);
  EXPECT_DOUBLE_EQ(m.transforms[0].header.stamp_s, 1317000001.5);
  EXPECT_EQ(m.transforms[0].header.frame_id, "odom");
  EXPECT_EQ(m.transforms[0].child_frame_id, "base_link");
  EXPECT_EQ(m.transforms[0].transform.translation[2], 3.0);
  EXPECT_EQ(m.transforms[0].transform.rotation[3], 1.0);
  EXPECT_EQ(rm::toCdr(m), b);  // and the fixtures' writer writes exactly these bytes
}

TEST(WireFormat, TruncatedMessagesNameFileTopicAndField) {
  const std::string cdr = rm::toCdr(cloudOf({{1, 2, 3, 4}}, kEpoch));
  const std::string e = errorOf([&] {
    rm::parsePointCloud2(
        {cdr.substr(0, cdr.size() - 8), rm::WireFormat::kCdr, "run.db3", "/points"});
  });
  EXPECT_MENTIONS(
      e, "run.db3: truncated sensor_msgs/PointCloud2 message on /points (ends inside data)");
  std::string ros1(4, '\0');  // header.seq, then nothing
  const std::string e1 = errorOf([&] {
    rm::parseImage({ros1, rm::WireFormat::kRos1, "run.bag", "/img"});
  });
  EXPECT_MENTIONS(
      e1, "run.bag: truncated sensor_msgs/Image message on /img (ends inside header.stamp)");
}

// ---- Options -----------------------------------------------------------------------------------

TEST(RosbagOptions, ParsesEveryKey) {
  const RosbagOptions o = semsegmap::parseRosbagOptions(
      "lidar=/os/points,camera=/a/image_raw;/b/image_raw/compressed,odometry=/odom,"
      "base_frame=base,odom_frame=world,tolerance=0.03");
  EXPECT_EQ(o.lidar_topic, "/os/points");
  ASSERT_TRUE(o.camera_topics);
  EXPECT_EQ(*o.camera_topics,
            (std::vector<std::string>{"/a/image_raw", "/b/image_raw/compressed"}));
  EXPECT_EQ(o.odometry_topic, "/odom");
  EXPECT_EQ(o.base_frame, "base");
  EXPECT_EQ(o.odom_frame, "world");
  EXPECT_EQ(o.tolerance_s, 0.03);
  EXPECT_FALSE(semsegmap::parseRosbagOptions("").camera_topics);
  EXPECT_TRUE(semsegmap::parseRosbagOptions("camera=none").camera_topics->empty());
}

TEST(RosbagOptions, ErrorsNameTheKey) {
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"lidr=/p", "rosbag option 'lidr': unknown key"},
           {"lidar", "rosbag option 'lidar': expected key=value"},
           {"camera=", "rosbag option 'camera': empty value"},
           {"tolerance=-1", "rosbag option 'tolerance': expected a positive number"},
           {"tolerance=0.1s", "rosbag option 'tolerance': expected a positive number"},
           {"lidar=/a,lidar=/b", "rosbag option 'lidar': given twice"}}) {
    const std::string e = errorOf([&] { semsegmap::parseRosbagOptions(text); });
    EXPECT_MENTIONS(e, expected);
    EXPECT_ONE_LINE(e);
  }
}

// ---- Bags end to end ---------------------------------------------------------------------------

namespace {

// A small recording: a LiDAR at 10 Hz with per-point times, a distorted camera whose images come
// 10 ms after each scan, the rig in /tf_static, odometry in /tf at 20 Hz.
struct Recording {
  std::vector<std::vector<LidarPoint>> scans;
  std::vector<std::vector<float>> times;
  std::vector<semsegmap::Image> images;
  std::vector<double> stamps;
  Camera camera;
  Pose T_base_lidar = poseXyzYaw(0.3, 0.0, 1.7, 0.05);
  Pose T_camera_lidar = Pose::Identity();

  static Pose odometry(double t) {
    return poseXyzYaw(2.0 * (t - kEpoch), 0.1 * (t - kEpoch), 0, 0.2 * (t - kEpoch));
  }

  Recording() {
    camera.width = 40;
    camera.height = 30;
    camera.fx = 35;
    camera.fy = 36;
    camera.cx = 20.5;
    camera.cy = 14.5;
    camera.model = CameraModel::kRadialTangential;
    camera.distortion = {-0.2, 0.05, 0.001, -0.001, 0.002};
    // The optical frame: z forward along the LiDAR's x.
    T_camera_lidar.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    T_camera_lidar.translation() = Eigen::Vector3d(0.05, -0.1, -0.2);
    for (int f = 0; f < 4; ++f) {
      stamps.push_back(kEpoch + 0.1 * f);
      std::vector<LidarPoint> pts;
      std::vector<float> ts;
      for (int i = 0; i < 50; ++i) {
        pts.push_back(
            {float(5 + i * 0.1 + f), float(std::sin(i) * 3), float(0.01 * i - 0.5), float(i + f)});
        ts.push_back(0.002f * i);
      }
      scans.push_back(pts);
      times.push_back(ts);
      images.push_back(testImage(camera.width, camera.height, f));
    }
  }

  std::vector<BagMessage> staticTf(bool with_camera = true) const {
    rm::TfMessage tf;
    tf.transforms.push_back(stampedOf("base_link", "velodyne", T_base_lidar, kEpoch));
    if (with_camera)
      tf.transforms.push_back(
          stampedOf("base_link", "cam_optical", T_base_lidar * T_camera_lidar.inverse(), kEpoch));
    return {{"/tf_static", kEpoch - 1, tf}};
  }

  // lidar topics, the camera's images (those of `image_frames`) with CameraInfo, TF, odometry.
  std::vector<BagMessage> messages(bool camera_info = true, bool camera_tf = true,
                                   std::vector<int> image_frames = {0, 1, 2, 3}) const {
    std::vector<BagMessage> m = staticTf(camera_tf);
    for (double t = kEpoch - 0.05; t < kEpoch + 0.45; t += 0.05)
      m.push_back({"/tf", t, rm::TfMessage{{stampedOf("odom", "base_link", odometry(t), t)}}});
    for (size_t f = 0; f < scans.size(); ++f)
      m.push_back({"/velodyne_points", stamps[f] + 0.02, cloudOf(scans[f], stamps[f], times[f])});
    for (int f : image_frames) {
      const double t = stamps[f] + 0.01;
      m.push_back({"/cam/image_raw", t + 0.001, rgb8Of(images[f], t, "cam_optical")});
      if (camera_info)
        m.push_back({"/cam/camera_info", t + 0.001, infoOf(camera, t, "cam_optical")});
    }
    std::stable_sort(m.begin(), m.end(),
                     [](const BagMessage& a, const BagMessage& b) { return a.time < b.time; });
    return m;
  }
};

}  // namespace

TEST_P(Bags, RoundTripOfASyntheticRecording) {
  TempDir dir;
  const Recording rec;
  const fs::path bag = writeBag(GetParam(), dir.path(), rec.messages());
  RosbagReader reader(bag);
  EXPECT_EQ(reader.lidarTopic(), "/velodyne_points");
  EXPECT_EQ(reader.cameraTopics(), std::vector<std::string>{"/cam/image_raw"});
  const auto& info = reader.info();
  EXPECT_TRUE(info.has_odometry);
  // What `semsegmap info` shows of the reader's choices.
  EXPECT_EQ(info.origin.lidar, "topic /velodyne_points, frame velodyne, base frame base_link");
  EXPECT_EQ(info.origin.cameras,
            std::vector<std::string>{"topic /cam/image_raw, /cam/camera_info, frame cam_optical"});
  EXPECT_EQ(info.origin.odometry, "TF odom -> base_link");
  EXPECT_NEAR(info.rig.rate_hz, 10.0, 1e-3);  // stamps near 1.3e9 s carry ~1e-7 s rounding
  EXPECT_TRUE(info.rig.T_base_lidar.isApprox(rec.T_base_lidar, 1e-9));
  ASSERT_EQ(info.rig.cameras.size(), 1u);
  const Camera& cam = info.rig.cameras[0];
  EXPECT_EQ(cam.name, "cam");
  EXPECT_EQ(cam.model, CameraModel::kRadialTangential);
  EXPECT_EQ(cam.distortion, rec.camera.distortion);
  EXPECT_EQ(cam.fx, rec.camera.fx);
  EXPECT_EQ(cam.cy, rec.camera.cy);
  EXPECT_TRUE(cam.T_camera_lidar.isApprox(rec.T_camera_lidar, 1e-9));
  ASSERT_EQ(reader.size(), 4u);
  for (size_t f = 0; f < 4; ++f) {
    const Frame frame = reader.frame(f);
    EXPECT_NEAR(frame.timestamp_s, rec.stamps[f], 1e-6);
    ASSERT_EQ(frame.points.size(), rec.scans[f].size());
    for (size_t i = 0; i < frame.points.size(); ++i) {
      EXPECT_EQ(frame.points[i].x, rec.scans[f][i].x);
      EXPECT_EQ(frame.points[i].z, rec.scans[f][i].z);
      EXPECT_EQ(frame.points[i].intensity, rec.scans[f][i].intensity);
    }
    EXPECT_EQ(frame.point_times, rec.times[f]);
    ASSERT_EQ(frame.cameras.size(), 1u);
    EXPECT_EQ(frame.cameras[0].rgb, rec.images[f]);
    EXPECT_TRUE(frame.T_odom_base.isApprox(Recording::odometry(rec.stamps[f]), 1e-6)) << f;
  }
  EXPECT_THROW(reader.frame(4), std::out_of_range);
}

// `semsegmap convert` is a DatasetWriter over the reader: the converted folder must give the
// frames the bag gives, lens model, per-point times and odometry included.
TEST_P(Bags, ConvertedFolderGivesTheFramesOfTheBag) {
  TempDir dir;
  const Recording rec;
  RosbagReader bag(writeBag(GetParam(), dir.path(), rec.messages()));
  {
    semsegmap::DatasetWriter writer(dir.path() / "converted", bag.info());
    for (size_t f = 0; f < bag.size(); ++f) writer.write(bag.frame(f));
  }
  semsegmap::DatasetReader converted(dir.path() / "converted");
  EXPECT_TRUE(converted.info().has_odometry);
  ASSERT_EQ(converted.info().rig.cameras.size(), 1u);
  EXPECT_EQ(converted.info().rig.cameras[0].distortion, bag.info().rig.cameras[0].distortion);
  EXPECT_TRUE(converted.info().rig.T_base_lidar.isApprox(bag.info().rig.T_base_lidar, 1e-12));
  ASSERT_EQ(converted.size(), bag.size());
  for (size_t f = 0; f < bag.size(); ++f) {
    const Frame a = bag.frame(f), b = converted.frame(f);
    EXPECT_EQ(a.timestamp_s, b.timestamp_s);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (size_t i = 0; i < a.points.size(); ++i) EXPECT_EQ(a.points[i].y, b.points[i].y);
    EXPECT_EQ(a.point_times, b.point_times);
    EXPECT_EQ(a.cameras[0].rgb, b.cameras[0].rgb);
    EXPECT_TRUE(a.T_odom_base.isApprox(b.T_odom_base, 1e-12));
  }
}

TEST_P(Bags, OdometryTopicAndNoOdometry) {
  TempDir dir;
  const Recording rec;
  std::vector<BagMessage> msgs;
  for (const BagMessage& m : rec.messages())
    if (m.topic != "/tf") msgs.push_back(m);
  {
    const fs::path bag = writeBag(GetParam(), dir.path(), msgs);
    RosbagReader reader(bag);
    EXPECT_FALSE(reader.info().has_odometry);  // no Odometry topic, no odom frame
    EXPECT_EQ(reader.info().origin.odometry, "");
    EXPECT_EQ(reader.size(), 4u);
  }
  // The odometry of the LiDAR frame, moved to the base by TF.
  for (double t = kEpoch - 0.1; t < kEpoch + 0.5; t += 0.1)
    msgs.push_back(
        {"/odom", t,
         rm::Odometry{
             {t, "odom"}, "velodyne", transformOf(Recording::odometry(t) * rec.T_base_lidar)}});
  TempDir dir2;
  RosbagReader reader(writeBag(GetParam(), dir2.path(), msgs));
  ASSERT_TRUE(reader.info().has_odometry);
  EXPECT_EQ(reader.info().origin.odometry, "topic /odom (nav_msgs/Odometry)");
  for (size_t f = 0; f < reader.size(); ++f)
    EXPECT_TRUE(reader.frame(f).T_odom_base.isApprox(Recording::odometry(rec.stamps[f]), 1e-6))
        << f;
}

// A scan takes an image only within the tolerance; the others go without, never with a far one.
TEST_P(Bags, ScansWithoutANearImageGetNone) {
  TempDir dir;
  const Recording rec;
  std::vector<BagMessage> msgs = rec.messages(true, true, {0, 2});
  const double far = rec.stamps[3] + 0.08;  // beyond half the 0.1 s period
  msgs.push_back({"/cam/image_raw", far, rgb8Of(rec.images[3], far, "cam_optical")});
  RosbagReader reader(writeBag(GetParam(), dir.path(), msgs));
  ASSERT_EQ(reader.size(), 4u);
  EXPECT_EQ(reader.frame(0).cameras[0].rgb, rec.images[0]);
  EXPECT_TRUE(reader.frame(1).cameras[0].rgb.empty());
  EXPECT_EQ(reader.frame(2).cameras[0].rgb, rec.images[2]);
  EXPECT_TRUE(reader.frame(3).cameras[0].rgb.empty());
  // A wider tolerance, given as an option, pairs the far image.
  RosbagOptions wide;
  wide.tolerance_s = 0.1;
  RosbagReader widened(dir.path() / (GetParam() == BagKind::kRos1 ? "bag.bag" : "bag.db3"), wide);
  EXPECT_EQ(widened.frame(3).cameras[0].rgb, rec.images[3]);
}

TEST_P(Bags, CompressedImagesAndCameraChoice) {
  TempDir dir;
  const Recording rec;
  std::vector<BagMessage> msgs = rec.messages();
  for (size_t f = 0; f < 4; ++f) {
    const semsegmap::Image& img = rec.images[f];
    cv::Mat bgr(img.height, img.width, CV_8UC3);
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(img.at(x, y)[2], img.at(x, y)[1], img.at(x, y)[0]);
    std::vector<uint8_t> png;
    cv::imencode(".png", bgr, png);
    msgs.push_back({"/cam/image_raw/compressed", rec.stamps[f] + 0.03,
                    compressedOf(png, "png", rec.stamps[f] + 0.01, "cam_optical")});
  }
  std::stable_sort(msgs.begin(), msgs.end(),
                   [](const BagMessage& a, const BagMessage& b) { return a.time < b.time; });
  const fs::path bag = writeBag(GetParam(), dir.path(), msgs);
  // By type, the raw and the compressed stream of one camera are one camera, the raw one.
  EXPECT_EQ(RosbagReader(bag).cameraTopics(), std::vector<std::string>{"/cam/image_raw"});
  RosbagOptions compressed;
  compressed.camera_topics = std::vector<std::string>{"/cam/image_raw/compressed"};
  RosbagReader reader(bag, compressed);
  ASSERT_EQ(reader.info().rig.cameras.size(), 1u);
  EXPECT_EQ(reader.frame(2).cameras[0].rgb, rec.images[2]);  // PNG is lossless
  RosbagOptions none;
  none.camera_topics = std::vector<std::string>{};
  EXPECT_TRUE(RosbagReader(bag, none).info().rig.cameras.empty());
}

TEST_P(Bags, MissingCalibrationIsOneLineNamingTopicOrFrame) {
  TempDir dir;
  const Recording rec;
  const fs::path no_info = writeBag(GetParam(), dir.path(), rec.messages(false, true));
  const std::string e1 = errorOf([&] { RosbagReader r(no_info); });
  EXPECT_MENTIONS(
      e1, no_info.string() +
              ": image topic /cam/image_raw has no sensor_msgs/CameraInfo on /cam/camera_info");
  EXPECT_ONE_LINE(e1);

  TempDir dir2;
  const fs::path no_tf = writeBag(GetParam(), dir2.path(), rec.messages(true, false));
  const std::string e2 = errorOf([&] { RosbagReader r(no_tf); });
  EXPECT_MENTIONS(e2,
                  no_tf.string() +
                      ": camera /cam/image_raw: no transform between 'cam_optical' and 'velodyne'");
  EXPECT_ONE_LINE(e2);

  RosbagOptions wrong_base;
  wrong_base.base_frame = "chassis";
  const std::string e3 = errorOf([&] { RosbagReader r(no_info, wrong_base); });
  EXPECT_MENTIONS(e3, "base_frame=chassis: no transform between 'chassis' and 'velodyne'");
}

TEST_P(Bags, SeveralLidarTopicsNeedAChoice) {
  TempDir dir;
  const Recording rec;
  std::vector<BagMessage> msgs = rec.messages();
  msgs.push_back({"/front/points", kEpoch + 0.3, cloudOf(rec.scans[0], kEpoch + 0.3)});
  const fs::path bag = writeBag(GetParam(), dir.path(), msgs);
  const std::string e = errorOf([&] { RosbagReader r(bag); });
  EXPECT_MENTIONS(e, bag.string() + ": several sensor_msgs/PointCloud2 topics (");
  EXPECT_MENTIONS(e, "/front/points");
  EXPECT_MENTIONS(e, "/velodyne_points");
  EXPECT_MENTIONS(e, "lidar=TOPIC");
  EXPECT_ONE_LINE(e);
  RosbagOptions choice;
  choice.lidar_topic = "/velodyne_points";
  EXPECT_EQ(RosbagReader(bag, choice).size(), 4u);
  choice.lidar_topic = "/cam/image_raw";
  EXPECT_MENTIONS(
      errorOf([&] { RosbagReader r(bag, choice); }),
      "topic /cam/image_raw is a sensor_msgs/Image, not a sensor_msgs/PointCloud2 (lidar=)");
}

TEST_P(Bags, CorruptAndTruncatedBagsNameTheFile) {
  TempDir dir;
  const fs::path name = dir.path() / (GetParam() == BagKind::kRos1 ? "junk.bag" : "junk.db3");
  std::ofstream(name) << std::string(3000, 'x');
  const std::string e = errorOf([&] { RosbagReader r(name); });
  EXPECT_EQ(e.rfind(name.string() + ": ", 0), 0u) << e;
  EXPECT_ONE_LINE(e);

  const Recording rec;
  const fs::path bag = writeBag(GetParam(), dir.path(), rec.messages());
  fs::resize_file(bag, fs::file_size(bag) / 2);
  const std::string t = errorOf([&] {
    RosbagReader r(bag);
    for (size_t i = 0; i < r.size(); ++i) r.frame(i);
  });
  EXPECT_EQ(t.rfind(bag.string() + ": ", 0), 0u) << t;
  EXPECT_ONE_LINE(t);
}

INSTANTIATE_TEST_SUITE_P(Formats, Bags, ::testing::Values(BagKind::kRos1, BagKind::kRos2),
                         kindName);

// ---- ROS 2 specifics ---------------------------------------------------------------------------

TEST(Ros2Bag, FolderWithMetadataAndSplitFiles) {
  TempDir dir;
  const Recording rec;
  std::vector<BagMessage> msgs = rec.messages();
  const auto half = msgs.begin() + static_cast<long>(msgs.size() / 2);
  writeRos2(dir.path() / "run_0.db3", {msgs.begin(), half});
  writeRos2(dir.path() / "run_1.db3", {half, msgs.end()});
  std::ofstream(dir.path() / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: sqlite3\n"
         "  relative_file_paths:\n    - run_0.db3\n    - run_1.db3\n  compression_format: \"\"\n";
  RosbagReader reader(dir.path());
  ASSERT_EQ(reader.size(), 4u);
  EXPECT_EQ(reader.frame(3).cameras[0].rgb, rec.images[3]);
  EXPECT_EQ(reader.frame(3).points.size(), rec.scans[3].size());

  std::ofstream(dir.path() / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  storage_identifier: rosbag_v2\n  relative_file_paths: "
         "[run_0.bag]\n";
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(dir.path()); }),
                  "metadata.yaml: storage 'rosbag_v2' is not read (sqlite3, mcap)");
}

TEST(Ros2Bag, EmptyTopicAndNonCdrSerialization) {
  TempDir dir;
  const Recording rec;
  std::vector<BagMessage> msgs;
  for (const BagMessage& m : rec.messages())
    if (m.topic != "/velodyne_points") msgs.push_back(m);
  writeRos2(dir.path() / "empty.db3", msgs, {{"/velodyne_points", rm::kPointCloud2}});
  const std::string e = errorOf([&] { RosbagReader r(dir.path() / "empty.db3"); });
  EXPECT_MENTIONS(e,
                  (dir.path() / "empty.db3").string() + ": topic /velodyne_points has no messages");

  writeRos2(dir.path() / "json.db3", rec.messages(), {}, "json");
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(dir.path() / "json.db3"); }),
                  "topic /velodyne_points is serialized as 'json'; only cdr is read");
}

TEST(Ros2Bag, NotABag) {
  TempDir dir;
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(dir.path() / "nothing.db3"); }),
                  "nothing.db3: no such bag");
  std::ofstream(dir.path() / "x.txt") << "hello";
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(dir.path() / "x.txt"); }), "x.txt: not a bag");
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(dir.path()); }),
                  "no metadata.yaml and no .db3 or .mcap file");
}

// ---- The real KITTI raw sample through both kinds of bag -------------------------------------

namespace {

const fs::path kKittiDrive =
    fs::path(SEMSEGMAP_SHARED_DATA) / "kitti_raw_2011_09_26_sample" / "2011_09_26" / "sample_sync";

// The drive as a robot would have recorded it: Velodyne clouds, the left colour camera with its
// CameraInfo, and the LiDAR-to-camera extrinsic in /tf_static.
std::vector<BagMessage> kittiMessages(semsegmap::KittiRawReader& kitti, size_t frames) {
  const Camera& cam = kitti.info().rig.cameras.at(0);
  rm::TfMessage tf{{stampedOf("camera_color_left", "velo_link", cam.T_camera_lidar, kEpoch)}};
  std::vector<BagMessage> m = {{"/tf_static", kEpoch, tf}};
  for (size_t i = 0; i < frames; ++i) {
    const Frame f = kitti.frame(i);
    const double t = kEpoch + f.timestamp_s;
    rm::PointCloud2 cloud = cloudOf(f.points, t);
    cloud.header.frame_id = "velo_link";
    m.push_back({"/kitti/velo/pointcloud", t, cloud});
    m.push_back({"/kitti/camera_color_left/image_raw", t + 0.001,
                 rgb8Of(f.cameras.at(0).rgb, t, "camera_color_left")});
    m.push_back(
        {"/kitti/camera_color_left/camera_info", t + 0.001, infoOf(cam, t, "camera_color_left")});
  }
  return m;
}

}  // namespace

TEST_P(Bags, RealKittiSampleRoundTrip) {
  if (!fs::exists(kKittiDrive))
    GTEST_SKIP() << "the real KITTI sample is absent (" << kKittiDrive.string()
                 << "): ../shared/data is not beside this checkout";
  semsegmap::KittiRawReader kitti(kKittiDrive);
  const size_t frames = std::min<size_t>(3, kitti.size());
  TempDir dir;
  const fs::path bag = writeBag(GetParam(), dir.path(), kittiMessages(kitti, frames));
  RosbagReader reader(bag);
  ASSERT_EQ(reader.size(), frames);
  const Camera& want = kitti.info().rig.cameras[0];
  const Camera& got = reader.info().rig.cameras.at(0);
  EXPECT_EQ(got.width, want.width);
  EXPECT_EQ(got.height, want.height);
  EXPECT_EQ(got.fx, want.fx);
  EXPECT_EQ(got.cx, want.cx);
  EXPECT_EQ(got.model, want.model);
  // Through a quaternion: the calibration's rounded rotation comes back orthonormalised.
  EXPECT_TRUE(got.T_camera_lidar.isApprox(want.T_camera_lidar, 1e-6));
  for (size_t i = 0; i < frames; ++i) {
    const Frame a = kitti.frame(i), b = reader.frame(i);
    ASSERT_EQ(b.points.size(), a.points.size());
    EXPECT_GT(b.points.size(), 10000u);
    for (size_t p = 0; p < a.points.size(); p += 97) {
      EXPECT_EQ(b.points[p].x, a.points[p].x);
      EXPECT_EQ(b.points[p].intensity, a.points[p].intensity);
    }
    EXPECT_EQ(b.cameras.at(0).rgb, a.cameras.at(0).rgb);
  }
}

// The README's worked example, bag in, map out, another drive localized against it, run line
// by line as the README shows it (`build/semsegmap` is this build's binary) in a folder that
// holds monday.bag and tuesday.bag (the real KITTI raw sample with its oxts as /odom) and a copy
// of config/: the copied config must still find the shipped models.
TEST(ReadmeBagExample, RunsAsTheReadmeShowsIt) {
  if (!SEMSEGMAP_WITH_ROS1)
    GTEST_SKIP() << "this build reads no ROS 1 bags (SEMSEGMAP_WITH_ROS1=OFF)";
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "config/lidar-camera.yaml's descriptor needs libtorch";
  if (!fs::exists(kKittiDrive))
    GTEST_SKIP() << "the real KITTI sample is absent (" << kKittiDrive.string() << ")";
  // The sample has no oxts: its odometry is the project's LiDAR odometry, as a robot's would be.
  TempDir dir;
  const std::string odometry = "'" + std::string(SEMSEGMAP_BINARY) +
                               "' odometry --dataset kitti-raw:" + kKittiDrive.string() +
                               " --out '" + (dir.path() / "odo").string() + "' > /dev/null 2>&1";
  ASSERT_EQ(std::system(odometry.c_str()), 0) << odometry;
  std::ifstream poses(dir.path() / "odo" / "trajectory_kitti.txt");
  semsegmap::KittiRawReader kitti(kKittiDrive);
  std::vector<BagMessage> messages = kittiMessages(kitti, kitti.size());
  const Pose T_base_lidar = kitti.info().rig.T_base_lidar;
  for (size_t i = 0; i < kitti.size(); ++i) {
    Pose T_odom_base = Pose::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) poses >> T_odom_base.matrix()(r, c);
    ASSERT_TRUE(poses) << "line " << i << " of the odometry";
    const double t = kEpoch + kitti.frame(i).timestamp_s;
    messages.push_back(
        {"/odom", t,
         rm::Odometry{{t, "odom"}, "velo_link", transformOf(T_odom_base * T_base_lidar)}});
  }
#if SEMSEGMAP_WITH_ROS1
  writeRos1(dir.path() / "monday.bag", messages);
  writeRos1(dir.path() / "tuesday.bag", messages);
#endif
  fs::create_directories(dir.path() / "config");
  for (const auto& entry : fs::directory_iterator(fs::path(SEMSEGMAP_SOURCE_DIR) / "config"))
    if (entry.path().extension() == ".yaml")
      fs::copy_file(entry.path(), dir.path() / "config" / entry.path().filename());
  const std::vector<std::string> block = semsegmap::test_support::blockContaining(
      fs::path(SEMSEGMAP_SOURCE_DIR) / "README.md", "rosbag:tuesday.bag");
  size_t ran = 0;
  for (std::string line : block) {
    if (line.rfind("build/semsegmap ", 0) != 0) continue;
    line.replace(0, 15, std::string("'") + SEMSEGMAP_BINARY + "'");
    const std::string command = "cd '" + dir.path().string() + "' && " +
                                line.substr(0, line.find(" #")) + " > run.out 2> run.err";
    const int status = std::system(command.c_str());
    ASSERT_EQ(status, 0) << line << "\n"
                         << semsegmap::test_support::readFile(dir.path() / "run.err");
    ++ran;
  }
  EXPECT_EQ(ran, 3u) << "map, localize, convert";
  // The localize line's output: every frame of the same drive is localized.
  const std::string summary =
      semsegmap::test_support::readFile(dir.path() / "tuesday/summary.json");
  EXPECT_NE(summary.find("\"frames\": 10"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"n_localizations\": 10,"), std::string::npos) << summary;
  // The drive moves a few metres: the odometry of the bag, not a standing robot.
  const size_t at = summary.find("\"distance_m\": ");
  ASSERT_NE(at, std::string::npos) << summary;
  EXPECT_GT(std::stod(summary.substr(at + 14)), 1.0) << summary;
  EXPECT_TRUE(fs::exists(dir.path() / "monday.map"));
  EXPECT_TRUE(fs::exists(dir.path() / "monday"));
}

// ---- MCAP --------------------------------------------------------------------------------------

namespace {

// Little-endian MCAP records, laid out as the specification says (mcap.dev/spec).
struct McapOut {
  std::string b;
  template <typename T>
  void put(T v) {
    b.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void str(const std::string& s) {
    put(static_cast<uint32_t>(s.size()));
    b += s;
  }
  void record(uint8_t op, const std::string& content) {
    put(op);
    put(static_cast<uint64_t>(content.size()));
    b += content;
  }
};

std::string compress(const std::string& raw, const std::string& compression) {
  std::string out;
  if (compression == "zstd") {
    out.resize(ZSTD_compressBound(raw.size()));
    out.resize(ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 3));
  } else if (compression == "lz4") {
    out.resize(LZ4F_compressFrameBound(raw.size(), nullptr));
    out.resize(LZ4F_compressFrame(out.data(), out.size(), raw.data(), raw.size(), nullptr));
  } else {
    out = raw;
  }
  return out;
}

// Schema and Channel records go into the chunk (or, unchunked, the data section) where a topic
// first appears; chunks hold `per_chunk` messages (0: no chunks at all).
void writeMcap(const fs::path& file, const std::vector<BagMessage>& messages,
               const std::string& compression, size_t per_chunk) {
  McapOut f;
  f.b = std::string("\x89MCAP0\r\n", 8);
  McapOut header;
  header.str("ros2");
  header.str("semsegmap test");
  f.record(0x01, header.b);
  std::map<std::string, uint16_t> channels;
  McapOut pending;  // the records of the chunk being filled
  size_t in_chunk = 0;
  auto flush = [&] {
    if (pending.b.empty()) return;
    McapOut chunk;
    chunk.put<uint64_t>(0);
    chunk.put<uint64_t>(0);
    chunk.put(static_cast<uint64_t>(pending.b.size()));
    chunk.put<uint32_t>(0);  // no CRC
    chunk.str(compression);
    const std::string packed = compress(pending.b, compression);
    chunk.put(static_cast<uint64_t>(packed.size()));
    chunk.b += packed;
    f.record(0x06, chunk.b);
    pending.b.clear();
    in_chunk = 0;
  };
  for (const BagMessage& m : messages) {
    McapOut& out = per_chunk > 0 ? pending : f;
    if (!channels.count(m.topic)) {
      const uint16_t id = static_cast<uint16_t>(channels.size() + 1);
      channels[m.topic] = id;
      McapOut schema, channel;
      schema.put(id);
      schema.str(ros2TypeName(typeName(m.message)));
      schema.str("ros2msg");
      schema.str("");
      out.record(0x03, schema.b);
      channel.put(id);
      channel.put(id);
      channel.str(m.topic);
      channel.str("cdr");
      channel.put<uint32_t>(0);  // no metadata
      out.record(0x04, channel.b);
    }
    McapOut msg;
    msg.put(channels[m.topic]);
    msg.put<uint32_t>(0);
    msg.put(static_cast<uint64_t>(std::llround(m.time * 1e9)));
    msg.put(static_cast<uint64_t>(std::llround(m.time * 1e9)));
    msg.b += std::visit([](const auto& v) { return rm::toCdr(v); }, m.message);
    out.record(0x05, msg.b);
    if (per_chunk > 0 && ++in_chunk == per_chunk) flush();
  }
  flush();
  f.record(0x0F, std::string(4, '\0'));   // data end, no CRC
  f.record(0x02, std::string(20, '\0'));  // footer: no summary
  f.b += std::string("\x89MCAP0\r\n", 8);
  std::ofstream(file, std::ios::binary) << f.b;
}

}  // namespace

TEST(Mcap, RoundTripInEveryChunkCompression) {
  const Recording rec;
  for (const auto& [compression, per_chunk] :
       std::vector<std::pair<std::string, size_t>>{{"zstd", 7}, {"lz4", 5}, {"", 3}, {"", 0}}) {
    TempDir dir;
    const fs::path bag = dir.path() / "run.mcap";
    writeMcap(bag, rec.messages(), compression, per_chunk);
    RosbagReader reader(bag);
    const std::string variant = "'" + compression + "' per chunk " + std::to_string(per_chunk);
    ASSERT_EQ(reader.size(), 4u) << variant;
    EXPECT_TRUE(reader.info().has_odometry) << variant;
    EXPECT_TRUE(reader.info().rig.cameras.at(0).T_camera_lidar.isApprox(rec.T_camera_lidar, 1e-9));
    for (size_t f = 0; f < 4; ++f) {
      const Frame frame = reader.frame(f);
      ASSERT_EQ(frame.points.size(), rec.scans[f].size()) << variant;
      EXPECT_EQ(frame.points[7].y, rec.scans[f][7].y) << variant;
      EXPECT_EQ(frame.point_times, rec.times[f]) << variant;
      EXPECT_EQ(frame.cameras[0].rgb, rec.images[f]) << variant;
      EXPECT_TRUE(frame.T_odom_base.isApprox(Recording::odometry(rec.stamps[f]), 1e-6)) << variant;
    }
  }
}

TEST(Mcap, BagFolderWithMetadata) {
  TempDir dir;
  const Recording rec;
  writeMcap(dir.path() / "run_0.mcap", rec.messages(), "zstd", 4);
  std::ofstream(dir.path() / "metadata.yaml")
      << "rosbag2_bagfile_information:\n  storage_identifier: mcap\n  relative_file_paths:\n"
         "    - run_0.mcap\n";
  RosbagReader reader(dir.path());
  ASSERT_EQ(reader.size(), 4u);
  EXPECT_EQ(reader.frame(1).cameras[0].rgb, rec.images[1]);
}

TEST(Mcap, CorruptFilesNameTheFile) {
  TempDir dir;
  const Recording rec;
  const fs::path bad_magic = dir.path() / "bad.mcap";
  std::ofstream(bad_magic) << "PK\x03\x04 this is a zip";
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(bad_magic); }),
                  bad_magic.string() + ": not an MCAP file (bad magic)");

  const fs::path cut = dir.path() / "cut.mcap";
  writeMcap(cut, rec.messages(), "zstd", 6);
  fs::resize_file(cut, fs::file_size(cut) * 2 / 3);
  const std::string e = errorOf([&] { RosbagReader r(cut); });
  EXPECT_EQ(e.rfind(cut.string() + ": truncated MCAP file", 0), 0u) << e;
  EXPECT_ONE_LINE(e);

  const fs::path bz2 = dir.path() / "bz2.mcap";
  writeMcap(bz2, rec.messages(), "bz2", 6);  // written uncompressed, but named bz2
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(bz2); }),
                  bz2.string() + ": MCAP chunk compression 'bz2' is not read (zstd, lz4 or none)");

  // A chunk whose compressed bytes are damaged (zstd checks its frame header).
  const fs::path damaged = dir.path() / "damaged.mcap";
  writeMcap(damaged, rec.messages(), "zstd", 100);
  std::string bytes;
  {
    std::ifstream in(damaged, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const size_t frame = bytes.find("\x28\xB5\x2F\xFD");  // the zstd frame's magic number
  ASSERT_NE(frame, std::string::npos);
  bytes[frame] = 'X';
  std::ofstream(damaged, std::ios::binary) << bytes;
  EXPECT_MENTIONS(errorOf([&] { RosbagReader r(damaged); }),
                  damaged.string() + ": corrupt MCAP chunk (zstd: ");
}

// A chunk whose `records` size is near 2^64 wrapped the bound check around (offset + size) and
// was allocated whole: now it is refused as a chunk whose records end past it.
TEST(Mcap, ChunkSizesNearTwoToTheSixtyFourAreRefused) {
  TempDir dir;
  const Recording rec;
  const fs::path bag = dir.path() / "wrapped.mcap";
  writeMcap(bag, rec.messages(), "", 100);
  std::string bytes;
  {
    std::ifstream in(bag, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  // The chunk record: opcode, length, two times, uncompressed size and crc, the compression
  // name (empty: a uint32 0), then the uint64 size of its records.
  uint64_t header_length = 0;  // the Header record follows the magic; the chunk follows it
  std::memcpy(&header_length, bytes.data() + 8 + 1, 8);
  const size_t chunk = 8 + 9 + header_length;
  ASSERT_EQ(bytes[chunk], '\x06');
  const size_t records_size = chunk + 9 + 8 + 8 + 8 + 4 + 4;
  const uint64_t huge = ~uint64_t{0} - 16;
  std::memcpy(bytes.data() + records_size, &huge, 8);
  std::ofstream(bag, std::ios::binary) << bytes;
  const std::string e = errorOf([&] { RosbagReader r(bag); });
  EXPECT_MENTIONS(e, bag.string() + ": corrupt MCAP chunk at byte " + std::to_string(chunk));
  EXPECT_ONE_LINE(e);
}

// What the message harness (fuzz/fuzz_ros_messages.cpp) found: its first byte chooses the type
// (0: PointCloud2, 1: Image, 2: CompressedImage) and the wire format (high bit: CDR), the rest is
// the message. A reproducer may be a valid message that hung (a cloud of 4 * 10^9 empty rows): each
// must be decoded, or refused naming the topic, within a second.
TEST(FuzzRegressions, RosMessages) {
  for (const auto& [name, bytes] : semsegmap::test_support::fuzzRegressions("ros_messages")) {
    ASSERT_FALSE(bytes.empty());
    rm::SerializedMessage m;
    m.format = bytes[0] & 0x80 ? rm::WireFormat::kCdr : rm::WireFormat::kRos1;
    m.bytes = bytes.substr(1);
    m.file = "fuzz.bag";
    m.topic = "/fuzz/topic";
    const int type = (bytes[0] & 0x7f) % 7;
    ASSERT_LE(type, 2) << name << ": a type this test does not decode";
    const auto start = std::chrono::steady_clock::now();
    semsegmap::test_support::expectNoFinding(name, "/fuzz/topic", [&] {
      if (type == 0) rm::decodePointCloud2(rm::parsePointCloud2(m), m.topic);
      if (type == 1) rm::decodeImage(rm::parseImage(m), m.topic);
      if (type == 2) rm::decodeCompressedImage(rm::parseCompressedImage(m), m.topic);
    });
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0)
        << name;
  }
}

#if SEMSEGMAP_WITH_ROS1
// Where the data of a bag's first chunk starts: the records walked by their lengths (uint32
// header length, header, uint32 data length, data) to the first whose header holds op=0x05.
size_t firstChunkData(const std::string& bag) {
  const auto u32 = [&](size_t at) {
    uint32_t v = 0;
    std::memcpy(&v, bag.data() + at, 4);
    return v;
  };
  for (size_t at = 13; at + 8 <= bag.size();) {
    const uint32_t header = u32(at), data = u32(at + 4 + header);
    if (bag.substr(at + 4, header).find(std::string("op=\x05", 4)) != std::string::npos)
      return at + 8 + header;
    at += 8 + header + data;
  }
  return std::string::npos;
}

// rosbag allocates a chunk's buffer by the size its header states, and reads the records in it
// by their lengths: both are checked when the bag opens, with one line naming the bag.
TEST(Ros1Chunks, ACorruptChunkSizeOrInnerRecordIsRefusedWhenTheBagOpens) {
  TempDir dir;
  std::vector<BagMessage> messages;
  for (double t = kEpoch; t < kEpoch + 0.35; t += 0.1)
    messages.push_back(
        {"/odom", t, rm::Odometry{{t, "odom"}, "base_link", transformOf(Pose::Identity())}});
  const fs::path plain = dir.path() / "plain.bag", packed = dir.path() / "packed.bag";
  writeRos1(plain, messages);
  writeRos1(packed, messages, rosbag::compression::BZ2);
  for (const fs::path& good : {plain, packed}) EXPECT_NO_THROW(rm::openBagStorage(good));
  const auto refusal = [&](const std::string& bytes) {
    const fs::path bad = dir.path() / "bad.bag";
    std::ofstream(bad, std::ios::binary) << bytes;
    const std::string e = errorOf([&] { rm::openBagStorage(bad); });
    EXPECT_EQ(e.rfind(bad.string() + ": truncated or corrupt ROS 1 bag (the record at byte ", 0),
              0u)
        << e;
    EXPECT_ONE_LINE(e);
    return e;
  };
  const auto withSize = [](std::string bytes, uint32_t size) {
    const size_t at = bytes.find("size=");
    std::memcpy(bytes.data() + at + 5, &size, 4);
    return bytes;
  };
  const std::string plain_bytes = semsegmap::readFileBytes(plain),
                    packed_bytes = semsegmap::readFileBytes(packed);
  EXPECT_MENTIONS(refusal(withSize(plain_bytes, 0xFFFFFF00u)), "says it holds 4294967040");
  EXPECT_MENTIONS(refusal(withSize(packed_bytes, 0x7FFFFFFFu)), "says it unpacks to 2147483647");
  std::string inner = plain_bytes;
  const size_t data = firstChunkData(inner);
  ASSERT_NE(data, std::string::npos);
  const uint32_t huge = 0x7FFFFFF0u;
  std::memcpy(inner.data() + data, &huge, 4);
  EXPECT_MENTIONS(refusal(inner), "ends past the end of its chunk");
}
#endif

// What the storage harness found: ROS 1 bags whose record lengths rosbag allocated as read.
TEST(FuzzRegressions, BagStorages) {
  TempDir dir;
  for (const auto& [name, bytes] : semsegmap::test_support::fuzzRegressions("rosbag_storage")) {
    const fs::path bag = dir.path() / (bytes.rfind("#ROSBAG", 0) == 0 ? "input.bag" : "input.mcap");
    std::ofstream(bag, std::ios::binary) << bytes;
    semsegmap::test_support::expectCleanRefusal(name, bag.string(), [&] {
      const auto storage = rm::openBagStorage(bag);
      for (const rm::BagTopic& topic : storage->topics()) storage->messages(topic.name);
    });
  }
}

// What the .db3 harness found (fuzz/fuzz_rosbag_sqlite.cpp builds the bag from the input's
// metadata.yaml and table rows, with the same code as here): a metadata.yaml that lists an
// absolute path, whose error named that path and not the bag; a YAML error of two lines.
TEST(FuzzRegressions, SqliteBags) {
  for (const auto& [name, bytes] : semsegmap::test_support::fuzzRegressions("rosbag_sqlite")) {
    TempDir dir;
    const std::string separator = "--8<--\n";
    const size_t at = bytes.find(separator);
    const std::string metadata = bytes.substr(0, at);
    const std::string rows = at == std::string::npos ? "" : bytes.substr(at + separator.size());
    const fs::path bag = dir.path() / "bag";
    fs::create_directories(bag);
    semsegmap::fuzz::writeBagDatabase(bag / "bag_0.db3", rows);
    if (!metadata.empty()) std::ofstream(bag / "metadata.yaml", std::ios::binary) << metadata;
    semsegmap::test_support::expectNoFinding(name, bag.string(), [&] {
      const auto storage = rm::openBagStorage(metadata.empty() ? bag / "bag_0.db3" : bag);
      for (const rm::BagTopic& topic : storage->topics()) storage->messages(topic.name);
    });
  }
}
