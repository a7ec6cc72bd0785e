// Readers of real datasets: the real KITTI raw sample in ../shared/data, plus SemanticKITTI and
// NCLT fixtures written here byte by byte from the formats' specifications, and broken copies
// of each that must fail with a message naming the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "error_text.h"
#include "mini_kitti.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/kitti_calib.h"
#include "semsegmap/io/kitti_raw_reader.h"
#include "semsegmap/io/nclt_reader.h"
#include "semsegmap/io/semantic_kitti_reader.h"
#include "semsegmap/io/trajectory_file.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

namespace fs = std::filesystem;

const fs::path kDay =
    fs::path(SEMSEGMAP_SHARED_DATA) / "kitti_raw_2011_09_26_sample" / "2011_09_26";
const fs::path kDrive = kDay / "sample_sync";

using semsegmap::test_support::errorOf;
using semsegmap::test_support::TempDir;

// Every KittiRaw test reads the real sample, or copies parts of it to break them.
class KittiRaw : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kDrive))
      GTEST_SKIP() << "the real KITTI sample is absent (" << kDrive.string()
                   << "): ../shared/data is not beside this checkout";
  }
};

void writeText(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

void writeBytes(const fs::path& path, const std::vector<uint8_t>& bytes) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Replaces the line starting with `key` (or drops it when `line` is empty).
void replaceCalibLine(const fs::path& path, const std::string& key, const std::string& line) {
  std::string text = readText(path);
  const size_t start = text.find("\n" + key) + 1;
  ASSERT_NE(start, 0u) << key;
  const size_t end = text.find('\n', start);
  text.replace(start, end + 1 - start, line.empty() ? "" : line + "\n");
  fs::permissions(path, fs::perms::owner_write, fs::perm_options::add);
  writeText(path, text);
}

// KITTI's float32 x y z reflectance, written by hand rather than with the project's writer.
void writeKittiBin(const fs::path& path, const std::vector<LidarPoint>& points) {
  std::vector<uint8_t> bytes(points.size() * 16);
  for (size_t i = 0; i < points.size(); ++i) {
    const float v[4] = {points[i].x, points[i].y, points[i].z, points[i].intensity};
    std::memcpy(&bytes[i * 16], v, 16);
  }
  writeBytes(path, bytes);
}

// ---------------------------------------------------------------------------------------------
// KITTI raw

// A copy of the sample's first `frames` frames in ROOT/2011_09_26/sample_sync, calibration
// next to it, writable so that tests can break it.
fs::path copyKittiSample(const fs::path& root, int frames) {
  const fs::path day = root / "2011_09_26";
  const fs::path drive = day / "sample_sync";
  fs::create_directories(drive / "velodyne_points" / "data");
  fs::create_directories(drive / "image_02" / "data");
  const auto copy = [](const fs::path& from, const fs::path& to) {
    fs::copy_file(from, to);
    fs::permissions(to, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::add);
  };
  for (const char* name :
       {"calib_cam_to_cam.txt", "calib_velo_to_cam.txt", "calib_imu_to_velo.txt"})
    copy(kDay / name, day / name);
  for (int i = 0; i < frames; ++i) {
    char stem[16];
    std::snprintf(stem, sizeof(stem), "%010d", i);
    copy(kDrive / "velodyne_points" / "data" / (std::string(stem) + ".bin"),
         drive / "velodyne_points" / "data" / (std::string(stem) + ".bin"));
    copy(kDrive / "image_02" / "data" / (std::string(stem) + ".png"),
         drive / "image_02" / "data" / (std::string(stem) + ".png"));
  }
  return drive;
}

TEST_F(KittiRaw, RealSampleLoads) {
  KittiRawReader reader(kDrive);
  ASSERT_EQ(reader.size(), 10u);
  const DatasetInfo& info = reader.info();
  EXPECT_FALSE(info.has_ground_truth_poses);  // the sample has no oxts
  // Nor odometry: its poses would be identities, and a run on them is refused (never mapped
  // with every scan stacked at the origin).
  EXPECT_FALSE(info.has_odometry);
  EXPECT_FALSE(info.has_point_labels);
  EXPECT_TRUE(info.classes == ClassTable::Default());
  EXPECT_TRUE(info.rig.T_base_lidar.isApprox(Pose::Identity()));
  ASSERT_EQ(info.rig.cameras.size(), 1u);
  const Camera& cam = info.rig.cameras[0];
  EXPECT_EQ(cam.width, 1242);
  EXPECT_EQ(cam.height, 375);
  // P_rect_02 in calib_cam_to_cam.txt.
  EXPECT_DOUBLE_EQ(cam.fx, 7.215377e+02);
  EXPECT_DOUBLE_EQ(cam.fy, 7.215377e+02);
  EXPECT_DOUBLE_EQ(cam.cx, 6.095593e+02);
  EXPECT_DOUBLE_EQ(cam.cy, 1.728540e+02);

  for (size_t i = 0; i < reader.size(); ++i) {
    const Frame f = reader.frame(i);
    EXPECT_EQ(f.index, i);
    EXPECT_NEAR(f.timestamp_s, 0.1 * static_cast<double>(i), 1e-12);  // no timestamps.txt
    EXPECT_GT(f.points.size(), 100000u);
    EXPECT_TRUE(f.point_labels.empty());
    ASSERT_EQ(f.cameras.size(), 1u);
    EXPECT_EQ(f.cameras[0].rgb.width, 1242);
    EXPECT_EQ(f.cameras[0].rgb.height, 375);
    EXPECT_EQ(f.cameras[0].rgb.channels, 3);
    EXPECT_TRUE(f.cameras[0].label.empty());
    EXPECT_TRUE(f.T_odom_base.isApprox(Pose::Identity()));
    EXPECT_FALSE(f.T_world_base.has_value());
  }
  // The first scan is 1828448 bytes of 16-byte points.
  EXPECT_EQ(reader.frame(0).points.size(), 1828448u / 16u);
}

TEST_F(KittiRaw, ProjectionMatchesTheDevkitFormula) {
  // Copied from the sample's calib_cam_to_cam.txt (P_rect_02, R_rect_00) and
  // calib_velo_to_cam.txt (R, T).
  const double P[3][4] = {{7.215377e+02, 0.000000e+00, 6.095593e+02, 4.485728e+01},
                          {0.000000e+00, 7.215377e+02, 1.728540e+02, 2.163791e-01},
                          {0.000000e+00, 0.000000e+00, 1.000000e+00, 2.745884e-03}};
  const double Rrect[3][3] = {{9.999239e-01, 9.837760e-03, -7.445048e-03},
                              {-9.869795e-03, 9.999421e-01, -4.278459e-03},
                              {7.402527e-03, 4.351614e-03, 9.999631e-01}};
  const double R[3][3] = {{7.533745e-03, -9.999714e-01, -6.166020e-04},
                          {1.480249e-02, 7.280733e-04, -9.998902e-01},
                          {9.998621e-01, 7.523790e-03, 1.480755e-02}};
  const double T[3] = {-4.069766e-03, -7.631618e-02, -2.717806e-01};
  auto devkitPixel = [&](const double X[3], double uv[2]) {
    double cam0[3], rect[3], h[3];
    for (int r = 0; r < 3; ++r) cam0[r] = R[r][0] * X[0] + R[r][1] * X[1] + R[r][2] * X[2] + T[r];
    for (int r = 0; r < 3; ++r)
      rect[r] = Rrect[r][0] * cam0[0] + Rrect[r][1] * cam0[1] + Rrect[r][2] * cam0[2];
    for (int r = 0; r < 3; ++r)
      h[r] = P[r][0] * rect[0] + P[r][1] * rect[1] + P[r][2] * rect[2] + P[r][3];
    uv[0] = h[0] / h[2];
    uv[1] = h[1] / h[2];
  };

  KittiRawReader reader(kDrive);
  const Camera& cam = reader.info().rig.cameras.at(0);
  const Frame f = reader.frame(3);
  int checked = 0, in_image = 0;
  for (size_t i = 0; i < f.points.size(); i += 101) {
    const LidarPoint& p = f.points[i];
    if (p.x < 2.0) continue;  // in front of the car, so in front of the camera
    const double X[3] = {p.x, p.y, p.z};
    double expected[2];
    devkitPixel(X, expected);
    const auto uv = cam.project(cam.T_camera_lidar * Eigen::Vector3d(X[0], X[1], X[2]));
    ASSERT_TRUE(uv.has_value()) << "point " << i;
    EXPECT_NEAR(uv->x(), expected[0], 1e-6) << "point " << i;
    EXPECT_NEAR(uv->y(), expected[1], 1e-6) << "point " << i;
    ++checked;
    if (cam.inImage(*uv)) ++in_image;
  }
  EXPECT_GT(checked, 100);
  EXPECT_GT(in_image, 100);  // the calibration lines the scan up with the picture
}

TEST_F(KittiRaw, CalibrationTwoLevelsUpAndTimestampsAreRead) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path() / "root", 2);
  // Move the day's calibration one level further up: root/calib_*, root/2011_09_26/drive.
  for (const char* name : {"calib_cam_to_cam.txt", "calib_velo_to_cam.txt"})
    fs::rename(drive.parent_path() / name, tmp.path() / "root" / name);
  writeText(drive / "velodyne_points" / "timestamps.txt",
            "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.067938443\n");
  KittiRawReader reader(drive);
  ASSERT_EQ(reader.size(), 2u);
  const Frame f0 = reader.frame(0), f1 = reader.frame(1);
  EXPECT_NEAR(f1.timestamp_s - f0.timestamp_s, 0.103548998, 1e-6);
  // 2011-09-26 00:00 UTC is 1316995200 s after the epoch.
  EXPECT_NEAR(f0.timestamp_s, 1316995200.0 + 13 * 3600 + 2 * 60 + 25.964389445, 1e-5);
}

