// The dataset directory format: a written dataset reads back identical, and every kind of damage
// a user can do to one gives an error that names the damaged file.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/dataset_reader.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/outputs/run_output.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {
namespace fs = std::filesystem;

using semsegmap::test_support::TempDir;

std::string readText(const fs::path& path) {
  return readFileBytes(path);
}

void writeText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << text;
}

// Replaces the one occurrence of `from`; fails the test if there is not exactly one, so that a
// change of fixture cannot silently turn a mutation test into a no-op.
std::string replaceOnce(const std::string& text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "'" << from << "' not found";
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << "'" << from << "' found twice";
  if (at == std::string::npos) return text;
  return text.substr(0, at) + to + text.substr(at + from.size());
}

// Runs `f`, expects an exception of type E whose message contains every one of `parts`.
template <typename E = std::runtime_error>
void expectError(const std::function<void()>& f, const std::vector<std::string>& parts) {
  try {
    f();
    ADD_FAILURE() << "no exception thrown";
  } catch (const E& e) {
    const std::string message = e.what();
    for (const auto& part : parts)
      EXPECT_NE(message.find(part), std::string::npos)
          << "message '" << message << "' lacks '" << part << "'";
    EXPECT_EQ(message.find('\n'), std::string::npos) << "message spans lines: " << message;
  }
}

Pose somePose(double a, double b, double c) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d(1.0, b, -c).normalized()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(a * 10.1, -b * 3.3, c + 0.123456789);
  return T;
}

double poseDifference(const Pose& a, const Pose& b) {
  return (a.matrix() - b.matrix()).cwiseAbs().maxCoeff();
}

DatasetInfo tinyInfo() {
  DatasetInfo info;
  info.name = "tiny test";
  info.has_ground_truth_poses = true;
  info.has_odometry = true;
  info.has_point_labels = true;
  info.rig.rate_hz = 10.0 / 3.0;  // not representable in a few digits: tests full precision
  info.rig.lidar.columns = 32;
  info.rig.lidar.rows = 4;
  info.rig.lidar.hfov_deg = 360.0;
  info.rig.lidar.vfov_up_deg = 10.5;
  info.rig.lidar.vfov_down_deg = -15.25;
  info.rig.lidar.min_range_m = 0.5;
  info.rig.lidar.max_range_m = 80.0;
  info.rig.lidar.range_noise_m = 0.1;
  info.rig.lidar.dropout = 1e-5;
  info.rig.T_base_lidar = somePose(0.2, 0.4, 0.7);
  const char* names[] = {"left", "front"};
  for (int k = 0; k < 2; ++k) {
    Camera cam;
    cam.name = names[k];
    cam.width = 8;
    cam.height = 6;
    cam.fx = 4.1 + k;
    cam.fy = 4.2 + k / 7.0;
    cam.cx = 3.9;
    cam.cy = 2.95;
    cam.T_camera_lidar = somePose(1.1 + k, 0.3, -0.9);
    info.rig.cameras.push_back(cam);
  }
  return info;
}

Frame tinyFrame(size_t index, bool with_gt) {
  Frame f;
  f.index = index;
  f.timestamp_s = 1234567890.123456 + 0.1 * static_cast<double>(index);
  const int n = 10 + static_cast<int>(index);
  for (int i = 0; i < n; ++i) {
    f.points.push_back({0.1f * static_cast<float>(i) - 3.0f, 1e-30f * static_cast<float>(i),
                        -2.5f + static_cast<float>(index), static_cast<float>(i) / 7.0f});
    f.point_labels.push_back(
        {static_cast<ClassId>((i + index) % 15), static_cast<uint16_t>(i * 1000 + index)});
  }
  for (int k = 0; k < 2; ++k) {
    CameraFrame cam;
    cam.rgb = Image(8, 6, 3);
    cam.label = Image(8, 6, 1);
    for (int y = 0; y < 6; ++y)
      for (int x = 0; x < 8; ++x) {
        for (int c = 0; c < 3; ++c)
          cam.rgb.at(x, y)[c] = static_cast<uint8_t>(x * 30 + y * 7 + c * 50 + k + index);
        *cam.label.at(x, y) = static_cast<uint8_t>((x + y + k + index) % 15);
      }
    f.cameras.push_back(cam);
  }
  f.T_odom_base = somePose(0.01 * static_cast<double>(index + 1), 2.0, 3.0);
  if (with_gt) f.T_world_base = somePose(0.02 * static_cast<double>(index + 1), 1.0, 0.5);
  return f;
}

// Frames 0, 1 and 3 (a gap, so file names must follow the index, not the row); gt on 0 and 3.
std::vector<Frame> writeTinyDataset(const fs::path& dir) {
  std::vector<Frame> frames = {tinyFrame(0, true), tinyFrame(1, false), tinyFrame(3, true)};
  DatasetWriter writer(dir, tinyInfo());
  for (const auto& f : frames) writer.write(f);
  EXPECT_EQ(writer.framesWritten(), 3u);
  return frames;
}

