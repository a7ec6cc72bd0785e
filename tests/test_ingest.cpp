// A robot's own data in: rig files, lens models, point cloud files of any layout, folders of
// scans and pictures, pose files. Fixtures are written by the tests; the real samples in
// ../shared/data (KITTI 00 as PCD, the PJLab rig) are read when present.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <random>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "error_text.h"
#include "fuzz_regressions.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/enrich/enricher.h"
#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/dataset_reader.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/io/folder_reader.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/kitti_calib.h"
#include "semsegmap/io/point_cloud_file.h"
#include "semsegmap/io/rig_file.h"
#include "semsegmap/io/semantic_kitti_reader.h"
#include "semsegmap/io/trajectory_file.h"
#include "semsegmap/pipeline/pipeline.h"
#include "temp_dir.h"

#if SEMSEGMAP_WITH_PCL
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <pcl/point_types.h>
#endif

namespace fs = std::filesystem;
using namespace semsegmap;
using semsegmap::test_support::errorOf;
using semsegmap::test_support::TempDir;

namespace {

const fs::path kShared = SEMSEGMAP_SHARED_DATA;

void writeText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

const char* const kRig = R"(rig_format_version: 1
name: test-rig
rate_hz: 10
lidar:
  folder: scans
  T_lidar_base:
    translation: [0, 0, -1.5]
    quaternion_wxyz: [1, 0, 0, 0]
cameras:
  - name: front
    width: 64
    height: 48
    fx: 40
    fy: 40
    cx: 32
    cy: 24
    model: radtan
    distortion: [-0.1, 0.01, 0.001, -0.002]
    T_lidar_camera:
      translation: [0.2, 0, -0.1]
      quaternion_xyzw: [-0.5, 0.5, -0.5, 0.5]
)";

}  // namespace

// ------------------------------------------------------------------------------------------
// Lens models against OpenCV's own projection.

TEST(LensModel, RadialTangentialMatchesOpenCv) {
  Camera cam;
  cam.model = CameraModel::kRadialTangential;
  cam.distortion = {-0.28, 0.07, 0.0012, -0.0008, 0.01};
  const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  const std::vector<double> d(cam.distortion.begin(), cam.distortion.end());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> lateral(-0.8, 0.8);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(lateral(rng), lateral(rng), 1.0);
    std::vector<cv::Point2d> uv;
    cv::projectPoints(std::vector<cv::Point3d>{{p.x(), p.y(), p.z()}}, cv::Vec3d(0, 0, 0),
                      cv::Vec3d(0, 0, 0), K, d, uv);
    const auto ours = cam.project(p);
    ASSERT_TRUE(ours.has_value());
    EXPECT_NEAR(ours->x(), uv[0].x, 1e-9);
    EXPECT_NEAR(ours->y(), uv[0].y, 1e-9);
    // And back: the pixel's ray is the point's direction.
    EXPECT_LT((cam.pixelRay(ours->x(), ours->y()) - p.normalized()).norm(), 1e-7);
  }
}

TEST(LensModel, EquidistantMatchesOpenCvFisheye) {
  Camera cam;
  cam.model = CameraModel::kEquidistant;
  cam.distortion = {0.05, -0.01, 0.002, -0.0003, 0.0};
  const cv::Matx33d K(cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1);
  const cv::Vec4d d(cam.distortion[0], cam.distortion[1], cam.distortion[2], cam.distortion[3]);
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> lateral(-2.5, 2.5);  // up to ~74 degrees off axis
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(lateral(rng), lateral(rng), 1.0);
    std::vector<cv::Point2d> uv;
    cv::fisheye::projectPoints(std::vector<cv::Point3d>{{p.x(), p.y(), p.z()}}, uv,
                               cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, d);
    const auto ours = cam.project(p);
    ASSERT_TRUE(ours.has_value());
    EXPECT_NEAR(ours->x(), uv[0].x, 1e-7);
    EXPECT_NEAR(ours->y(), uv[0].y, 1e-7);
    EXPECT_LT((cam.pixelRay(ours->x(), ours->y()) - p.normalized()).norm(), 1e-7);
  }
}

TEST(LensModel, RefusesWhereThePolynomialFoldsBack) {
  Camera cam;
  cam.model = CameraModel::kRadialTangential;
  cam.distortion = {-0.5, 0.0, 0.0, 0.0, 0.0};  // r (1 - 0.5 r^2) turns at r = 0.816
  EXPECT_TRUE(cam.project({0.5, 0.0, 1.0}).has_value());
  // Far off axis the polynomial comes back towards the centre: that pixel would be wrong.
  EXPECT_FALSE(cam.project({1.5, 0.0, 1.0}).has_value());
  EXPECT_FALSE(cam.project({0.0, 0.0, -1.0}).has_value());  // behind
}

TEST(LensModel, RigValidationNamesTheCamera) {
  SensorRig rig;
  Camera cam;
  cam.name = "left";
  cam.distortion[0] = 0.1;  // pinhole with coefficients
  rig.cameras = {cam};
  EXPECT_NE(errorOf([&] { rig.validate(); }).find("camera 'left'"), std::string::npos);
  rig.cameras[0].model = CameraModel::kRadialTangential;
  EXPECT_NO_THROW(rig.validate());
  rig.cameras[0].distortion[1] = std::nan("");
  EXPECT_NE(errorOf([&] { rig.validate(); }).find("finite"), std::string::npos);
}

// ------------------------------------------------------------------------------------------
// Rig files.