TEST_F(KittiRaw, OxtsBecomeLidarPosesRelativeToTheFirstFrame) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 2);
  // Frame 1 is 1e-5 degrees of latitude north of frame 0 and has turned 0.1 rad left.
  auto oxts = [](double lat, double yaw) {
    char line[512];
    std::snprintf(line, sizeof(line), "%.10f 8.4 115.0 0 0 %.10f", lat, yaw);
    std::string s = line;
    for (int i = 6; i < 30; ++i) s += " 0";
    return s + "\n";
  };
  const double lat0 = 49.0, dlat = 1e-5;
  writeText(drive / "oxts" / "data" / "0000000000.txt", oxts(lat0, 0.0));
  writeText(drive / "oxts" / "data" / "0000000001.txt", oxts(lat0 + dlat, 0.1));
  KittiRawReader reader(drive);
  EXPECT_TRUE(reader.info().has_ground_truth_poses);
  const Frame f0 = reader.frame(0), f1 = reader.frame(1);
  ASSERT_TRUE(f0.T_world_base && f1.T_world_base);
  EXPECT_TRUE(f0.T_world_base->isApprox(Pose::Identity(), 1e-9));
  EXPECT_TRUE(f1.T_odom_base.isApprox(*f1.T_world_base));

  // IMU motion: Mercator north = earth radius * dlat (scale cos(lat0) cancels 1 / cos(lat)),
  // about 1.113 m, and a 0.1 rad turn. The LiDAR moves by the same motion seen through the
  // IMU-to-Velodyne mounting of calib_imu_to_velo.txt.
  Pose T_imu0_imu1 = Pose::Identity();
  T_imu0_imu1.translation() = Eigen::Vector3d(0.0, 6378137.0 * dlat * M_PI / 180.0, 0.0);
  T_imu0_imu1.linear() = Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Pose T_velo_imu = Pose::Identity();
  T_velo_imu.linear() << 9.999976e-01, 7.553071e-04, -2.035826e-03, -7.854027e-04, 9.998898e-01,
      -1.482298e-02, 2.024406e-03, 1.482454e-02, 9.998881e-01;
  T_velo_imu.translation() << -8.086759e-01, 3.195559e-01, -7.997231e-01;
  const Pose expected = T_velo_imu * T_imu0_imu1 * T_velo_imu.inverse(Eigen::Affine);
  EXPECT_LT(translationError(*f1.T_world_base, expected), 1e-3);
  EXPECT_LT(rotationErrorDeg(*f1.T_world_base, expected), 1e-3);
  EXPECT_NEAR(Eigen::AngleAxisd(f1.T_world_base->linear()).angle(), 0.1, 1e-6);
}