void expectSameFrame(const Frame& a, const Frame& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.timestamp_s, b.timestamp_s);
  ASSERT_EQ(a.points.size(), b.points.size());
  for (size_t i = 0; i < a.points.size(); ++i)
    EXPECT_EQ(std::memcmp(&a.points[i], &b.points[i], sizeof(LidarPoint)), 0) << "point " << i;
  EXPECT_EQ(a.point_labels, b.point_labels);
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (size_t k = 0; k < a.cameras.size(); ++k) {
    EXPECT_EQ(a.cameras[k].rgb, b.cameras[k].rgb) << "camera " << k;
    EXPECT_EQ(a.cameras[k].label, b.cameras[k].label) << "camera " << k;
  }
  EXPECT_LT(poseDifference(a.T_odom_base, b.T_odom_base), 1e-12);
  ASSERT_EQ(a.T_world_base.has_value(), b.T_world_base.has_value());
  if (a.T_world_base) {
    EXPECT_LT(poseDifference(*a.T_world_base, *b.T_world_base), 1e-12);
  }
}

void expectSameInfo(const DatasetInfo& a, const DatasetInfo& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_EQ(a.has_ground_truth_poses, b.has_ground_truth_poses);
  EXPECT_EQ(a.has_odometry, b.has_odometry);
  EXPECT_EQ(a.odometry_is_ground_truth, b.odometry_is_ground_truth);
  EXPECT_EQ(a.has_point_labels, b.has_point_labels);
  EXPECT_TRUE(a.classes == b.classes);
  EXPECT_EQ(a.rig.rate_hz, b.rig.rate_hz);
  const LidarModel &la = a.rig.lidar, &lb = b.rig.lidar;
  EXPECT_EQ(la.columns, lb.columns);
  EXPECT_EQ(la.rows, lb.rows);
  EXPECT_EQ(la.hfov_deg, lb.hfov_deg);
  EXPECT_EQ(la.vfov_up_deg, lb.vfov_up_deg);
  EXPECT_EQ(la.vfov_down_deg, lb.vfov_down_deg);
  EXPECT_EQ(la.min_range_m, lb.min_range_m);
  EXPECT_EQ(la.max_range_m, lb.max_range_m);
  EXPECT_EQ(la.range_noise_m, lb.range_noise_m);
  EXPECT_EQ(la.dropout, lb.dropout);
  EXPECT_LT(poseDifference(a.rig.T_base_lidar, b.rig.T_base_lidar), 1e-12);
  ASSERT_EQ(a.rig.cameras.size(), b.rig.cameras.size());
  for (size_t k = 0; k < a.rig.cameras.size(); ++k) {
    const Camera &ca = a.rig.cameras[k], &cb = b.rig.cameras[k];
    EXPECT_EQ(ca.name, cb.name);
    EXPECT_EQ(ca.width, cb.width);
    EXPECT_EQ(ca.height, cb.height);
    EXPECT_EQ(ca.fx, cb.fx);
    EXPECT_EQ(ca.fy, cb.fy);
    EXPECT_EQ(ca.cx, cb.cx);
    EXPECT_EQ(ca.cy, cb.cy);
    EXPECT_LT(poseDifference(ca.T_camera_lidar, cb.T_camera_lidar), 1e-12);
  }
}

std::vector<fs::path> temporaryFilesUnder(const fs::path& dir) {
  std::vector<fs::path> found;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp") != std::string::npos) found.push_back(e.path());
  return found;
}

// ---------------------------------------------------------------------------------------------
// Round trip

TEST(DatasetIo, RoundTripGivesIdenticalFramesAndInfo) {
  TempDir tmp;
  const DatasetInfo info = tinyInfo();
  const std::vector<Frame> written = writeTinyDataset(tmp.path());

  DatasetReader reader(tmp.path());
  expectSameInfo(info, reader.info());
  ASSERT_EQ(reader.size(), written.size());
  for (size_t i = 0; i < written.size(); ++i) expectSameFrame(written[i], reader.frame(i));
  EXPECT_TRUE(temporaryFilesUnder(tmp.path()).empty());
}

// A dataset converted from one whose odometry is its ground truth keeps saying so.
TEST(DatasetIo, OdometryThatIsTheGroundTruthStaysMarked) {
  TempDir tmp;
  DatasetInfo info = tinyInfo();
  writeMetaYaml(tmp.path() / "meta.yaml", info);
  EXPECT_EQ(readFileBytes(tmp.path() / "meta.yaml").find("odometry_is_ground_truth"),
            std::string::npos);  // absent when false: older builds read the file as before
  EXPECT_FALSE(readMetaYaml(tmp.path() / "meta.yaml").odometry_is_ground_truth);
  info.odometry_is_ground_truth = true;
  writeMetaYaml(tmp.path() / "meta.yaml", info);
  EXPECT_TRUE(readMetaYaml(tmp.path() / "meta.yaml").odometry_is_ground_truth);
}