TEST(RigFile, ReadsBothDirectionsAndLensModels) {
  TempDir tmp;
  writeText(tmp.path() / "rig.yaml", kRig);
  const RigFile rig = readRigFile(tmp.path() / "rig.yaml");
  EXPECT_EQ(rig.name, "test-rig");
  EXPECT_FALSE(rig.base_is_lidar);
  // T_lidar_base was given: the base is 1.5 m below the LiDAR.
  EXPECT_NEAR(rig.rig.T_base_lidar.translation().z(), 1.5, 1e-12);
  ASSERT_EQ(rig.rig.cameras.size(), 1u);
  const Camera& cam = rig.rig.cameras[0];
  EXPECT_EQ(cam.model, CameraModel::kRadialTangential);
  EXPECT_DOUBLE_EQ(cam.distortion[3], -0.002);
  EXPECT_DOUBLE_EQ(cam.distortion[4], 0.0);
  // T_lidar_camera was given: the camera looks along the LiDAR's +x, so a point 10 m ahead is
  // on its optical axis, 10 m - 0.2 m away.
  const Eigen::Vector3d p = cam.T_camera_lidar * Eigen::Vector3d(10.0, 0.0, -0.1);
  EXPECT_NEAR(p.z(), 9.8, 1e-9);
  EXPECT_NEAR(p.x(), 0.0, 1e-9);
  EXPECT_NEAR(p.y(), 0.0, 1e-9);
  EXPECT_EQ(rig.lidar_folder, "scans");
  EXPECT_EQ(rig.camera_folders[0], "front");  // its name by default
}

TEST(RigFile, MatrixAndKFormsEqualTheOthers) {
  TempDir tmp;
  writeText(tmp.path() / "rig.yaml", R"(rig_format_version: 1
cameras:
  - name: c
    width: 64
    height: 48
    K: [40, 0, 32, 0, 40, 24, 0, 0, 1]
    T_camera_lidar: [0, -1, 0, 0.1,  0, 0, -1, 0.2,  1, 0, 0, 0.3,  0, 0, 0, 1]
)");
  const RigFile rig = readRigFile(tmp.path() / "rig.yaml");
  EXPECT_TRUE(rig.base_is_lidar);
  const Camera& cam = rig.rig.cameras[0];
  EXPECT_DOUBLE_EQ(cam.fx, 40.0);
  EXPECT_DOUBLE_EQ(cam.cy, 24.0);
  EXPECT_NEAR(
      (cam.T_camera_lidar * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(0.1, 0.2, 1.3)).norm(), 0.0,
      1e-12);
}

TEST(RigFile, ErrorsNameTheFileAndField) {
  TempDir tmp;
  const fs::path path = tmp.path() / "rig.yaml";
  const std::string head =
      "rig_format_version: 1\ncameras:\n  - name: c\n    width: 64\n"
      "    height: 48\n    fx: 40\n    fy: 40\n    cx: 32\n    cy: 24\n";
  auto error = [&](const std::string& text) {
    writeText(path, text);
    return errorOf([&] { readRigFile(path); });
  };
  const std::string both = error(head +
                                 "    T_camera_lidar: {translation: [0,0,0], quaternion_xyzw: "
                                 "[0,0,0,1]}\n    T_lidar_camera: {translation: [0,0,0], "
                                 "quaternion_xyzw: [0,0,0,1]}\n");
  EXPECT_NE(both.find(path.string()), std::string::npos) << both;
  EXPECT_NE(both.find("not both"), std::string::npos) << both;
  EXPECT_NE(error(head).find("cameras[0]: missing the extrinsic"), std::string::npos);
  EXPECT_NE(error(head + "    T_camera_lidar: [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2]\n")
                .find("last row"),
            std::string::npos);
  EXPECT_NE(error(head + "    model: fisheye\n    T_camera_lidar: {translation: [0,0,0], "
                         "quaternion_xyzw: [0,0,0,1]}\n")
                .find("cameras[0].model"),
            std::string::npos);
  EXPECT_NE(error(head + "    quaternion: 1\n").find("unknown key 'quaternion'"),
            std::string::npos);
  EXPECT_NE(error("rig_format_version: 2\n").find("version"), std::string::npos);
  // A reflection is not a rotation: a matrix read backwards or mistyped is caught.
  EXPECT_NE(error(head + "    T_camera_lidar: [-1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n")
                .find("rotation"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { readRigFile(tmp.path()); }).find("is a directory"), std::string::npos);
}

// ------------------------------------------------------------------------------------------
// Point records of any layout.

TEST(PointFields, DecodesPaddedFloat64LayoutsWithTimes) {
  // x y z as float64, intensity uint16, 6 bytes of padding, time uint32 ns: 38-byte records.
  const std::vector<PointFieldSpec> fields = {{"x", 0, FieldType::kFloat64, 1},
                                              {"y", 8, FieldType::kFloat64, 1},
                                              {"z", 16, FieldType::kFloat64, 1},
                                              {"intensity", 24, FieldType::kUint16, 1},
                                              {"t", 32, FieldType::kUint32, 1}};
  const size_t step = 38;
  std::vector<uint8_t> data(3 * step, 0);
  auto put = [&](size_t i, double x, double y, double z, uint16_t v, uint32_t t) {
    uint8_t* r = data.data() + i * step;
    std::memcpy(r, &x, 8);
    std::memcpy(r + 8, &y, 8);
    std::memcpy(r + 16, &z, 8);
    std::memcpy(r + 24, &v, 2);
    std::memcpy(r + 32, &t, 4);
  };
  put(0, 1.5, -2.0, 0.25, 7, 0);
  put(1, std::nan(""), 0, 0, 0, 50000000);  // an organized cloud's empty cell
  put(2, 3.0, 4.0, 5.0, 300, 99000000);
  const DecodedPoints d = decodePointFields(fields, step, data.data(), data.size(), 3, "cloud");
  ASSERT_EQ(d.points.size(), 2u);
  EXPECT_EQ(d.dropped_invalid, 1u);
  EXPECT_FLOAT_EQ(d.points[0].x, 1.5f);
  EXPECT_FLOAT_EQ(d.points[1].z, 5.0f);
  EXPECT_FLOAT_EQ(d.points[1].intensity, 300.0f);
  ASSERT_EQ(d.times.size(), 2u);
  EXPECT_NEAR(d.times[1], 0.099, 1e-12);  // integers are nanoseconds
  EXPECT_EQ(d.time_field, "t");

  EXPECT_NE(errorOf([&] {
              decodePointFields(fields, step, data.data(), 100, 3, "cloud");
            }).find("cloud: 3 points"),
            std::string::npos);
  const std::vector<PointFieldSpec> no_z = {{"x", 0, FieldType::kFloat32, 1},
                                            {"y", 4, FieldType::kFloat32, 1}};
  EXPECT_NE(
      errorOf([&] { decodePointFields(no_z, 8, data.data(), 8, 1, "cloud"); }).find("no 'z' field"),
      std::string::npos);
  const std::vector<PointFieldSpec> outside = {{"x", 0, FieldType::kFloat32, 1},
                                               {"y", 4, FieldType::kFloat32, 1},
                                               {"z", 8, FieldType::kFloat64, 1}};
  const std::string outside_error =
      errorOf([&] { decodePointFields(outside, 12, data.data(), 12, 1, "cloud"); });
  EXPECT_NE(outside_error.find("field 'z' at offset 8 does not fit"), std::string::npos)
      << outside_error;
}