TEST_F(KittiRaw, MissingCalibrationFileIsNamed) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 1);
  fs::remove(drive.parent_path() / "calib_velo_to_cam.txt");
  const std::string msg = errorOf([&] { KittiRawReader r(drive); });
  EXPECT_MENTIONS(msg, "calib_velo_to_cam.txt");
  EXPECT_MENTIONS(msg, "not found");
}

TEST_F(KittiRaw, MissingCalibrationKeyIsNamed) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 1);
  replaceCalibLine(drive.parent_path() / "calib_cam_to_cam.txt", "P_rect_02:", "");
  const std::string msg = errorOf([&] { KittiRawReader r(drive); });
  EXPECT_MENTIONS(msg, "calib_cam_to_cam.txt: P_rect_02: missing");
}

TEST_F(KittiRaw, WrongValueCountIsNamed) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 1);
  replaceCalibLine(drive.parent_path() / "calib_cam_to_cam.txt",
                   "R_rect_00:", "R_rect_00: 1 0 0 0 1 0 0 0");
  const std::string msg = errorOf([&] { KittiRawReader r(drive); });
  EXPECT_MENTIONS(msg, "calib_cam_to_cam.txt: R_rect_00: expected 9 values, found 8");
}

TEST_F(KittiRaw, NonRotationIsRejected) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 1);
  replaceCalibLine(drive.parent_path() / "calib_velo_to_cam.txt", "R:", "R: 2 0 0 0 1 0 0 0 1");
  const std::string msg = errorOf([&] { KittiRawReader r(drive); });
  EXPECT_MENTIONS(msg, "calib_velo_to_cam.txt: R: not a rotation matrix");
}

TEST_F(KittiRaw, NonNumericValueIsNamed) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 1);
  replaceCalibLine(drive.parent_path() / "calib_velo_to_cam.txt", "T:", "T: 0.1 abc 0.3");
  const std::string msg = errorOf([&] { KittiRawReader r(drive); });
  EXPECT_MENTIONS(msg, "calib_velo_to_cam.txt: T: 'abc' is not a finite number");
}

TEST_F(KittiRaw, ImageOfTheWrongSizeIsNamed) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 2);
  const fs::path png = drive / "image_02" / "data" / "0000000001.png";
  fs::remove(png);
  writePng(png, Image(100, 50, 3, 128));
  KittiRawReader reader(drive);  // sizes are checked when the frame is read
  EXPECT_NO_THROW(reader.frame(0));
  const std::string msg = errorOf([&] { reader.frame(1); });
  EXPECT_MENTIONS(msg, png.string());
  EXPECT_MENTIONS(msg, "100x50");
  EXPECT_MENTIONS(msg, "1242x375");
}

TEST_F(KittiRaw, MissingImageIsNamed) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 2);
  fs::remove(drive / "image_02" / "data" / "0000000001.png");
  const std::string msg = errorOf([&] { KittiRawReader r(drive); });
  EXPECT_MENTIONS(msg, "0000000001.png: missing");
}

TEST_F(KittiRaw, TruncatedScanIsNamed) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 1);
  const fs::path bin = drive / "velodyne_points" / "data" / "0000000000.bin";
  fs::resize_file(bin, fs::file_size(bin) - 3);
  KittiRawReader reader(drive);
  const std::string msg = errorOf([&] { reader.frame(0); });
  EXPECT_MENTIONS(msg, bin.string());
  EXPECT_MENTIONS(msg, "truncated");
}

TEST_F(KittiRaw, NonFiniteCoordinateIsNamedWithItsIndex) {
  TempDir tmp;
  const fs::path drive = copyKittiSample(tmp.path(), 1);
  const fs::path bin = drive / "velodyne_points" / "data" / "0000000000.bin";
  fs::remove(bin);
  writeKittiBin(bin, {{1, 2, 3, 0}, {4, 5, 6, 0}, {std::nanf(""), 0, 0, 0}});
  KittiRawReader reader(drive);
  const std::string msg = errorOf([&] { reader.frame(0); });
  EXPECT_MENTIONS(msg, bin.string());
  EXPECT_MENTIONS(msg, "point 2");
}

// ---------------------------------------------------------------------------------------------
// SemanticKITTI

std::string row3x4(const Pose& T) {
  std::string s;
  char buf[64];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      std::snprintf(buf, sizeof(buf), "%s%.17g", s.empty() ? "" : " ", T.matrix()(r, c));
      s += buf;
    }
  return s;
}

struct SemanticKittiFixture {
  fs::path dir;
  std::vector<std::vector<LidarPoint>> points;
  std::vector<std::vector<uint32_t>> raw_labels;
  std::vector<Pose> T_world_cam0;
  Pose Tr;  // velodyne -> camera 0
};