TEST(DatasetIo, FilesFollowTheDocumentedLayout) {
  TempDir tmp;
  writeTinyDataset(tmp.path());
  for (const char* f :
       {"meta.yaml", "frames.csv", "lidar/000003.bin", "lidar_gt/000003.bin", "cam0/000003.png",
        "cam1/000003.png", "cam0_label/000003.png", "cam1_label/000003.png"})
    EXPECT_TRUE(fs::exists(tmp.path() / f)) << f;
  EXPECT_FALSE(fs::exists(tmp.path() / "lidar/000002.bin"));
  // KITTI layout: 16 bytes per point; SemanticKITTI: 4 bytes per label, class in the low half.
  EXPECT_EQ(fs::file_size(tmp.path() / "lidar/000003.bin"), 13u * 16u);
  const std::string labels = readFileBytes(tmp.path() / "lidar_gt/000001.bin");
  ASSERT_EQ(labels.size(), 11u * 4u);
  uint32_t word = 0;
  std::memcpy(&word, &labels[4 * 2], 4);  // point 2 of frame 1: class 3, instance 2001
  EXPECT_EQ(word, 3u | (2001u << 16));

  const std::string csv = readText(tmp.path() / "frames.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), kFramesCsvHeader);
  // Frame 1 has no ground truth: its seven gt columns are empty.
  EXPECT_NE(csv.find("\n1,1234567890.223456,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",,,,,,,\n"), std::string::npos) << csv;
}

TEST(DatasetIo, HandWrittenMetaYamlFromTheDocsReads) {
  TempDir tmp;
  // The example of docs/dataset-format.md, verbatim: what the docs show must read.
  writeText(tmp.path() / "meta.yaml", R"(format_version: 1
name: "sim-town"
rate_hz: 5
has_ground_truth_poses: true
has_point_labels: true
lidar:
  columns: 1920
  rows: 64
  hfov_deg: 270
  vfov_up_deg: 2
  vfov_down_deg: -24.8
  min_range_m: 0.9
  max_range_m: 100
  range_noise_m: 0.02
  dropout: 0.01
  T_base_lidar: [0, 0, 1.9, 0, 0, 0, 1]
cameras:
  - name: "front"
    width: 640
    height: 480
    fx: 320
    fy: 320
    cx: 320
    cy: 240
    T_camera_lidar: [0, -0.25, -0.35, 0.5, -0.5, 0.5, 0.5]
classes:
  - {id: 0, name: "unknown", color: [0, 0, 0], dynamic: false, ground: false}
  - {id: 1, name: "road", color: [255, 0, 255], dynamic: false, ground: true}
  - {id: 11, name: "car", color: [100, 150, 245], dynamic: true, ground: false}
)");
  const DatasetInfo info = readMetaYaml(tmp.path() / "meta.yaml");
  EXPECT_EQ(info.name, "sim-town");
  EXPECT_EQ(info.rig.lidar.vfov_down_deg, -24.8);
  EXPECT_EQ(info.rig.T_base_lidar.translation().z(), 1.9);
  ASSERT_EQ(info.rig.cameras.size(), 1u);
  EXPECT_EQ(info.rig.cameras[0].height, 480);
  // That quaternion turns the camera's optical axis (z) into the LiDAR's forward axis (x).
  const Eigen::Vector3d forward =
      info.rig.cameras[0].T_camera_lidar.linear() * Eigen::Vector3d::UnitX();
  EXPECT_LT((forward - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  ASSERT_EQ(info.classes.classes().size(), 3u);
  EXPECT_TRUE(info.classes.at(1).ground);
  EXPECT_TRUE(info.classes.at(11).dynamic);
  EXPECT_EQ(info.classes.at(11).color_rgb[2], 245);
}

TEST(DatasetIo, RewritingADatasetReplacesItsOldStreams) {
  TempDir tmp;
  writeTinyDataset(tmp.path());
  DatasetInfo info = tinyInfo();
  info.has_point_labels = false;
  Frame f = tinyFrame(0, false);
  f.point_labels.clear();
  f.cameras[1].rgb = Image();
  {
    DatasetWriter writer(tmp.path(), info);
    writer.write(f);
  }
  EXPECT_FALSE(fs::exists(tmp.path() / "cam1"));
  EXPECT_FALSE(fs::exists(tmp.path() / "lidar_gt"));
  DatasetReader reader(tmp.path());
  ASSERT_EQ(reader.size(), 1u);
  expectSameFrame(f, reader.frame(0));
}

TEST(DatasetIo, WriterRefusesADirectoryWithFormatFoldersButNoMeta) {
  TempDir tmp;
  fs::create_directories(tmp.path() / "lidar");
  expectError([&] { DatasetWriter(tmp.path(), tinyInfo()); }, {tmp.path().string(), "lidar"});
}

TEST(DatasetIo, OutOfRangeFrameThrowsOutOfRange) {
  TempDir tmp;
  writeTinyDataset(tmp.path());
  DatasetReader reader(tmp.path());
  EXPECT_THROW(reader.frame(3), std::out_of_range);
}

// ---------------------------------------------------------------------------------------------
// meta.yaml errors

class MetaYamlErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    writeTinyDataset(tmp_.path());
    meta_ = tmp_.path() / "meta.yaml";
    text_ = readText(meta_);
  }
  // Writes the mutated meta.yaml and expects both readMetaYaml and DatasetReader to fail naming
  // meta.yaml and saying `what`.
  void expectRejected(const std::string& mutated, const std::string& what) {
    writeText(meta_, mutated);
    expectError([&] { readMetaYaml(meta_); }, {meta_.string(), what});
    expectError([&] { DatasetReader reader(tmp_.path()); }, {meta_.string(), what});
  }
  TempDir tmp_;
  fs::path meta_;
  std::string text_;
};

TEST_F(MetaYamlErrors, UnknownKeyInACamera) {
  expectRejected(replaceOnce(text_, "name: \"front\"\n", "name: \"front\"\n    foo: 1\n"),
                 "unknown key 'foo' in cameras[1]");
}

TEST_F(MetaYamlErrors, UnknownTopLevelKey) {
  expectRejected(text_ + "colour: red\n", "unknown key 'colour' at the top level");
}

TEST_F(MetaYamlErrors, OtherFormatVersion) {
  expectRejected(replaceOnce(text_, "format_version: 1\n", "format_version: 2\n"),
                 "format_version is 2, but this build reads version 1");
}

TEST_F(MetaYamlErrors, MissingField) {
  expectRejected(replaceOnce(text_, "    fy: " + formatExactDouble(4.2 + 1 / 7.0) + "\n", ""),
                 "cameras[1].fy: missing");
}

TEST_F(MetaYamlErrors, NegativeFocalLength) {
  expectRejected(replaceOnce(text_, "fx: 5.1\n", "fx: -5.1\n"), "focal lengths");
}

TEST_F(MetaYamlErrors, WrongType) {
  expectRejected(replaceOnce(text_, "rows: 4\n", "rows: four\n"),
                 "lidar.rows: expected an integer, got 'four'");
}

TEST_F(MetaYamlErrors, BadPose) {
  expectRejected(replaceOnce(text_, "T_base_lidar: [", "T_base_lidar: [1, "),
                 "lidar.T_base_lidar: expected [x, y, z, qx, qy, qz, qw]");
}

// 1e308 is finite, and used to give 0 segments and exit 0: a sensor 100 m from the base is no rig.
TEST_F(MetaYamlErrors, AbsurdExtrinsic) {
  const size_t from = text_.find("T_base_lidar: [");
  ASSERT_NE(from, std::string::npos);
  const size_t to = text_.find(']', from);
  std::string mutated = text_;
  mutated.replace(from, to + 1 - from, "T_base_lidar: [1e308, 0, 0, 0, 0, 0, 1]");
  expectRejected(mutated, "lidar.T_base_lidar: translation [1e+308, 0, 0] m: more than 100 m");
}

TEST_F(MetaYamlErrors, DuplicateClassId) {
  expectRejected(replaceOnce(text_, "{id: 14,", "{id: 13,"), "id 13 appears twice");
}

TEST_F(MetaYamlErrors, YamlSyntaxError) {
  expectRejected(text_ + "cameras: [\n", "YAML syntax error at line");
}

TEST_F(MetaYamlErrors, MissingFile) {
  fs::remove(meta_);
  expectError([&] { DatasetReader reader(tmp_.path()); }, {meta_.string(), "missing"});
}

// ---------------------------------------------------------------------------------------------
// Damaged frame files

class DamagedFrames : public ::testing::Test {
 protected:
  void SetUp() override { writeTinyDataset(tmp_.path()); }
  fs::path file(const std::string& relative) const { return tmp_.path() / relative; }
  // Frame 1 (row 1) is the one the tests damage; the others must still read.
  void expectFrame1Fails(const std::vector<std::string>& parts) {
    DatasetReader reader(tmp_.path());
    expectError([&] { reader.frame(1); }, parts);
    EXPECT_NO_THROW(reader.frame(0));
    EXPECT_NO_THROW(reader.frame(2));
  }
  // A missing or mis-sized file is found by stat when the reader opens, before any frame is
  // read; a run of frame 0 alone does not look at frame 1's files.
  void expectFoundBeforeAnyFrame(const std::vector<std::string>& parts) {
    expectError([&] { DatasetReader reader(tmp_.path()); }, parts);
    expectError([&] { DatasetReader reader(tmp_.path(), 2); }, parts);
    DatasetReader first(tmp_.path(), 1);
    EXPECT_EQ(first.size(), 3u);
    EXPECT_NO_THROW(first.frame(0));
    EXPECT_NO_THROW(first.frame(2));
    expectError([&] { first.frame(1); }, {parts.front()});
  }
  TempDir tmp_;
};

TEST_F(DamagedFrames, TruncatedLidarBin) {
  fs::resize_file(file("lidar/000001.bin"), 11 * 16 - 3);
  expectFoundBeforeAnyFrame(
      {file("lidar/000001.bin").string(), "truncated (173 bytes is not a multiple of 16)"});
}

TEST_F(DamagedFrames, MissingLidarBin) {
  fs::remove(file("lidar/000001.bin"));
  expectFoundBeforeAnyFrame({file("lidar/000001.bin").string(), ": missing"});
}

TEST_F(DamagedFrames, MissingCameraPng) {
  fs::remove(file("cam1/000001.png"));
  expectFoundBeforeAnyFrame({file("cam1/000001.png").string(), ": missing"});
}

TEST_F(DamagedFrames, PngOfTheWrongSize) {
  writePng(file("cam0/000001.png"), Image(9, 6, 3));
  expectFrame1Fails({file("cam0/000001.png").string(), "image is 9x6, meta.yaml says 8x6"});
}

TEST_F(DamagedFrames, RgbWhereALabelImageBelongs) {
  writePng(file("cam0_label/000001.png"), Image(8, 6, 3));
  expectFrame1Fails({file("cam0_label/000001.png").string(), "3 channels, expected 1"});
}

TEST_F(DamagedFrames, MissingLabelImage) {
  fs::remove(file("cam0_label/000001.png"));
  expectFoundBeforeAnyFrame({file("cam0_label/000001.png").string(), ": missing"});
}

TEST_F(DamagedFrames, LabelCountDiffersFromPointCount) {
  writeLabelBin(file("lidar_gt/000001.bin"), std::vector<PointLabel>(7));
  expectFoundBeforeAnyFrame({file("lidar_gt/000001.bin").string(),
                             file("lidar/000001.bin").string(), "28 bytes, expected 44",
                             "11 points"});
}

TEST_F(DamagedFrames, LabelWithAClassNotInTheTable) {
  std::vector<PointLabel> labels(11);
  labels[4].class_id = 99;
  writeLabelBin(file("lidar_gt/000001.bin"), labels);
  expectFrame1Fails({file("lidar_gt/000001.bin").string(), "point 4 has class 99"});
}

TEST_F(DamagedFrames, NanInALidarFile) {
  std::string bytes = readFileBytes(file("lidar/000001.bin"));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&bytes[2 * 16 + 4], &nan, 4);  // y of point 2
  writeText(file("lidar/000001.bin"), bytes);
  expectFrame1Fails({file("lidar/000001.bin").string(), "point 2 has a non-finite coordinate"});
}

TEST_F(DamagedFrames, GarbagePng) {
  writeText(file("cam1_label/000001.png"), "this is not a PNG at all");
  expectFoundBeforeAnyFrame({file("cam1_label/000001.png").string(), "too small for a PNG"});
  writeText(file("cam1_label/000001.png"), std::string(100, 'x'));  // a plausible size
  expectFrame1Fails({file("cam1_label/000001.png").string(), "not a PNG"});
}

TEST_F(DamagedFrames, PngCutShort) {
  const std::string bytes = readFileBytes(file("cam1/000001.png"));
  writeText(file("cam1/000001.png"), bytes.substr(0, bytes.size() / 2));
  expectFrame1Fails({file("cam1/000001.png").string(), "corrupt PNG"});
}

TEST(DatasetIo, BadFramesCsvRowNamesFileAndLine) {
  TempDir tmp;
  writeTinyDataset(tmp.path());
  const fs::path csv = tmp.path() / "frames.csv";
  const std::string good = readText(csv);

  writeText(csv, replaceOnce(good, "\n1,1234567890.223456,", "\n1,12345x,"));
  expectError([&] { DatasetReader reader(tmp.path()); },
              {csv.string(), "line 3: timestamp_s: expected a finite number, got '12345x'"});

  writeText(csv, replaceOnce(good, "\n1,1234567890.223456,", "\n1,1234567890.223456,7,"));
  expectError([&] { DatasetReader reader(tmp.path()); },
              {csv.string(), "line 3: expected 16 comma-separated fields, got 17"});

  writeText(csv, replaceOnce(good, "\n3,", "\n1,"));
  expectError([&] { DatasetReader reader(tmp.path()); },
              {csv.string(), "line 4: index 1 does not follow 1"});

  writeText(csv, replaceOnce(good, "index,", "idx,"));
  expectError([&] { DatasetReader reader(tmp.path()); }, {csv.string(), "line 1"});
}

TEST(DatasetIo, AbsurdPositionInFramesCsvIsRefused) {
  TempDir tmp;
  writeTinyDataset(tmp.path());
  const fs::path csv = tmp.path() / "frames.csv";
  const std::string good = readText(csv);
  const size_t row = good.find("\n1,");
  const size_t odom_x = good.find(',', good.find(',', row + 1) + 1) + 1;
  std::string bad = good;
  bad.replace(odom_x, good.find(',', odom_x) - odom_x, "1e308");
  writeText(csv, bad);
  expectError([&] { DatasetReader reader(tmp.path()); },
              {csv.string(), "line 3: odom_x: 1e308 m is beyond 10000000 m"});
}

size_t residentKib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stoul(line.substr(6));
  return 0;
}

// frames.csv is streamed: a million rows (the old reader held about 0.5 KB a row, 500 MB here)
// leave the reader's memory flat, a run of the first frame checks only its files, and any row
// reads back by seeking, in any order.
TEST(DatasetIo, AMillionRowFramesCsvIsIndexedNotHeld) {
  TempDir tmp;
  writeTinyDataset(tmp.path());
  const fs::path csv = tmp.path() / "frames.csv";
  constexpr size_t kRows = 1000000;
  {
    std::ofstream out(csv, std::ios::app | std::ios::binary);
    char line[160];
    for (size_t i = 4; i < kRows + 1; ++i) {
      std::snprintf(line, sizeof line, "%zu,%zu.5,%zu,2,3,0,0,0,1,,,,,,,\n", i, i, i % 1000);
      out << line;
    }
  }
  const size_t before = residentKib();
  DatasetReader reader(tmp.path(), 1);
  const size_t after = residentKib();
  ASSERT_EQ(reader.size(), kRows);
  EXPECT_LT(after - std::min(after, before), 20u * 1024u) << "KiB grown while indexing";
  EXPECT_NO_THROW(reader.frame(0));
  EXPECT_DOUBLE_EQ(reader.frameTime(kRows - 1), 1000000.5);
  EXPECT_DOUBLE_EQ(reader.frameTime(5000), 5001.5);  // back, then forward again
  EXPECT_DOUBLE_EQ(reader.frameTime(5001), 5002.5);
  EXPECT_DOUBLE_EQ(reader.frameTime(2), reader.frame(2).timestamp_s);
  // Checking every row's files finds the first frame without any.
  expectError([&] { DatasetReader all(tmp.path()); },
              {(tmp.path() / "lidar" / "000004.bin").string(), "missing"});
}

// ---------------------------------------------------------------------------------------------
// RunOutputs: a failed command's outputs are removed, nothing that was there before

std::vector<std::string> entriesOf(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    names.push_back(e.path().lexically_relative(dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

TEST(RunOutputs, AFailedRunRemovesWhatItCreatedAndNothingElse) {
  TempDir tmp;
  const fs::path old_dir = tmp.path() / "old";
  fs::create_directories(old_dir / "kept_empty");
  writeText(old_dir / "mine.txt", "before");
  writeText(old_dir / "replaced.txt", "before");
  {
    RunOutputs outputs;
    EXPECT_EQ(outputs.folder(old_dir), 3u);  // what it held before
    EXPECT_EQ(outputs.folder(tmp.path() / "new"), 0u);
    EXPECT_FALSE(outputs.file(tmp.path() / "x.map"));
    EXPECT_TRUE(fs::is_directory(tmp.path() / "new"));  // made up front
    fs::create_directories(old_dir / "sub");
    writeBytesAtomically(old_dir / "sub" / "summary.json", "{}");
    writeBytesAtomically(old_dir / "replaced.txt", "after");
    fs::create_directories(tmp.path() / "new" / "deep");
    writeBytesAtomically(tmp.path() / "new" / "deep" / "a.csv", "a");
    writeBytesAtomically(tmp.path() / "x.map", "m");
    writeBytesAtomically(tmp.path() / "cache.bin", "outside the outputs: kept");
  }  // not committed: the command failed
  EXPECT_EQ(entriesOf(tmp.path()), (std::vector<std::string>{"cache.bin", "old", "old/kept_empty",
                                                             "old/mine.txt", "old/replaced.txt"}));
  EXPECT_EQ(readText(old_dir / "mine.txt"), "before");
}

// Two runs in one process, one output inside the other's: each removes exactly its own new
// files, and the one left alive keeps watching its own after the other is gone.
TEST(RunOutputs, TwoAliveAtOnceEachRemoveOnlyTheirOwnFiles) {
  TempDir tmp;
  const fs::path a = tmp.path() / "a", b = tmp.path() / "b", inner = a / "inner";
  fs::create_directories(inner);
  fs::create_directories(b);
  {
    RunOutputs first;
    first.folder(a);
    {
      RunOutputs second;
      second.folder(b);
      second.folder(inner);
      writeBytesAtomically(a / "first.txt", "1");
      writeBytesAtomically(inner / "second.txt", "2");  // the innermost output: second's
      writeBytesAtomically(b / "second.txt", "2");
    }  // second failed: its two files go, first's stays
    EXPECT_EQ(entriesOf(tmp.path()),
              (std::vector<std::string>{"a", "a/first.txt", "a/inner", "b"}));
    writeBytesAtomically(inner / "first_after.txt", "1");  // no second any more: first's
  }
  EXPECT_EQ(entriesOf(tmp.path()), (std::vector<std::string>{"a", "a/inner", "b"}));
}

// The watches themselves: each of two sees its own new files, the innermost scope wins, and a
// file replaced (not new) is reported to none.
TEST(NewFileWatch, EachSeesTheNewFilesOfItsOwnScope) {
  TempDir tmp;
  const fs::path outer = tmp.path() / "outer", inner = outer / "inner";
  fs::create_directories(inner);
  std::vector<fs::path> outer_seen, inner_seen, file_seen;
  NewFileWatch outer_watch(outer, [&](const fs::path& p) { outer_seen.push_back(p); });
  {
    NewFileWatch inner_watch(inner, [&](const fs::path& p) { inner_seen.push_back(p); });
    NewFileWatch file_watch(outer / "one.txt", [&](const fs::path& p) { file_seen.push_back(p); });
    writeBytesAtomically(outer / "x.txt", "x");
    writeBytesAtomically(inner / "y.txt", "y");
    writeBytesAtomically(outer / "one.txt", "1");
    writeBytesAtomically(inner / "y.txt", "replaced");
    writeBytesAtomically(tmp.path() / "elsewhere.txt", "z");
  }
  writeBytesAtomically(inner / "z.txt", "z");
  EXPECT_EQ(outer_seen, (std::vector<fs::path>{outer / "x.txt", inner / "z.txt"}));
  EXPECT_EQ(inner_seen, (std::vector<fs::path>{inner / "y.txt"}));
  EXPECT_EQ(file_seen, (std::vector<fs::path>{outer / "one.txt"}));
}

TEST(RunOutputs, ACommittedRunKeepsEverything) {
  TempDir tmp;
  {
    RunOutputs outputs;
    outputs.folder(tmp.path() / "out");
    writeBytesAtomically(tmp.path() / "out" / "summary.json", "{}");
    outputs.commit();
  }
  EXPECT_TRUE(fs::exists(tmp.path() / "out" / "summary.json"));
}

// A missing folder above an output is a mistyped path: refused, never made.
TEST(RunOutputs, AnOutputWhoseFolderIsMissingIsRefusedAndNothingIsMade) {
  TempDir tmp;
  writeText(tmp.path() / "there.map", "x");
  RunOutputs outputs;
  const fs::path missing = tmp.path() / "no" / "such";
  expectError([&] { outputs.file(missing / "x.map", "--out"); },
              {(missing / "x.map").string() + ": --out cannot be written: its folder " +
               missing.string() + " does not exist"});
  expectError([&] { outputs.folder(missing / "out", "--out"); },
              {"its folder " + missing.string() + " does not exist"});
  expectError([&] { outputs.keptFile(missing / "c.cache", "--cache"); },
              {"--cache cannot be written"});
  EXPECT_EQ(entriesOf(tmp.path()), (std::vector<std::string>{"there.map"}));
  EXPECT_TRUE(outputs.file(tmp.path() / "there.map"));  // there before: replaced
  EXPECT_EQ(outputs.folder(tmp.path() / "out/"), 0u);   // a trailing '/' names the folder
  EXPECT_TRUE(fs::is_directory(tmp.path() / "out"));
}

TEST(RunOutputs, OutputsOfTheWrongKindAreRefusedBeforeAnythingIsMade) {
  TempDir tmp;
  writeText(tmp.path() / "file", "x");
  fs::create_directories(tmp.path() / "dir");
  RunOutputs outputs;
  expectError([&] { outputs.file(tmp.path() / "dir", "--out"); },
              {(tmp.path() / "dir").string(), "--out is a directory, expected a file"});
  expectError([&] { outputs.folder(tmp.path() / "file"); }, {"exists and is not a directory"});
  expectError([&] { outputs.folder(tmp.path() / "file" / "a" / "b"); },
              {"cannot be created", (tmp.path() / "file").string() + " is not a directory"});
  EXPECT_EQ(entriesOf(tmp.path()), (std::vector<std::string>{"dir", "file"}));
  if (::geteuid() == 0) return;  // root writes anywhere: no read-only case to check
  fs::permissions(tmp.path() / "dir", fs::perms::owner_read | fs::perms::owner_exec);
  expectError([&] { outputs.folder(tmp.path() / "dir" / "out"); }, {"cannot be written"});
  fs::permissions(tmp.path() / "dir", fs::perms::owner_all);
}

// ---------------------------------------------------------------------------------------------
// Writer checks: a frame that could not be read back is refused before any file is written.

class WriterChecks : public ::testing::Test {
 protected:
  void expectRefused(const Frame& f, const std::vector<std::string>& parts) {
    expectError<std::invalid_argument>([&] { writer_.write(f); }, parts);
    EXPECT_FALSE(fs::exists(tmp_.path() / "lidar" / frameFileName(f.index, "bin")));
    EXPECT_EQ(writer_.framesWritten(), 1u);
  }
  TempDir tmp_;
  DatasetWriter writer_{tmp_.path(), tinyInfo()};
  void SetUp() override { writer_.write(tinyFrame(0, true)); }
};

TEST_F(WriterChecks, RgbImageOfTheWrongSizeNamesTheCamera) {
  Frame f = tinyFrame(1, false);
  f.cameras[1].rgb = Image(8, 7, 3);
  expectRefused(f, {"cam1/000001.png", "camera 'front'", "is 8x7, meta.yaml says 8x6"});
}

TEST_F(WriterChecks, LabelImageMustHaveOneChannel) {
  Frame f = tinyFrame(1, false);
  f.cameras[0].label = Image(8, 6, 3);
  expectRefused(f, {"cam0_label/000001.png", "camera 'left'", "3 channels, expected 1"});
}

TEST_F(WriterChecks, RgbImageMustHaveThreeChannels) {
  Frame f = tinyFrame(1, false);
  f.cameras[0].rgb = Image(8, 6, 1);
  expectRefused(f, {"cam0/000001.png", "camera 'left'", "1 channels, expected 3"});
}

TEST_F(WriterChecks, StreamsAreFixedByTheFirstFrame) {
  Frame f = tinyFrame(1, false);
  f.cameras[1].label = Image();
  expectRefused(f, {"cam1_label/000001.png", "lacks a label image of camera 'front'"});
}

TEST_F(WriterChecks, LabelCountMustMatchPoints) {
  Frame f = tinyFrame(1, false);
  f.point_labels.pop_back();
  expectRefused(f, {"lidar_gt/000001.bin", "10 point labels for 11 points"});
}

TEST_F(WriterChecks, IndicesMustIncrease) {
  writer_.write(tinyFrame(5, false));
  expectError<std::invalid_argument>([&] { writer_.write(tinyFrame(4, false)); },
                                     {"frames.csv", "indices must increase"});
  EXPECT_FALSE(fs::exists(tmp_.path() / "lidar/000004.bin"));
  EXPECT_EQ(DatasetReader(tmp_.path()).size(), 2u);
}

TEST_F(WriterChecks, NanPointIsRefused) {
  Frame f = tinyFrame(1, false);
  f.points[3].z = std::numeric_limits<float>::infinity();
  expectRefused(f, {"lidar/000001.bin", "point 3"});
  DatasetReader reader(tmp_.path());
  EXPECT_EQ(reader.size(), 1u);
}

TEST(DatasetIo, WriterRefusesAnInvalidRigBeforeTouchingTheDisk) {
  TempDir tmp;
  DatasetInfo info = tinyInfo();
  info.rig.cameras[1].fy = 0.0;
  expectError<std::invalid_argument>([&] { DatasetWriter(tmp.path() / "out", info); },
                                     {"meta.yaml", "camera 'front'"});
  EXPECT_FALSE(fs::exists(tmp.path() / "out"));
}

// ---------------------------------------------------------------------------------------------
// PNG and atomic files

// 2x1 PNGs made outside OpenCV (Python zlib): a red and a blue pixel, so that a channel-order
// mistake in either direction shows.
const unsigned char kPngRgbRedBlue[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
    0x44, 0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x08, 0x02, 0x00, 0x00,
    0x00, 0x7b, 0x40, 0xe8, 0xdd, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x44, 0x41, 0x54, 0x78,
    0xda, 0x63, 0xf8, 0xcf, 0x00, 0x04, 0xff, 0x01, 0x07, 0x00, 0x01, 0xff, 0x3d, 0x7d,
    0x8c, 0x49, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
const unsigned char kPngRgbaRedBlue[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44,
    0x52, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0xf4,
    0x22, 0x7f, 0x8a, 0x00, 0x00, 0x00, 0x11, 0x49, 0x44, 0x41, 0x54, 0x78, 0xda, 0x63, 0xf8,
    0xcf, 0xc0, 0xd0, 0xc0, 0xc0, 0xf0, 0xbf, 0x01, 0x00, 0x0c, 0xff, 0x02, 0xff, 0x36, 0x65,
    0x0f, 0xbe, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};
// 1x1, 16-bit grayscale.
const unsigned char kPngGray16[] = {
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48,
    0x44, 0x52, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x10, 0x00, 0x00, 0x00,
    0x00, 0x6a, 0xee, 0x47, 0x16, 0x00, 0x00, 0x00, 0x0b, 0x49, 0x44, 0x41, 0x54, 0x78,
    0xda, 0x63, 0x10, 0x32, 0x01, 0x00, 0x00, 0x5b, 0x00, 0x47, 0x05, 0x5f, 0x6c, 0x82,
    0x00, 0x00, 0x00, 0x00, 0x49, 0x45, 0x4e, 0x44, 0xae, 0x42, 0x60, 0x82};

template <size_t N>
std::string bytesOf(const unsigned char (&a)[N]) {
  return std::string(reinterpret_cast<const char*>(a), N);
}

TEST(ImageIo, ReadsRgbAndRgbaInRgbOrder) {
  TempDir tmp;
  const std::vector<uint8_t> red_blue = {255, 0, 0, 0, 0, 255};
  writeText(tmp.path() / "rgb.png", bytesOf(kPngRgbRedBlue));
  writeText(tmp.path() / "rgba.png", bytesOf(kPngRgbaRedBlue));
  for (const char* name : {"rgb.png", "rgba.png"}) {
    const Image image = readPng(tmp.path() / name);
    EXPECT_EQ(image.width, 2) << name;
    EXPECT_EQ(image.height, 1) << name;
    EXPECT_EQ(image.channels, 3) << name;
    EXPECT_EQ(image.data, red_blue) << name;
  }
}

TEST(ImageIo, WriteThenReadKeepsBytesAndChannelOrder) {
  TempDir tmp;
  Image rgb(2, 1, 3);
  rgb.data = {255, 0, 0, 0, 0, 255};
  writePng(tmp.path() / "rgb.png", rgb);
  EXPECT_EQ(readPng(tmp.path() / "rgb.png"), rgb);
  EXPECT_EQ(rgb.data[0], 255) << "writePng changed the image it was given";
  Image label(3, 2, 1);
  label.data = {0, 1, 2, 13, 14, 255};
  writePng(tmp.path() / "label.png", label);
  EXPECT_EQ(readPng(tmp.path() / "label.png"), label);
}

TEST(ImageIo, SixteenBitPngIsAnError) {
  TempDir tmp;
  writeText(tmp.path() / "deep.png", bytesOf(kPngGray16));
  expectError([&] { readPng(tmp.path() / "deep.png"); },
              {(tmp.path() / "deep.png").string(), "16-bit"});
}

TEST(ImageIo, MissingPngIsAnError) {
  TempDir tmp;
  expectError([&] { readPng(tmp.path() / "none.png"); },
              {(tmp.path() / "none.png").string(), "cannot open"});
}

TEST(AtomicFile, FailedWriteLeavesTheOldContentAndNoTemporary) {
  TempDir tmp;
  const fs::path target = tmp.path() / "map.txt";
  writeBytesAtomically(target, "old content");
  EXPECT_THROW(writeFileAtomically(target,
                                   [](std::ostream& out) {
                                     out << "half of the new";
                                     throw std::runtime_error("interrupted");
                                   }),
               std::runtime_error);
  EXPECT_EQ(readFileBytes(target), "old content");
  EXPECT_EQ(std::distance(fs::directory_iterator(tmp.path()), fs::directory_iterator()), 1);
}

TEST(AtomicFile, SuccessfulWriteReplacesTheContent) {
  TempDir tmp;
  const fs::path target = tmp.path() / "map.txt";
  writeBytesAtomically(target, "old content");
  writeFileAtomically(target, [](std::ostream& out) { out << "new"; });
  EXPECT_EQ(readFileBytes(target), "new");
  EXPECT_TRUE(temporaryFilesUnder(tmp.path()).empty());
}

TEST(AtomicFile, UnwritableDirectoryNamesTheTarget) {
  TempDir tmp;
  const fs::path target = tmp.path() / "no_such_dir" / "map.txt";
  expectError([&] { writeBytesAtomically(target, "x"); }, {target.string()});
}

}  // namespace
}  // namespace semsegmap