// A ring beyond any LiDAR's rows (or one no int holds) and a non-finite time are corrupt records,
// refused naming the point; a NaN coordinate is an organized cloud's "no return", dropped.
TEST(PointFields, CorruptRingsAndTimesAreRefusedNaNPointsDropped) {
  const std::vector<PointFieldSpec> fields = {{"x", 0, FieldType::kFloat32, 1},
                                              {"y", 4, FieldType::kFloat32, 1},
                                              {"z", 8, FieldType::kFloat32, 1},
                                              {"ring", 12, FieldType::kFloat32, 1},
                                              {"t", 16, FieldType::kFloat32, 1}};
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::vector<float> records = {1, 2, 3, 5, 0.01f, nan, 2, 3, 1, 0.02f};
  const auto decode = [&] {
    return decodePointFields(fields, 20, reinterpret_cast<const uint8_t*>(records.data()),
                             records.size() * 4, 2, "cloud");
  };
  const DecodedPoints d = decode();
  EXPECT_EQ(d.points.size(), 1u);
  EXPECT_EQ(d.dropped_invalid, 1u);
  EXPECT_EQ(d.rings, 6);
  records[3] = 1e30f;
  EXPECT_NE(errorOf(decode).find("cloud: point 0 has the ring"), std::string::npos)
      << errorOf(decode);
  records[3] = 5;
  records[4] = std::numeric_limits<float>::infinity();
  EXPECT_NE(errorOf(decode).find("cloud: point 0 has the time inf (field 't')"), std::string::npos)
      << errorOf(decode);
}

TEST(PointFields, AbsoluteTimesBecomeRelative) {
  const std::vector<float> rel = relativePointTimes({1650000000.05, 1650000000.08}, 1650000000.0);
  EXPECT_NEAR(rel[0], 0.05, 1e-6);
  EXPECT_NEAR(rel[1], 0.08, 1e-6);
  const std::vector<float> kept = relativePointTimes({0.01, 0.02}, 1650000000.0);
  EXPECT_NEAR(kept[1], 0.02, 1e-7);
}

#if SEMSEGMAP_WITH_PCL
TEST(PointCloudFile, ReadsPcdInEveryEncodingAndRefusesTruncation) {
  TempDir tmp;
  pcl::PointCloud<pcl::PointXYZI> cloud;
  for (int i = 0; i < 100; ++i)
    cloud.push_back(pcl::PointXYZI(static_cast<float>(i), 0.5f * i, -1.0f, 0.25f * i));
  pcl::io::savePCDFileASCII((tmp.path() / "a.pcd").string(), cloud);
  pcl::io::savePCDFileBinary((tmp.path() / "b.pcd").string(), cloud);
  pcl::io::savePCDFileBinaryCompressed((tmp.path() / "c.pcd").string(), cloud);
  for (const char* name : {"a.pcd", "b.pcd", "c.pcd"}) {
    const DecodedPoints d = readPointCloudFile(tmp.path() / name);
    ASSERT_EQ(d.points.size(), 100u) << name;
    EXPECT_FLOAT_EQ(d.points[42].y, 21.0f) << name;
    EXPECT_FLOAT_EQ(d.points[42].intensity, 10.5f) << name;
  }
  // Cut the binary file in the middle of its points.
  const std::string bytes = readFileBytes(tmp.path() / "b.pcd");
  writeBytesAtomically(tmp.path() / "t.pcd", bytes.substr(0, bytes.size() - 200));
  const std::string truncated = errorOf([&] { readPointCloudFile(tmp.path() / "t.pcd"); });
  EXPECT_NE(truncated.find("t.pcd: truncated"), std::string::npos) << truncated;
  // An ASCII file whose header promises more points than it holds.
  std::string ascii = readFileBytes(tmp.path() / "a.pcd");
  ascii.replace(ascii.find("POINTS 100"), 10, "POINTS 120");
  ascii.replace(ascii.find("WIDTH 100"), 9, "WIDTH 120");
  writeBytesAtomically(tmp.path() / "w.pcd", ascii);
  const std::string wrong = errorOf([&] { readPointCloudFile(tmp.path() / "w.pcd"); });
  EXPECT_NE(wrong.find("w.pcd"), std::string::npos) << wrong;
  EXPECT_NE(errorOf([&] { readPointCloudFile(tmp.path() / "none.pcd"); }).find("no such file"),
            std::string::npos);
}