// Three scans with 5, 6 and 7 points, labels cycling through raw ids, non-trivial poses and Tr.
SemanticKittiFixture writeSemanticKitti(const fs::path& dir) {
  SemanticKittiFixture fx;
  fx.dir = dir;
  const uint32_t ids[] = {40, 252, 30, 49, 999, 0, 81, 44, 11, 31, 50, 72, 1, 80};
  for (int k = 0; k < 3; ++k) {
    std::vector<LidarPoint> pts;
    std::vector<uint32_t> labels;
    for (int i = 0; i < 5 + k; ++i) {
      pts.push_back({k + 0.5f, -1.25f * i, 0.125f * i, 0.1f * i});
      const uint32_t instance = static_cast<uint32_t>(i % 3 == 0 ? 0 : 100 * k + i);
      labels.push_back(ids[(3 * k + i) % 14] | (instance << 16));
    }
    char stem[16];
    std::snprintf(stem, sizeof(stem), "%06d", k);
    writeKittiBin(dir / "velodyne" / (std::string(stem) + ".bin"), pts);
    std::vector<uint8_t> bytes(labels.size() * 4);
    std::memcpy(bytes.data(), labels.data(), bytes.size());  // little-endian uint32
    writeBytes(dir / "labels" / (std::string(stem) + ".label"), bytes);
    fx.points.push_back(pts);
    fx.raw_labels.push_back(labels);
  }
  // Tr: camera z forward, x right, y down from the Velodyne's x forward, y left, z up, with a
  // small extra rotation and an offset, like KITTI's.
  fx.Tr = Pose::Identity();
  fx.Tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  fx.Tr.linear() =
      fx.Tr.linear() * Eigen::AngleAxisd(0.02, Eigen::Vector3d(0.3, 0.1, 1).normalized());
  fx.Tr.translation() = Eigen::Vector3d(-0.012, -0.054, -0.29);
  for (int k = 0; k < 3; ++k) {
    Pose T = Pose::Identity();
    if (k > 0) {
      T.linear() = Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d(0.1, 1.0, 0.05).normalized())
                       .toRotationMatrix();
      T.translation() = Eigen::Vector3d(0.3 * k, -0.05 * k, 1.7 * k);
    }
    fx.T_world_cam0.push_back(T);
  }
  std::string poses, calib;
  for (const Pose& T : fx.T_world_cam0) poses += row3x4(T) + "\n";
  writeText(dir / "poses.txt", poses);
  const std::string P = "7.188560e+02 0 6.071928e+02 0 0 7.188560e+02 1.852157e+02 0 0 0 1 0";
  calib = "P0: " + P + "\nP1: " + P + "\nP2: " + P + "\nP3: " + P + "\nTr: " + row3x4(fx.Tr) + "\n";
  writeText(dir / "calib.txt", calib);
  writeText(dir / "times.txt", "0.000000e+00\n1.037359e-01\n2.073381e-01\n");
  return fx;
}

// The mapping as the lead specified it, written out independently of the reader's table.
ClassId expectedClass(uint32_t raw) {
  switch (raw & 0xffffu) {
    case 40:
    case 44:
      return cls::kRoad;
    case 48:
      return cls::kSidewalk;
    case 49:
    case 72:
      return cls::kTerrain;
    case 50:
      return cls::kBuilding;
    case 80:
      return cls::kPole;
    case 81:
      return cls::kTrafficSign;
    case 10:
    case 11:
    case 252:
      return cls::kCar;
    case 30:
    case 31:
      return cls::kPerson;
    case 0:
    case 1:
      return cls::kUnknown;
    default:
      return cls::kOther;
  }
}

TEST(SemanticKitti, DecodesPointsLabelsTimesAndPoses) {
  TempDir tmp;
  const SemanticKittiFixture fx = writeSemanticKitti(tmp.path() / "08");
  SemanticKittiReader reader(fx.dir);
  ASSERT_EQ(reader.size(), 3u);
  EXPECT_TRUE(reader.info().has_point_labels);
  EXPECT_TRUE(reader.info().has_ground_truth_poses);
  EXPECT_TRUE(reader.info().rig.cameras.empty());
  const double times[] = {0.0, 1.037359e-01, 2.073381e-01};
  for (size_t k = 0; k < 3; ++k) {
    const Frame f = reader.frame(k);
    EXPECT_DOUBLE_EQ(f.timestamp_s, times[k]);
    EXPECT_TRUE(f.cameras.empty());
    ASSERT_EQ(f.points.size(), fx.points[k].size());
    ASSERT_EQ(f.point_labels.size(), fx.points[k].size());
    for (size_t i = 0; i < f.points.size(); ++i) {
      EXPECT_EQ(f.points[i].x, fx.points[k][i].x);
      EXPECT_EQ(f.points[i].y, fx.points[k][i].y);
      EXPECT_EQ(f.points[i].z, fx.points[k][i].z);
      EXPECT_EQ(f.points[i].intensity, fx.points[k][i].intensity);
      const uint32_t raw = fx.raw_labels[k][i];
      EXPECT_EQ(f.point_labels[i].class_id, expectedClass(raw)) << "raw label " << (raw & 0xffff);
      EXPECT_EQ(f.point_labels[i].instance_id, raw >> 16);
    }
    // Tr^-1 * T_world_cam0 * Tr means: a LiDAR point moved to the world and then seen in camera
    // coordinates equals the camera's world pose applied to the same point seen by the camera.
    ASSERT_TRUE(f.T_world_base.has_value());
    EXPECT_TRUE(f.T_odom_base.isApprox(*f.T_world_base));
    for (const Eigen::Vector3d& X : {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(-20, 5, -1)}) {
      const Eigen::Vector3d lhs = fx.Tr * (*f.T_world_base * X);
      const Eigen::Vector3d rhs = fx.T_world_cam0[k] * (fx.Tr * X);
      EXPECT_LT((lhs - rhs).norm(), 1e-9) << "frame " << k;
    }
  }
  EXPECT_TRUE(reader.frame(0).T_world_base->isApprox(Pose::Identity(), 1e-12));
}

TEST(SemanticKitti, EveryMappedClassIsInTheDefaultTable) {
  const ClassTable table = ClassTable::Default();
  for (const auto& row : semanticKittiClasses()) {
    EXPECT_TRUE(table.contains(row.class_id)) << row.name;
    EXPECT_EQ(semanticKittiToClass(row.label), row.class_id) << row.name;
  }
  EXPECT_EQ(semanticKittiToClass(254), cls::kPerson);  // moving-person
  EXPECT_EQ(semanticKittiToClass(258), cls::kCar);     // moving-truck
  EXPECT_EQ(semanticKittiToClass(60000), cls::kOther);
  EXPECT_TRUE(table.at(cls::kCar).dynamic);
  EXPECT_TRUE(table.at(semanticKittiToClass(49)).ground);  // other-ground stays ground
}

// The map is documented as a table (docs/class-maps.md); the page must say what the reader does.
TEST(SemanticKitti, ClassMapsPageListsTheReadersTable) {
  const std::string page = readText(fs::path(SEMSEGMAP_SOURCE_DIR) / "docs" / "class-maps.md");
  ASSERT_FALSE(page.empty());
  const ClassTable table = ClassTable::Default();
  for (const auto& row : semanticKittiClasses()) {
    const std::string line = "| " + std::to_string(row.label) + " | " + row.name + " | " +
                             table.at(row.class_id).name + " |";
    EXPECT_NE(page.find(line), std::string::npos) << line;
  }
}

TEST(SemanticKitti, LabelsAndPosesAreOptional) {
  TempDir tmp;
  const SemanticKittiFixture fx = writeSemanticKitti(tmp.path() / "08");
  fs::remove_all(fx.dir / "labels");
  fs::remove(fx.dir / "poses.txt");
  fs::remove(fx.dir / "times.txt");
  SemanticKittiReader reader(fx.dir);
  EXPECT_FALSE(reader.info().has_point_labels);
  EXPECT_FALSE(reader.info().has_ground_truth_poses);
  const Frame f = reader.frame(2);
  EXPECT_EQ(f.points.size(), 7u);
  EXPECT_TRUE(f.point_labels.empty());
  EXPECT_FALSE(f.T_world_base.has_value());
  EXPECT_NEAR(f.timestamp_s, 0.2, 1e-12);
}

// A sequence's poses are its odometry too: said in one line and marked, until --odometry FILE
// replaces it. That file's KITTI lines go by the scans' frame numbers, as poses.txt's do.
TEST(SemanticKitti, GroundTruthAsOdometryIsSaidAndAPoseFileGoesByFrameNumber) {
  TempDir tmp;
  const SemanticKittiFixture fx = writeSemanticKitti(tmp.path() / "08");
  for (const char* file : {"velodyne/000001.bin", "labels/000001.label"})
    fs::remove(fx.dir / file);  // sparse: frames 0 and 2
  fs::remove(fx.dir / "times.txt");
  std::vector<std::string> lines;
  setMessageSink([&](const std::string& line) { lines.push_back(line); });
  const auto own = openDataset("semantickitti:" + fx.dir.string());
  EXPECT_TRUE(own->info().odometry_is_ground_truth);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find("semantickitti:08: its ground-truth poses serve as its odometry too"),
            std::string::npos)
      << lines[0];
  lines.clear();
  writeText(tmp.path() / "odom" / "odom.txt",
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 10 0 1 0 0 0 0 1 0\n1 0 0 20 0 1 0 0 0 0 1 0\n");
  DatasetOptions options;
  options.odometry = tmp.path() / "odom" / "odom.txt";  // no calib.txt beside it: base poses
  const auto posed = openDataset("semantickitti:" + fx.dir.string(), options);
  setMessageSink({});
  EXPECT_FALSE(posed->info().odometry_is_ground_truth);
  ASSERT_EQ(posed->size(), 2u);
  EXPECT_EQ(posed->frameNumber(1), 2u);
  EXPECT_NEAR(posed->frame(1).T_odom_base.translation().x(), 20.0, 1e-12);  // line 2, not 1
  ASSERT_EQ(lines.size(), 1u) << ::testing::PrintToString(lines);
  EXPECT_NE(lines[0].find("KITTI poses matched by frame number"), std::string::npos) << lines[0];
  // Without times.txt its times are made up from the frame numbers: no TUM poses to them.
  writeText(tmp.path() / "odom" / "odom.tum", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n");
  options.odometry = tmp.path() / "odom" / "odom.tum";
  EXPECT_NE(errorOf([&] {
              openDataset("semantickitti:" + fx.dir.string(), options);
            }).find("odom.tum: TUM poses are matched to scans by time"),
            std::string::npos);
}

TEST(SemanticKitti, LabelCountMismatchNamesBothFiles) {
  TempDir tmp;
  const SemanticKittiFixture fx = writeSemanticKitti(tmp.path() / "08");
  const fs::path label = fx.dir / "labels" / "000001.label";
  fs::resize_file(label, 4 * 4);  // 4 labels for 6 points
  SemanticKittiReader reader(fx.dir);
  const std::string msg = errorOf([&] { reader.frame(1); });
  EXPECT_MENTIONS(msg, label.string());
  EXPECT_MENTIONS(msg, (fx.dir / "velodyne" / "000001.bin").string());
}

TEST(SemanticKitti, ErrorsNameTheFile) {
  TempDir tmp;
  const SemanticKittiFixture fx = writeSemanticKitti(tmp.path() / "08");
  fs::remove(fx.dir / "labels" / "000002.label");
  EXPECT_MENTIONS(errorOf([&] { SemanticKittiReader r(fx.dir); }), "000002.label: missing");

  writeSemanticKitti(fx.dir);
  writeText(fx.dir / "poses.txt",
            row3x4(Pose::Identity()) + "\n" + row3x4(Pose::Identity()) + "\n");
  EXPECT_MENTIONS(errorOf([&] { SemanticKittiReader r(fx.dir); }),
                  "poses.txt: no pose for frame 2");

  writeSemanticKitti(fx.dir);
  writeText(fx.dir / "calib.txt", "P0: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_MENTIONS(errorOf([&] { SemanticKittiReader r(fx.dir); }), "calib.txt: Tr: missing");

  writeSemanticKitti(fx.dir);
  writeKittiBin(fx.dir / "velodyne" / "000000.bin",
                {{0, 0, 0, 0}, {1, std::numeric_limits<float>::infinity(), 0, 0}});
  writeBytes(fx.dir / "labels" / "000000.label", std::vector<uint8_t>(8, 0));
  SemanticKittiReader reader(fx.dir);
  const std::string msg = errorOf([&] { reader.frame(0); });
  EXPECT_MENTIONS(msg, "000000.bin");
  EXPECT_MENTIONS(msg, "point 1");
}

// With image_2: P2 = K [I | K^-1 p], the stereo offset t = K^-1 p = (0.06, -0.01, 0.004) m, on a
// Tr without rotation noise, and 40x30 pictures.
constexpr double kFx = 700, kCx = 20, kCy = 15;
const Eigen::Vector3d kOffset(0.06, -0.01, 0.004);

Pose cleanTr() {
  Pose Tr = Pose::Identity();
  Tr.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Tr.translation() = Eigen::Vector3d(0, -0.08, -0.27);
  return Tr;
}

Eigen::Matrix<double, 3, 4> p2Matrix() {
  Eigen::Matrix3d K;
  K << kFx, 0, kCx, 0, kFx, kCy, 0, 0, 1;
  Eigen::Matrix<double, 3, 4> P;
  P << K, K * kOffset;
  return P;
}

std::string p2Line() {
  std::string s = "P2:";
  char buf[40];
  const Eigen::Matrix<double, 3, 4> P = p2Matrix();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) {
      std::snprintf(buf, sizeof(buf), " %.17g", P(r, c));
      s += buf;
    }
  return s;
}

// The fixture with image_2 pictures (one grey level per frame) and that calibration.
SemanticKittiFixture writeSemanticKittiWithImages(const fs::path& dir) {
  SemanticKittiFixture fx = writeSemanticKitti(dir);
  fx.Tr = cleanTr();
  const std::string P0 = "700 0 20 0 0 700 15 0 0 0 1 0";
  writeText(dir / "calib.txt", "P0: " + P0 + "\nP1: " + P0 + "\n" + p2Line() + "\nP3: " + P0 +
                                   "\nTr: " + row3x4(fx.Tr) + "\n");
  fs::create_directories(dir / "image_2");
  for (int k = 0; k < 3; ++k)
    writePng(dir / "image_2" / ("00000" + std::to_string(k) + ".png"),
             Image(40, 30, 3, static_cast<uint8_t>(50 * k)));
  return fx;
}

TEST(SemanticKitti, Image2IsACameraProjectingAsP2TimesTr) {
  TempDir tmp;
  const SemanticKittiFixture fx = writeSemanticKittiWithImages(tmp.path() / "05");
  SemanticKittiReader reader(fx.dir);
  ASSERT_EQ(reader.info().rig.cameras.size(), 1u);
  const Camera& cam = reader.info().rig.cameras[0];
  EXPECT_EQ(cam.name, "image_2");
  EXPECT_EQ(cam.width, 40);
  EXPECT_EQ(cam.height, 30);
  // A point 20.27 m ahead of the Velodyne, 8 cm below it, is 20 m ahead of camera 0 on its axis
  // (Tr), and (0.06, -0.01, 20.004) in camera 2: pixel (20 + 700 * 0.06 / 20.004,
  // 15 - 700 * 0.01 / 20.004).
  const auto uv = cam.project(cam.T_camera_lidar * Eigen::Vector3d(20.27, 0, -0.08));
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 20 + 42.0 / 20.004, 1e-9);
  EXPECT_NEAR(uv->y(), 15 - 7.0 / 20.004, 1e-9);
  // Any point: the devkit's P2 * Tr * X.
  for (const Eigen::Vector3d& X :
       {Eigen::Vector3d(5, 1, 0.5), Eigen::Vector3d(30, -4, -1.5), Eigen::Vector3d(2, 0.3, 0.2)}) {
    const Eigen::Vector3d h = p2Matrix() * (fx.Tr * X).homogeneous();
    const auto got = cam.project(cam.T_camera_lidar * X);
    ASSERT_TRUE(got.has_value());
    EXPECT_NEAR(got->x(), h.x() / h.z(), 1e-9);
    EXPECT_NEAR(got->y(), h.y() / h.z(), 1e-9);
  }
  const Frame f = reader.frame(2);
  ASSERT_EQ(f.cameras.size(), 1u);
  EXPECT_EQ(f.cameras[0].rgb.width, 40);
  EXPECT_EQ(f.cameras[0].rgb.channels, 3);
  EXPECT_EQ(f.cameras[0].rgb.at(3, 4)[1], 100);  // frame 2's picture, not another's
  EXPECT_TRUE(f.cameras[0].label.empty());       // classes come from a network or a label set
  EXPECT_EQ(f.point_labels.size(), f.points.size());
}