// Headers that promise more points than their file holds are refused before PCL allocates them
// (an ASCII header of 4 * 10^9 points was 48 GB allocated).
TEST(PointCloudFile, OversizedHeadersAreRefusedBeforeReading) {
  TempDir tmp;
  const std::string head =
      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nVIEWPOINT 0 0 0 1 0 0 0\n";
  for (const char* data : {"ascii", "binary", "binary_compressed"}) {
    writeText(tmp.path() / "huge.pcd", head +
                                           "WIDTH 4000000000\nHEIGHT 1\n"
                                           "POINTS 4000000000\nDATA " +
                                           data + "\n1 2 3\n");
    const std::string error = errorOf([&] { readPointCloudFile(tmp.path() / "huge.pcd"); });
    EXPECT_NE(error.find("huge.pcd: truncated or corrupt: the header promises 4000000000 points"),
              std::string::npos)
        << data << ": " << error;
  }
  writeText(tmp.path() / "few.pcd",
            head + "WIDTH 1000\nHEIGHT 1\nPOINTS 1000\nDATA ascii\n1 2 3\n");
  EXPECT_NE(errorOf([&] { readPointCloudFile(tmp.path() / "few.pcd"); }).find("few.pcd: "),
            std::string::npos);
  const auto refusalOf = [&](const std::string& name, const std::string& text) {
    writeText(tmp.path() / name, text);
    return errorOf([&] { readPointCloudFile(tmp.path() / name); });
  };
  // A field of 77777777771 bytes: PCL allocated 12 GB for 3 points (found by the fuzzer).
  EXPECT_NE(refusalOf("wide.pcd",
                      "VERSION 0.7\nFIELDS x y z\nSIZE 77777777771 4 4\n"
                      "TYPE F F F\nCOUNT 1 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\n"
                      "DATA ascii\n1 2 3\n4 5 6\n7 8 9\n")
                .find("wide.pcd: not a readable PCD header: a SIZE that is not 1, 2, 4 or 8"),
            std::string::npos);
  // PCL reads "COUNT\b" as COUNT, so a check that did not went by its counts (a segfault).
  EXPECT_NE(refusalOf("key.pcd",
                      "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n"
                      "COUNT\b 1 1 99999999999999999999\nWIDTH 1\nHEIGHT 1\n"
                      "POINTS 1\nDATA binary\n123456789012")
                .find("key.pcd: not a readable PCD header: the key 'COUNT' runs on"),
            std::string::npos);
  writeText(tmp.path() / "huge.ply",
            "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n"
            "property float y\nproperty float z\nend_header\n");
  const std::string ply = errorOf([&] { readPointCloudFile(tmp.path() / "huge.ply"); });
  EXPECT_NE(ply.find("huge.ply: truncated or corrupt: the header promises 4000000000 vertices"),
            std::string::npos)
      << ply;
}

// PCL places a field by SIZE and COUNT but writes it at the width of its TYPE (4-byte floats
// when TYPE is missing, the first TYPE when SIZE comes again): both wrote past PCL's buffer.
TEST(PointCloudFile, FieldsWiderThanTheirSizeAreRefused) {
  TempDir tmp;
  const std::string counts = "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n";
  const std::string tail = counts + "1 2 3\n4 5 6\n";
  for (const auto& [name, head] :
       {std::pair{"untyped.pcd", "FIELDS x y z\nSIZE 1 1 1\n"},
        std::pair{"twice.pcd",
                  "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nSIZE 1 1 1\nCOUNT 1 1 1\n"}}) {
    writeText(tmp.path() / name, head + tail);
    const std::string error = errorOf([&] { readPointCloudFile(tmp.path() / name); });
    EXPECT_NE(error.find(std::string(name) + ": not a readable PCD header: the field 'x' has a "
                                             "TYPE that does not fit its SIZE and COUNT"),
              std::string::npos)
        << error;
  }
  // PCL sizes its buffer at POINTS with the point size it knows by then.
  for (const char* data : {"ascii", "binary"}) {
    writeText(tmp.path() / "early.pcd",
              "FIELDS x y z\nPOINTS 2\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
              "DATA " +
                  std::string(data) + "\n" + std::string(48, '1'));
    EXPECT_NE(errorOf([&] {
                readPointCloudFile(tmp.path() / "early.pcd");
              }).find("early.pcd: not a readable PCD header: POINTS comes before SIZE or COUNT"),
              std::string::npos)
        << data;
  }
  // Sizes and types that agree read, whatever the field widths.
  writeText(tmp.path() / "mixed.pcd",
            "FIELDS x y z i\nSIZE 8 4 4 1\nTYPE F F F U\nCOUNT 1 1 1 1\n" + counts +
                "1 2 3 7\n4 5 6 8\n");
  const DecodedPoints d = readPointCloudFile(tmp.path() / "mixed.pcd");
  ASSERT_EQ(d.points.size(), 2u);
  EXPECT_FLOAT_EQ(d.points[1].x, 4.0f);
  EXPECT_FLOAT_EQ(d.points[1].z, 6.0f);
  EXPECT_FLOAT_EQ(d.points[1].intensity, 8.0f);
}

TEST(PointCloudFile, ReadsPlyInBothEncodings) {
  TempDir tmp;
  pcl::PointCloud<pcl::PointXYZI> cloud;
  for (int i = 0; i < 30; ++i)
    cloud.push_back(pcl::PointXYZI(0.5f * i, -1.0f * i, 2.0f, static_cast<float>(i)));
  pcl::io::savePLYFileASCII((tmp.path() / "a.ply").string(), cloud);
  pcl::io::savePLYFileBinary((tmp.path() / "b.ply").string(), cloud);
  for (const char* name : {"a.ply", "b.ply"}) {
    const DecodedPoints d = readPointCloudFile(tmp.path() / name);
    ASSERT_EQ(d.points.size(), 30u) << name;
    EXPECT_FLOAT_EQ(d.points[7].x, 3.5f) << name;
    EXPECT_FLOAT_EQ(d.points[7].y, -7.0f) << name;
    EXPECT_FLOAT_EQ(d.points[7].intensity, 7.0f) << name;
  }
  writeText(tmp.path() / "bad.ply", "ply\nformat ascii 1.0\nelement vertex 5\nend_header\n1 2\n");
  EXPECT_NE(errorOf([&] { readPointCloudFile(tmp.path() / "bad.ply"); }).find("bad.ply"),
            std::string::npos);
}
#endif

// ------------------------------------------------------------------------------------------
// Folders of scans and pictures, and pose files.