TEST(SemanticKitti, Image2ErrorsNameTheFile) {
  TempDir tmp;
  const SemanticKittiFixture fx = writeSemanticKittiWithImages(tmp.path() / "05");
  fs::remove(fx.dir / "image_2" / "000001.png");
  std::string msg = errorOf([&] { SemanticKittiReader r(fx.dir); });
  EXPECT_MENTIONS(msg, (fx.dir / "image_2" / "000001.png").string() + ": missing");
  EXPECT_ONE_LINE(msg);

  writeSemanticKittiWithImages(fx.dir);
  writePng(fx.dir / "image_2" / "000001.png", Image(41, 30, 3, 0));
  SemanticKittiReader reader(fx.dir);
  msg = errorOf([&] { reader.frame(1); });
  EXPECT_MENTIONS(msg, (fx.dir / "image_2" / "000001.png").string() + ": picture is 41x30");
  EXPECT_MENTIONS(msg, "000000.png is 40x30");
  EXPECT_ONE_LINE(msg);

  writeSemanticKittiWithImages(fx.dir);
  replaceCalibLine(fx.dir / "calib.txt", "P2", "");
  msg = errorOf([&] { SemanticKittiReader r(fx.dir); });
  EXPECT_MENTIONS(msg, (fx.dir / "calib.txt").string() + ": P2: missing");
  EXPECT_ONE_LINE(msg);

  // Without poses the calibration is still needed for the camera.
  writeSemanticKittiWithImages(fx.dir);
  fs::remove(fx.dir / "poses.txt");
  replaceCalibLine(fx.dir / "calib.txt", "Tr", "");
  msg = errorOf([&] { SemanticKittiReader r(fx.dir); });
  EXPECT_MENTIONS(msg, (fx.dir / "calib.txt").string() + ": Tr: missing");
  EXPECT_ONE_LINE(msg);
  fs::remove(fx.dir / "calib.txt");
  msg = errorOf([&] { SemanticKittiReader r(fx.dir); });
  EXPECT_MENTIONS(msg, (fx.dir / "calib.txt").string() + ": cannot open");
  EXPECT_ONE_LINE(msg);
}

// The real sample: SemanticKITTI's labels say what each point is; where the points land must
// agree with the picture.
TEST(MiniKitti, PointsLandOnTheirPixels) {
  SEMSEGMAP_SKIP_WITHOUT_MINI_KITTI();
  TempDir tmp;
  for (const std::string sequence : {"05", "07"}) {
    SemanticKittiReader reader(test_support::miniKittiSequence(tmp.path(), sequence));
    ASSERT_EQ(reader.size(), 10u);
    const Camera& cam = reader.info().rig.cameras.at(0);
    EXPECT_EQ(cam.width, 1226);
    EXPECT_EQ(cam.height, 370);
    const Frame f = reader.frame(0);
    const Image& rgb = f.cameras.at(0).rgb;
    size_t in_image = 0, road = 0, road_grey = 0, near_road = 0, far_road = 0;
    double near_road_v = 0, far_road_v = 0;
    for (size_t i = 0; i < f.points.size(); ++i) {
      const LidarPoint& p = f.points[i];
      const Eigen::Vector3d pc = cam.T_camera_lidar * Eigen::Vector3d(p.x, p.y, p.z);
      const auto uv = cam.project(pc);
      if (!uv || !cam.inImage(*uv)) continue;
      ++in_image;
      if (f.point_labels[i].class_id != cls::kRoad) continue;
      ++road;
      const uint8_t* c = rgb.at(static_cast<int>(uv->x()), static_cast<int>(uv->y()));
      if (std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]}) < 40) ++road_grey;
      // Depth order: the road nearer the car lies lower in the picture.
      if (pc.z() < 10) near_road_v += uv->y(), ++near_road;
      if (pc.z() > 20) far_road_v += uv->y(), ++far_road;
    }
    const double share = static_cast<double>(in_image) / f.points.size();
    RecordProperty("in_image_share_" + sequence, std::to_string(share));
    RecordProperty("road_grey_share_" + sequence, std::to_string(double(road_grey) / road));
    // The picture spans 82 of the scan's 360 degrees of azimuth, and of the HDL-64E's rings (+2
    // to -24.8 degrees) those down to -14.7: about a sixth of the scan (0.163 in both).
    EXPECT_GT(share, 0.13) << sequence;
    EXPECT_LT(share, 0.20) << sequence;
    ASSERT_GT(road, 1000u) << sequence;
    EXPECT_GT(static_cast<double>(road_grey) / road, 0.9) << sequence;  // asphalt is grey
    ASSERT_GT(near_road, 100u);
    ASSERT_GT(far_road, 100u);
    EXPECT_GT(near_road_v / near_road, far_road_v / far_road + 40) << sequence;
    EXPECT_GT(far_road_v / far_road, cam.cy) << sequence;  // the road is below the horizon
  }
}

// ---------------------------------------------------------------------------------------------
// NCLT

constexpr int64_t kT0 = 1326030975000000;  // 2012-01-08, microseconds

uint16_t ncltQuantise(double metres) {
  return static_cast<uint16_t>(std::lround((metres + 100.0) / 0.005));
}

// NCLT's velodyne_sync layout: uint16 x, y, z, uint8 intensity, uint8 laser id, little-endian.
void writeNcltScan(const fs::path& path, const std::vector<Eigen::Vector3d>& points) {
  std::vector<uint8_t> bytes;
  for (size_t i = 0; i < points.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      const uint16_t q = ncltQuantise(points[i][a]);
      bytes.push_back(static_cast<uint8_t>(q & 0xff));
      bytes.push_back(static_cast<uint8_t>(q >> 8));
    }
    bytes.push_back(static_cast<uint8_t>(40 * i));  // intensity
    bytes.push_back(static_cast<uint8_t>(i % 32));  // laser id
  }
  writeBytes(path, bytes);
}

std::vector<Eigen::Vector3d> ncltPoints(int k) {
  return {{12.345 + k, -3.21, 0.987}, {-99.9, 99.9, 0.0}, {0.0027, -0.0026, 45.678 - k}};
}

fs::path writeNclt(const fs::path& dir) {
  for (int k = 0; k < 3; ++k)
    writeNcltScan(dir / "velodyne_sync" / (std::to_string(kT0 + 100000 * k) + ".bin"),
                  ncltPoints(k));
  // Scan 0 (kT0) lies before the first valid row (the NaN row is skipped); scan 1 sits halfway
  // between two rows; scan 2 hits a row exactly.
  writeText(dir / "groundtruth_2012-01-08.csv",
            std::to_string(kT0 - 20000) + ",nan,nan,nan,nan,nan,nan\n" +
                std::to_string(kT0 + 50000) + ",10,20,-1,0,0,0.2\n" + std::to_string(kT0 + 150000) +
                ",12,24,-3,0,0,0.6\n" + std::to_string(kT0 + 200000) +
                ",13,25,-4,0.05,-0.02,0.7\n");
  return dir;
}