namespace {

// A folder of `n` scans (KITTI .bin, named by nanosecond times 0.1 s apart) and pictures of
// camera "front" (named by times 0.01 s later), with the rig above.
fs::path writeFolder(const fs::path& root, size_t n, int picture_width = 64) {
  writeText(root / "rig.yaml", kRig);
  fs::create_directories(root / "scans");
  fs::create_directories(root / "front");
  for (size_t i = 0; i < n; ++i) {
    const long long ns = 1650000000000000000LL + static_cast<long long>(i) * 100000000LL;
    std::vector<LidarPoint> points;
    for (int k = 0; k < 50; ++k)
      points.push_back({5.0f + 0.1f * k, 0.05f * k - 1.0f, 0.1f * static_cast<float>(i), 1.0f});
    writeLidarBin(root / "scans" / (std::to_string(ns) + ".bin"), points);
    Image picture(picture_width, 48, 3);
    std::fill(picture.data.begin(), picture.data.end(), static_cast<uint8_t>(10 * i));
    writePng(root / "front" / (std::to_string(ns + 10000000LL) + ".png"), picture);
  }
  return root;
}

}  // namespace

TEST(FolderReader, PairsScansAndPicturesByTheTimesInTheirNames) {
  TempDir tmp;
  const fs::path dir = writeFolder(tmp.path() / "rec", 4);
  FolderReader reader(dir, {});
  ASSERT_EQ(reader.size(), 4u);
  EXPECT_FALSE(reader.info().has_odometry);
  EXPECT_EQ(reader.info().name, "test-rig");
  const Frame f = reader.frame(2);
  EXPECT_NEAR(f.timestamp_s, 1650000000.2, 1e-6);
  ASSERT_EQ(f.points.size(), 50u);
  EXPECT_FLOAT_EQ(f.points[0].z, 0.2f);
  ASSERT_EQ(f.cameras.size(), 1u);
  EXPECT_EQ(f.cameras[0].rgb.data[0], 20);  // the picture 0.01 s after scan 2, not another
  EXPECT_NEAR(reader.frameTime(3), 1650000000.3, 1e-6);
}

TEST(FolderReader, NeverPairsAFarPicture) {
  TempDir tmp;
  const fs::path dir = writeFolder(tmp.path() / "rec", 3);
  // Move the pictures 1 s later (1.01..1.21 s, the scans are at 0..0.2 s): with half the
  // period (0.05 s) no scan has a picture near it.
  for (const auto& e : fs::directory_iterator(dir / "front")) {
    const long long ns = std::stoll(e.path().stem().string()) + 1000000000LL;
    fs::rename(e.path(), dir / "front" / (std::to_string(ns) + ".png"));
  }
  const std::string error = errorOf([&] { FolderReader(dir, {}); });
  EXPECT_NE(error.find("no picture of camera 'front' lies within"), std::string::npos) << error;
  FolderOptions loose;
  loose.tolerance_s = 0.9;  // scan 2 (0.2 s) reaches the first picture (1.01 s), scan 0 does not
  FolderReader reader(dir, loose);
  EXPECT_TRUE(reader.frame(0).cameras[0].rgb.empty());
  EXPECT_EQ(reader.frame(2).cameras[0].rgb.data[0], 0);
}

TEST(FolderReader, RefusesPicturesOfAnotherSize) {
  TempDir tmp;
  const fs::path dir = writeFolder(tmp.path() / "rec", 2, 80);
  const std::string error = errorOf([&] { FolderReader(dir, {}); });
  EXPECT_NE(error.find(".png: the picture is 80x48 but camera 'front' of the rig is 64x48"),
            std::string::npos)
      << error;
}

TEST(FolderReader, NumberedScansWithoutARigAreLidarOnly) {
  TempDir tmp;
  for (int i = 0; i < 3; ++i)
    writeLidarBin(tmp.path() / frameFileName(static_cast<size_t>(i), "bin"),
                  {{1.0f, 2.0f, 3.0f, 0.0f}});
  FolderReader reader(tmp.path(), {});
  EXPECT_TRUE(reader.info().rig.cameras.empty());
  EXPECT_NEAR(reader.frameTime(2), 0.2, 1e-12);  // 10 Hz, in name order
  EXPECT_EQ(timeFromFileName("000042"), std::nullopt);
  EXPECT_NEAR(*timeFromFileName("1650000000.5"), 1650000000.5, 1e-6);
  EXPECT_NEAR(*timeFromFileName("1650000000500"), 1650000000.5, 1e-6);  // ms
  EXPECT_EQ(timeFromFileName("scan_7"), std::nullopt);
}

TEST(PoseFiles, TumIsInterpolatedAndScansOutsideAreLeftOut) {
  TempDir tmp;
  const fs::path dir = writeFolder(tmp.path() / "rec", 4);
  // Odometry from 0.05 s to 0.25 s: scans 0 (0.0 s) and 3 (0.3 s) lie outside.
  writeText(tmp.path() / "odom.tum",
            "# t x y z qx qy qz qw\n1650000000.05 0 0 0 0 0 0 1\n"
            "1650000000.25 2 0 0 0 0 0.7071068 0.7071068\n");
  DatasetOptions options;
  options.odometry = tmp.path() / "odom.tum";
  auto source = openDataset("folder:" + dir.string(), options);
  EXPECT_TRUE(source->info().has_odometry);
  ASSERT_EQ(source->size(), 2u);
  const Frame f = source->frame(0);  // scan 1, at 0.1 s: a quarter of the way
  EXPECT_NEAR(f.timestamp_s, 1650000000.1, 1e-6);
  EXPECT_NEAR(f.T_odom_base.translation().x(), 0.5, 1e-6);
  EXPECT_NEAR(yawOf(f.T_odom_base), 0.25 * M_PI / 2, 1e-6);
}