TEST(Nclt, DecodesPackedPointsWithin5mm) {
  TempDir tmp;
  const fs::path dir = writeNclt(tmp.path() / "2012-01-08");
  NcltReader reader(dir);
  ASSERT_EQ(reader.size(), 3u);
  EXPECT_TRUE(reader.info().rig.cameras.empty());
  EXPECT_FALSE(reader.info().has_point_labels);
  for (size_t k = 0; k < 3; ++k) {
    const Frame f = reader.frame(k);
    EXPECT_DOUBLE_EQ(f.timestamp_s,
                     static_cast<double>(kT0 + 100000 * static_cast<int64_t>(k)) * 1e-6);
    const auto expected = ncltPoints(static_cast<int>(k));
    ASSERT_EQ(f.points.size(), expected.size());
    for (size_t i = 0; i < expected.size(); ++i) {
      EXPECT_NEAR(f.points[i].x, expected[i].x(), 0.0025 + 1e-5);
      EXPECT_NEAR(f.points[i].y, expected[i].y(), 0.0025 + 1e-5);
      EXPECT_NEAR(f.points[i].z, expected[i].z(), 0.0025 + 1e-5);
      EXPECT_FLOAT_EQ(f.points[i].intensity, static_cast<float>(40 * i) / 255.0f);
      EXPECT_TRUE(f.point_labels.empty());
    }
  }
  // 0 maps to -100 m exactly: the offset, not something near it.
  writeBytes(dir / "velodyne_sync" / (std::to_string(kT0 + 300000) + ".bin"),
             {0, 0, 0, 0, 0, 0, 255, 7});
  NcltReader again(dir);
  const Frame f = again.frame(3);
  ASSERT_EQ(f.points.size(), 1u);
  EXPECT_EQ(f.points[0].x, -100.0f);
  EXPECT_EQ(f.points[0].intensity, 1.0f);
}

TEST(Nclt, GroundTruthIsInterpolatedAndTurnedZUp) {
  TempDir tmp;
  NcltReader reader(writeNclt(tmp.path() / "2012-01-08"));
  EXPECT_TRUE(reader.info().has_ground_truth_poses);
  // The LiDAR frame is NCLT's z-down body frame; the base is its z-up version.
  Pose F = Pose::Identity();
  F.linear() = Eigen::Vector3d(1, -1, -1).asDiagonal();
  EXPECT_TRUE(reader.info().rig.T_base_lidar.isApprox(F));

  const Frame f0 = reader.frame(0), f1 = reader.frame(1), f2 = reader.frame(2);
  EXPECT_FALSE(f0.T_world_base.has_value());  // before the first valid row
  // Its odometry holds the first known pose (x 10, y 20, z -1, yaw 0.2 in NED).
  EXPECT_LT((f0.T_odom_base.translation() - Eigen::Vector3d(10, -20, 1)).norm(), 1e-12);

  // Halfway between (10, 20, -1, yaw 0.2) and (12, 24, -3, yaw 0.6): (11, 22, -2, yaw 0.4) in
  // NED, i.e. (11, -22, 2) with yaw -0.4 in the z-up world.
  ASSERT_TRUE(f1.T_world_base.has_value());
  EXPECT_LT((f1.T_world_base->translation() - Eigen::Vector3d(11, -22, 2)).norm(), 1e-9);
  EXPECT_NEAR(yawOf(*f1.T_world_base), -0.4, 1e-9);
  EXPECT_TRUE(f1.T_odom_base.isApprox(*f1.T_world_base));

  // Exactly on a row, with roll and pitch: R = Rz(yaw) Ry(pitch) Rx(roll), conjugated by F.
  ASSERT_TRUE(f2.T_world_base.has_value());
  const Eigen::Matrix3d R_ned = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(-0.02, Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()))
                                    .toRotationMatrix();
  const Eigen::Matrix3d Fm = F.linear();
  EXPECT_TRUE(f2.T_world_base->linear().isApprox(Fm * R_ned * Fm, 1e-12));
  EXPECT_LT((f2.T_world_base->translation() - Eigen::Vector3d(13, -25, 4)).norm(), 1e-12);

  // A point on the robot's left in the z-up base is at negative y in NCLT's body (right) frame.
  const Eigen::Vector3d left_in_base = reader.info().rig.T_base_lidar * Eigen::Vector3d(0, -1, 0);
  EXPECT_GT(left_in_base.y(), 0.0);
}

TEST(Nclt, WithoutGroundTruthOdometryIsIdentity) {
  TempDir tmp;
  const fs::path dir = writeNclt(tmp.path() / "2012-01-08");
  fs::remove(dir / "groundtruth_2012-01-08.csv");
  NcltReader reader(dir);
  EXPECT_FALSE(reader.info().has_ground_truth_poses);
  const Frame f = reader.frame(1);
  EXPECT_FALSE(f.T_world_base.has_value());
  EXPECT_TRUE(f.T_odom_base.isApprox(Pose::Identity()));
}

TEST(Nclt, ErrorsNameTheFile) {
  TempDir tmp;
  const fs::path dir = writeNclt(tmp.path() / "2012-01-08");
  const fs::path scan = dir / "velodyne_sync" / (std::to_string(kT0 + 100000) + ".bin");
  fs::resize_file(scan, 8 * 3 - 5);
  NcltReader reader(dir);
  EXPECT_MENTIONS(errorOf([&] { reader.frame(1); }), scan.string() + ": truncated");

  writeText(dir / "groundtruth_2012-01-08.csv", std::to_string(kT0) + ",1,2,3,0,0\n");
  std::string msg = errorOf([&] { NcltReader r(dir); });
  EXPECT_MENTIONS(msg, "groundtruth_2012-01-08.csv: line 1: expected 7 values");

  writeText(dir / "groundtruth_2012-01-08.csv",
            std::to_string(kT0) + ",1,2,3,0,0,0\n" + std::to_string(kT0) + ",1,x,3,0,0,0\n");
  msg = errorOf([&] { NcltReader r(dir); });
  EXPECT_MENTIONS(msg, "groundtruth_2012-01-08.csv: line 2: 'x' is not a number");

  writeText(dir / "groundtruth_2012-01-15.csv", "");
  msg = errorOf([&] { NcltReader r(dir); });
  EXPECT_MENTIONS(msg, "more than one ground truth file");
  fs::remove(dir / "groundtruth_2012-01-15.csv");

  writeText(dir / "velodyne_sync" / "scan_12.bin", "");
  msg = errorOf([&] { NcltReader r(dir); });
  EXPECT_MENTIONS(msg, "scan_12.bin: file name is not a timestamp in microseconds");
}

}  // namespace
}  // namespace semsegmap