TEST(PoseFiles, KittiPairsByIndexAndCountsMustSuffice) {
  TempDir tmp;
  const fs::path dir = writeFolder(tmp.path() / "rec", 3);
  writeText(tmp.path() / "gt.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  DatasetOptions options;
  options.ground_truth = tmp.path() / "gt.txt";
  const std::string few = errorOf([&] { openDataset("folder:" + dir.string(), options); });
  EXPECT_NE(few.find("gt.txt: 2 KITTI poses for 3 scans"), std::string::npos) << few;
  writeText(tmp.path() / "gt.txt",
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n"
            "1 0 0 2 0 1 0 0 0 0 1 0\n");
  auto source = openDataset("folder:" + dir.string(), options);
  EXPECT_TRUE(source->info().has_ground_truth_poses);
  EXPECT_FALSE(source->info().has_odometry);
  EXPECT_NEAR(source->frame(2).T_world_base->translation().x(), 2.0, 1e-12);
  writeText(tmp.path() / "bad.txt", "1 2 3\n");
  options.ground_truth = tmp.path() / "bad.txt";
  EXPECT_NE(errorOf([&] {
              openDataset("folder:" + dir.string(), options);
            }).find("bad.txt: expected 8 numbers per line"),
            std::string::npos);
}

TEST(PoseFiles, ARunWithoutOdometryIsRefusedUpFront) {
  TempDir tmp;
  const fs::path dir = writeFolder(tmp.path() / "rec", 2);
  auto source = openDataset("folder:" + dir.string());
  const std::string error = errorOf(
      [&] { Pipeline pipe(PipelineConfig{}, source->info(), PoseSource::kOdometry, nullptr); });
  EXPECT_NE(error.find("has no odometry: give --odometry FILE"), std::string::npos) << error;
}

namespace {

// A LiDAR-only folder whose scans are named by the frame numbers given (`digits` wide: 6 as in
// KITTI, 0 for plain numbers); each scan's single point lies at x = its frame number.
fs::path writeNumberedScans(const fs::path& dir, const std::vector<size_t>& numbers,
                            int digits = 6) {
  fs::create_directories(dir);
  for (const size_t n : numbers) {
    char stem[32];
    std::snprintf(stem, sizeof(stem), "%0*zu", digits, n);
    writeLidarBin(dir / (std::string(stem) + ".bin"), {{static_cast<float>(n), 0.0f, 0.0f, 0.0f}});
  }
  return dir;
}

// KITTI poses, one line per frame: the pose of frame N lies at x = N.
void writeKittiPosesAlongX(const fs::path& path, size_t lines) {
  std::string text;
  for (size_t n = 0; n < lines; ++n) text += "1 0 0 " + std::to_string(n) + " 0 1 0 0 0 0 1 0\n";
  writeText(path, text);
}

// The notes and warnings that `f` gives.
std::vector<std::string> messagesOf(const std::function<void()>& f) {
  std::vector<std::string> lines;
  setMessageSink([&](const std::string& line) { lines.push_back(line); });
  try {
    f();
  } catch (...) {
    setMessageSink({});
    throw;
  }
  setMessageSink({});
  return lines;
}

bool saysOnce(const std::vector<std::string>& lines, const std::string& text) {
  return std::count_if(lines.begin(), lines.end(), [&](const std::string& l) {
           return l.find(text) != std::string::npos;
         }) == 1;
}

}  // namespace

// KITTI's full poses.txt beside sparse scans: scan 000120 takes line 120, not line 3.
TEST(PoseFiles, KittiLineNBelongsToTheScanNamedN) {
  for (const int digits : {6, 0}) {  // 000038.bin and 38.bin alike (38 sorts after 120 by name)
    TempDir tmp;
    const fs::path dir = writeNumberedScans(tmp.path() / "scans", {0, 38, 79, 120}, digits);
    writeKittiPosesAlongX(tmp.path() / "poses.txt", 121);
    DatasetOptions options;
    options.ground_truth = tmp.path() / "poses.txt";
    options.odometry = tmp.path() / "poses.txt";
    std::unique_ptr<FrameSource> source;
    const auto lines = messagesOf([&] { source = openDataset("folder:" + dir.string(), options); });
    ASSERT_EQ(source->size(), 4u);
    const double expected[] = {0, 38, 79, 120};
    for (size_t i = 0; i < 4; ++i) {
      const Frame f = source->frame(i);
      EXPECT_EQ(source->frameNumber(i), static_cast<size_t>(expected[i]));
      // The frame carries its name through the pose files' wrapper: outputs name it so.
      EXPECT_EQ(f.number, source->frameNumber(i));
      EXPECT_FLOAT_EQ(f.points.at(0).x, static_cast<float>(expected[i])) << "scan order";
      EXPECT_NEAR(f.T_world_base->translation().x(), expected[i], 1e-12) << "digits " << digits;
      EXPECT_NEAR(f.T_odom_base.translation().x(), expected[i], 1e-12);
    }
    EXPECT_NEAR(source->frameTime(3), 12.0, 1e-9);  // frame 120 at 10 Hz
    EXPECT_EQ(std::count_if(lines.begin(), lines.end(),
                            [](const std::string& l) {
                              return l.find("poses.txt: KITTI poses matched by frame number") !=
                                     std::string::npos;
                            }),
              2)  // one line per pose file given
        << ::testing::PrintToString(lines);
    // One file for both: odometry is the ground truth, said once and marked.
    EXPECT_TRUE(source->info().odometry_is_ground_truth);
    EXPECT_TRUE(saysOnce(lines, "ground-truth poses serve as its odometry too"))
        << ::testing::PrintToString(lines);
  }
}

TEST(PoseFiles, KittiPosesShortOfTheLargestFrameAreRefused) {
  TempDir tmp;
  const fs::path dir = writeNumberedScans(tmp.path() / "scans", {0, 38, 79, 120});
  writeKittiPosesAlongX(tmp.path() / "poses.txt", 120);  // lines 0..119: no line for 120
  DatasetOptions options;
  options.ground_truth = tmp.path() / "poses.txt";
  const std::string error = errorOf([&] { openDataset("folder:" + dir.string(), options); });
  EXPECT_NE(error.find((tmp.path() / "poses.txt").string() +
                       ": 120 KITTI poses, but the scans go up to frame 120"),
            std::string::npos)
      << error;
}

// Scans named by frame number have no times of their own: TUM poses need a times file.
TEST(PoseFiles, TumPosesNeedScanTimesFromTheData) {
  TempDir tmp;
  const fs::path dir = writeNumberedScans(tmp.path() / "scans", {0, 5, 10});
  writeText(tmp.path() / "odom.tum", "100.0 0 0 0 0 0 0 1\n101.0 2 0 0 0 0 0 1\n");
  DatasetOptions options;
  options.odometry = tmp.path() / "odom.tum";
  const std::string error = errorOf([&] { openDataset("folder:" + dir.string(), options); });
  EXPECT_NE(error.find("odom.tum: TUM poses are matched to scans by time, but the scans of"),
            std::string::npos)
      << error;
  writeText(tmp.path() / "times.txt", "100.0\n100.5\n101.0\n");
  std::unique_ptr<FrameSource> source;
  const auto lines = messagesOf([&] {
    source = openDataset("folder:" + dir.string() + ",times=" + (tmp.path() / "times.txt").string(),
                         options);
  });
  ASSERT_EQ(source->size(), 3u);
  EXPECT_NEAR(source->frame(1).T_odom_base.translation().x(), 1.0, 1e-9);  // 100.5 s: half way
  EXPECT_NEAR(source->frame(2).T_odom_base.translation().x(), 2.0, 1e-9);
  EXPECT_FALSE(source->info().odometry_is_ground_truth);
  EXPECT_TRUE(saysOnce(lines, "odom.tum: TUM poses matched by time"))
      << ::testing::PrintToString(lines);
}

// Names that are no frame numbers: KITTI lines in order only with one line per scan.
TEST(PoseFiles, KittiPosesForScansWithoutNumbersMustCountTheScans) {
  TempDir tmp;
  const fs::path dir = tmp.path() / "scans";
  fs::create_directories(dir);
  for (const char* name : {"scan_a", "scan_b", "scan_c"})
    writeLidarBin(dir / (std::string(name) + ".bin"), {{1.0f, 0.0f, 0.0f, 0.0f}});
  writeKittiPosesAlongX(tmp.path() / "poses.txt", 4);
  DatasetOptions options;
  options.ground_truth = tmp.path() / "poses.txt";
  const std::string error = errorOf([&] { openDataset("folder:" + dir.string(), options); });
  EXPECT_NE(error.find("poses.txt: 4 KITTI poses for 3 scans whose names are no frame numbers"),
            std::string::npos)
      << error;
  writeKittiPosesAlongX(tmp.path() / "poses.txt", 3);
  std::unique_ptr<FrameSource> source;
  const auto lines = messagesOf([&] { source = openDataset("folder:" + dir.string(), options); });
  EXPECT_NEAR(source->frame(2).T_world_base->translation().x(), 2.0, 1e-12);
  EXPECT_TRUE(saysOnce(lines, "poses.txt: KITTI poses taken in scan order"))
      << ::testing::PrintToString(lines);
  // Nor do such names give times to match TUM poses to.
  writeText(tmp.path() / "gt.tum", "0.0 0 0 0 0 0 0 1\n1.0 4 0 0 0 0 0 1\n");
  options.ground_truth = tmp.path() / "gt.tum";
  EXPECT_NE(errorOf([&] {
              openDataset("folder:" + dir.string(), options);
            }).find("gt.tum: TUM poses are matched to scans by time"),
            std::string::npos);
}

// KITTI 00's sparse scans as a folder with the sequence's full poses.txt: every scan gets the
// pose of its own frame number, as semantickitti: gives it (scan 000120 about 89 m out, not at
// the 2.6 m of line 4).
TEST(RealSamples, SparseKittiScansTakeThePoseOfTheirFrameNumber) {
  const fs::path dir = kShared / "kitti_odometry_00_sparse";
  if (!fs::exists(dir / "poses.txt"))
    GTEST_SKIP() << "the real sparse KITTI 00 sample is absent (" << dir.string()
                 << "): ../shared/data is not beside this checkout";
  DatasetOptions options;
  options.ground_truth = dir / "poses.txt";  // camera-0 poses; calib.txt beside it says Tr
  auto folder = openDataset("folder:" + (dir / "velodyne").string(), options);
  SemanticKittiReader sequence(dir);
  ASSERT_EQ(folder->size(), sequence.size());
  std::optional<size_t> frame120;
  for (size_t i = 0; i < folder->size(); ++i) {
    ASSERT_EQ(folder->frameNumber(i), sequence.frameNumber(i));
    if (folder->frameNumber(i) == 120u) frame120 = i;
  }
  ASSERT_TRUE(frame120.has_value()) << "the sample's README lists frame 120";
  const Frame f = folder->frame(*frame120), g = sequence.frame(*frame120);
  ASSERT_TRUE(f.T_world_base && g.T_world_base);
  EXPECT_LT((f.T_world_base->translation() - g.T_world_base->translation()).norm(), 1e-6);
  EXPECT_GT(f.T_world_base->translation().norm(), 50.0);
}

// ------------------------------------------------------------------------------------------
// The real samples.

TEST(RealSamples, KittiPcdFolderWithGroundTruth) {
  const fs::path dir = kShared / "kitti00_first10_pcd";
  if (!fs::exists(dir))
    GTEST_SKIP() << "the real KITTI PCD sample is absent (" << dir.string()
                 << "): ../shared/data is not beside this checkout";
#if !SEMSEGMAP_WITH_PCL
  GTEST_SKIP() << "PCD files are read with PCL, which this build leaves out";
#endif
  DatasetOptions options;
  options.ground_truth = dir / "poses.txt";  // camera-0 poses; calib.txt beside it says Tr
  auto source = openDataset("folder:" + dir.string(), options);
  ASSERT_EQ(source->size(), 10u);
  const Frame f0 = source->frame(0), f9 = source->frame(9);
  EXPECT_GT(f0.points.size(), 100000u);
  // LiDAR poses: the car drives along the LiDAR's +x, about 0.86 m a frame, staying level.
  const Eigen::Vector3d moved = f9.T_world_base->translation() - f0.T_world_base->translation();
  EXPECT_NEAR(moved.x(), 9 * 0.86, 0.3);
  EXPECT_LT(std::abs(moved.z()), 0.4);
  EXPECT_LT(std::abs(moved.y()), 0.8);
}

TEST(RealSamples, PjlabPointsLandOnTheirPicture) {
  const fs::path dir = kShared / "pjlab_lidar_camera_sample";
  if (!fs::exists(dir))
    GTEST_SKIP() << "the real PJLab sample is absent (" << dir.string()
                 << "): ../shared/data is not beside this checkout";
#if !SEMSEGMAP_WITH_PCL
  GTEST_SKIP() << "PCD files are read with PCL, which this build leaves out";
#endif
  DatasetOptions options;
  options.rig = fs::path(SEMSEGMAP_SOURCE_DIR) / "examples" / "pjlab" / "rig.yaml";
  auto source = openDataset("folder:" + dir.string(), options);
  ASSERT_EQ(source->size(), 1u);
  const Frame f = source->frame(0);
  ASSERT_EQ(f.cameras.size(), 1u);
  EXPECT_EQ(f.cameras[0].rgb.width, 1920);
  const EnrichedCloud cloud = enrichFrame(f, source->info().rig, EnrichmentConfig{});
  size_t coloured = 0;
  for (const EnrichedPoint& p : cloud) coloured += p.has_color;
  // A front camera sees the part of the sweep ahead of it: thousands of points, not all.
  EXPECT_GT(coloured, 5000u);
  EXPECT_LT(coloured, cloud.size() / 2);
}

// ------------------------------------------------------------------------------------------
// Converting a folder gives the frames that reading it directly gives.

#if SEMSEGMAP_WITH_PCL
TEST(ConvertFolder, SameFramesAsReadingDirectly) {
  TempDir tmp;
  const fs::path dir = writeFolder(tmp.path() / "rec", 3);
  // Replace the .bin scans by ASCII PCD scans with a per-point time field (float seconds).
  for (const auto& e : fs::directory_iterator(dir / "scans")) {
    std::string pcd =
        "VERSION 0.7\nFIELDS x y z intensity t\nSIZE 4 4 4 4 4\nTYPE F F F F F\n"
        "COUNT 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\nDATA ascii\n";
    pcd += "1 2 3 4 0.01\n5 6 7 8 0.02\n9 10 11 12 0.05\n";
    writeText(e.path().parent_path() / (e.path().stem().string() + ".pcd"), pcd);
    fs::remove(e.path());
  }
  FolderReader direct(dir, {});
  {
    DatasetWriter writer(tmp.path() / "converted", direct.info());
    for (size_t i = 0; i < direct.size(); ++i) writer.write(direct.frame(i));
  }
  auto converted = openDataset((tmp.path() / "converted").string());
  EXPECT_FALSE(converted->info().has_odometry);
  const Camera& cam = converted->info().rig.cameras.at(0);
  EXPECT_EQ(cam.model, CameraModel::kRadialTangential);
  EXPECT_EQ(cam.distortion, direct.info().rig.cameras[0].distortion);
  ASSERT_EQ(converted->size(), direct.size());
  for (size_t i = 0; i < direct.size(); ++i) {
    const Frame a = direct.frame(i), b = converted->frame(i);
    EXPECT_EQ(a.timestamp_s, b.timestamp_s);
    ASSERT_EQ(a.points.size(), b.points.size());
    for (size_t k = 0; k < a.points.size(); ++k) EXPECT_EQ(a.points[k].z, b.points[k].z);
    EXPECT_EQ(a.point_times, b.point_times);
    EXPECT_EQ(b.point_times.size(), 3u);
    EXPECT_EQ(a.cameras[0].rgb.data, b.cameras[0].rgb.data);
  }
}
#endif

// ------------------------------------------------------------------------------------------
// What the fuzz harnesses found (tests/fuzz_regressions/), through the harnesses' own calls.

TEST(FuzzRegressions, PointCloudFiles) {
  TempDir tmp;
  for (const auto& [name, bytes] : semsegmap::test_support::fuzzRegressions("point_cloud_file")) {
    const fs::path path = tmp.path() / (bytes.rfind("ply", 0) == 0 ? "scan.ply" : "scan.pcd");
    std::ofstream(path, std::ios::binary) << bytes;
    semsegmap::test_support::expectCleanRefusal(name, path.string(),
                                                [&] { readPointCloudFile(path); });
  }
}

// The harness's input is meta.yaml, a line "--- frames.csv ---", frames.csv, and optionally
// "--- lidar ---" and "--- labels ---" with the files of frames 0-2 (fuzz/fuzz_dataset_dir.cpp).
TEST(FuzzRegressions, DatasetFolders) {
  const auto split = [](const std::string& text, const std::string& separator) {
    const size_t at = text.find(separator);
    if (at == std::string::npos) return std::pair<std::string, std::string>{text, ""};
    return std::pair<std::string, std::string>{text.substr(0, at),
                                               text.substr(at + separator.size())};
  };
  for (const auto& [name, bytes] : semsegmap::test_support::fuzzRegressions("dataset_dir")) {
    TempDir tmp;
    const auto [meta, rest] = split(bytes, "\n--- frames.csv ---\n");
    const auto [frames, files] = split(rest, "\n--- lidar ---\n");
    const auto [scan, labels] = split(files, "\n--- labels ---\n");
    std::ofstream(tmp.path() / "meta.yaml", std::ios::binary) << meta;
    std::ofstream(tmp.path() / "frames.csv", std::ios::binary) << frames;
    for (const auto& [folder, content] : {std::pair{"lidar", scan}, std::pair{"lidar_gt", labels}})
      if (!content.empty()) {
        std::filesystem::create_directories(tmp.path() / folder);
        for (size_t i = 0; i < 3; ++i)
          std::ofstream(tmp.path() / folder / frameFileName(i, "bin"), std::ios::binary) << content;
      }
    semsegmap::test_support::expectCleanRefusal(name, tmp.path().string(), [&] {
      DatasetReader reader(tmp.path(), 3);
      for (size_t i = 0; i < std::min<size_t>(reader.size(), 3); ++i) (void)reader.frame(i);
    });
  }
}
