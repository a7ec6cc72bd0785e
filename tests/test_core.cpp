#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/binary_io.h"
#include "semsegmap/core/class_table.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/core/json.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/core/random.h"
#include "semsegmap/core/sensor_rig.h"
#include "semsegmap/core/shown_text.h"
#include "temp_dir.h"

using namespace semsegmap;

TEST(ClassTable, DefaultHasThePaperClassesWithTheirFlags) {
  const ClassTable t = ClassTable::Default();
  for (const char* name : {"road", "sidewalk", "terrain", "building", "roof", "fence", "vegetation",
                           "trunk", "pole", "traffic-sign", "car", "person", "other", "unknown"})
    EXPECT_TRUE(t.find(name).has_value()) << name;
  EXPECT_TRUE(t.at(*t.find("car")).dynamic);
  EXPECT_TRUE(t.at(*t.find("person")).dynamic);
  EXPECT_FALSE(t.at(*t.find("building")).dynamic);
  for (const char* g : {"road", "sidewalk", "terrain"}) EXPECT_TRUE(t.at(*t.find(g)).ground) << g;
  EXPECT_FALSE(t.at(*t.find("vegetation")).ground);
  EXPECT_THROW(t.at(999), std::out_of_range);
}

TEST(ClassTable, RejectsDuplicateIds) {
  EXPECT_THROW(ClassTable({{1, "a", {0, 0, 0}, false, false}, {1, "b", {0, 0, 0}, false, false}}),
               std::invalid_argument);
}

// The one layout of every JSON file: keys in the order they were set, a 2-space indent, a final
// newline; quotes and backslashes escaped, so that what is written reads back unchanged.
// The CLI's sink ends its progress line before a note; without a sink the line goes to stderr.
TEST(Diagnostics, NotesAndWarningsGoToTheInstalledSinkAsWholeLines) {
  std::vector<std::string> lines;
  setMessageSink([&](const std::string& line) { lines.push_back(line); });
  note("a rig read from defaults");
  warn("a map built with other settings");
  setMessageSink({});
  testing::internal::CaptureStderr();
  note("after the sink");
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "note: after the sink\n");
  EXPECT_EQ(lines, (std::vector<std::string>{"note: a rig read from defaults",
                                             "warning: a map built with other settings"}));
}

TEST(ShownText, NumbersReadAsAStreamPrintsThem) {
  EXPECT_EQ(shownNumber(10.0), "10");
  EXPECT_EQ(shownNumber(0.1), "0.1");
  EXPECT_EQ(shownNumber(1e308), "1e+308");
}

TEST(Json, WritesOrderedIndentedEscapedText) {
  nlohmann::ordered_json j;
  j["name"] = "a \"quoted\" C:\\path";
  j["count"] = 3;
  j["values"] = {0.1, 2.5};
  EXPECT_EQ(jsonText(j),
            "{\n  \"name\": \"a \\\"quoted\\\" C:\\\\path\",\n  \"count\": 3,\n"
            "  \"values\": [\n    0.1,\n    2.5\n  ]\n}\n");
  test_support::TempDir tmp;
  writeJsonAtomically(tmp.path() / "j.json", j);
  EXPECT_EQ(nlohmann::ordered_json::parse(readFileBytes(tmp.path() / "j.json")), j);
}

TEST(Pose, XyzQuatRoundTrip) {
  Pose T = planarPose(1.0, -2.0, 0.5, 0.7);
  T.linear() = T.linear() * Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Pose back = fromXyzQuat(toXyzQuat(T));
  EXPECT_LT(translationError(T, back), 1e-12);
  EXPECT_LT(rotationErrorDeg(T, back), 1e-6);
}

TEST(Pose, YawAndErrors) {
  EXPECT_NEAR(yawOf(planarPose(0, 0, 0, 1.25)), 1.25, 1e-12);
  EXPECT_NEAR(rotationErrorDeg(planarPose(0, 0, 0, 0), planarPose(0, 0, 0, M_PI / 2)), 90.0, 1e-9);
  EXPECT_NEAR(translationError(planarPose(0, 0, 0, 0), planarPose(3, 4, 0, 1)), 5.0, 1e-12);
}

TEST(Random, CounterBasedIsAPureFunction) {
  EXPECT_EQ(hashKeys(1, 2, 3), hashKeys(1, 2, 3));
  EXPECT_NE(hashKeys(1, 2, 3), hashKeys(1, 3, 2));
  double sum = 0, sum2 = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const double g = gaussianFromHash(hashKeys(7, k));
    sum += g;
    sum2 += g * g;
  }
  EXPECT_NEAR(sum / n, 0.0, 0.03);
  EXPECT_NEAR(sum2 / n, 1.0, 0.05);
  SeededRng a(5), b(5);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(a.next(), b.next());
  std::set<int> seen;
  SeededRng c(9);
  for (int k = 0; k < 1000; ++k) {
    const int v = c.integer(2, 4);
    ASSERT_GE(v, 2);
    ASSERT_LE(v, 4);
    seen.insert(v);
  }
  EXPECT_EQ(seen.size(), 3u);
}

TEST(SensorRig, DefaultRigLooksLeftFrontRight) {
  const SensorRig rig = defaultSimRig();
  ASSERT_EQ(rig.cameras.size(), 3u);
  EXPECT_NO_THROW(rig.validate());
  // A point straight ahead of the LiDAR lands near the centre of the front camera...
  const auto& front = rig.cameras[1];
  const auto uv = front.project(front.T_camera_lidar * Eigen::Vector3d(20.0, 0.0, -0.25));
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 320.0, 1.0);
  EXPECT_NEAR(uv->y(), 240.0, 1.0);
  // ...and behind the left camera's image plane for a point on the right.
  const auto& left = rig.cameras[0];
  EXPECT_FALSE(left.project(left.T_camera_lidar * Eigen::Vector3d(0.0, -10.0, 0.0)).has_value());
  // Each camera sees 90 degrees: the image edge of the front camera is at 45 degrees.
  const auto edge = front.project(front.T_camera_lidar * Eigen::Vector3d(20.0, 20.0 - 0.0, -0.25));
  ASSERT_TRUE(edge.has_value());
  EXPECT_NEAR(edge->x(), 0.0, 8.0);
}

TEST(SensorRig, PixelRayInvertsProjection) {
  const Camera cam = defaultSimRig().cameras[1];
  const Eigen::Vector3d ray = cam.pixelRay(100.5, 400.25);
  const auto uv = cam.project(ray * 7.0);
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 100.5, 1e-9);
  EXPECT_NEAR(uv->y(), 400.25, 1e-9);
}

TEST(SensorRig, LidarBeamsSpanTheFieldOfView) {
  const LidarModel l;
  const Eigen::Vector3d first = l.beamDirection(0, 0),
                        last = l.beamDirection(l.rows - 1, l.columns - 1);
  EXPECT_NEAR(std::atan2(first.y(), first.x()) * 180 / M_PI, 135.0, 0.1);
  EXPECT_NEAR(std::atan2(last.y(), last.x()) * 180 / M_PI, -135.0, 0.1);
  EXPECT_NEAR(std::asin(first.z()) * 180 / M_PI, l.vfov_up_deg, 1e-9);
  EXPECT_NEAR(std::asin(last.z()) * 180 / M_PI, l.vfov_down_deg, 1e-9);
}

// One HDL-64E: the simulator's preset renders the beams real KITTI scans are read with, at 2048
// of the real 2083 columns (its ray budget) and with the simulator's range defaults.
TEST(SensorRig, TheHdl64PresetHasTheRealSensorsBeams) {
  const LidarModel real = velodyneHdl64e(), preset = lidarPreset("hdl64");
  EXPECT_EQ(real.columns, 2083);
  EXPECT_EQ(preset.columns, 2048);
  EXPECT_EQ(preset.rows, real.rows);
  EXPECT_EQ(preset.hfov_deg, real.hfov_deg);
  EXPECT_EQ(preset.vfov_up_deg, real.vfov_up_deg);
  EXPECT_EQ(preset.vfov_down_deg, real.vfov_down_deg);
  EXPECT_EQ(preset.max_range_m, LidarModel{}.max_range_m);
  EXPECT_EQ(real.dropout, 0.0) << "real scans carry their own dropouts";
}

TEST(SensorRig, ValidateNamesTheBadField) {
  SensorRig rig = defaultSimRig();
  rig.cameras[2].fx = -1.0;
  try {
    rig.validate();
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("right"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
  rig = defaultSimRig();
  rig.cameras[0].T_camera_lidar.linear() *= 2.0;
  EXPECT_THROW(rig.validate(), std::invalid_argument);
}

// issue 18: a 40000 x 40000 camera read from a file passed (only > 0 was checked) and made the
// enricher allocate 6+ GB inside an OpenMP loop, which aborts. Sizes, counts and poses have
// limits, each named.
TEST(SensorRig, ValidateRefusesHugeSizesAndNonFinitePoses) {
  const auto messageOf = [](const SensorRig& rig) {
    try {
      rig.validate();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  SensorRig rig = defaultSimRig();
  rig.cameras[1].width = rig.cameras[1].height = 40000;
  rig.cameras[1].cx = rig.cameras[1].cy = 20000;
  EXPECT_NE(messageOf(rig).find("width and height must be in 1..16384, got 40000 x 40000"),
            std::string::npos)
      << messageOf(rig);
  rig = defaultSimRig();
  rig.cameras.resize(kMaxCameras + 1, rig.cameras[0]);
  EXPECT_NE(messageOf(rig).find("65 cameras, at most 64"), std::string::npos) << messageOf(rig);
  rig = defaultSimRig();
  rig.lidar.columns = 1 << 30;
  EXPECT_NE(messageOf(rig).find("lidar.columns"), std::string::npos) << messageOf(rig);
  rig = defaultSimRig();
  rig.T_base_lidar.translation().x() = std::numeric_limits<double>::infinity();
  EXPECT_NE(messageOf(rig).find("T_base_lidar"), std::string::npos) << messageOf(rig);
  rig = defaultSimRig();
  rig.cameras[0].T_camera_lidar.translation().y() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(messageOf(rig).find("T_camera_lidar has a NaN"), std::string::npos) << messageOf(rig);
  rig = defaultSimRig();
  rig.rate_hz = std::numeric_limits<double>::infinity();
  EXPECT_NE(messageOf(rig).find("rate_hz"), std::string::npos) << messageOf(rig);
  EXPECT_EQ(messageOf(defaultSimRig()), "(no error)");
}

// ---- The binary reader and writer of every file format ------------------------------------------

namespace {
std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no error)";
}
}  // namespace

TEST(BinaryIo, RoundTripOfValuesStringsAndArrays) {
  BinaryWriter w;
  w.putBytes("MAGIC", 5);
  w.put<uint32_t>(7);
  w.putString8("short");
  w.putString32(std::string(300, 'x'));
  w.putArray(std::vector<float>{1.5f, -2.0f});
  w.putChecksum();
  const std::string bytes = w.take();
  BinaryReader r("f.bin", bytes, "test file");
  r.expectMagic("MAGIC");
  r.checksummed();
  EXPECT_EQ(r.get<uint32_t>("a"), 7u);
  EXPECT_EQ(r.getString8("b"), "short");
  EXPECT_EQ(r.getString32("c"), std::string(300, 'x'));
  EXPECT_EQ(r.getArray<float>(2, "d"), (std::vector<float>{1.5f, -2.0f}));
  EXPECT_NO_THROW(r.expectEnd("d"));
  EXPECT_THROW(BinaryWriter().putString8(std::string(256, 'x')), std::invalid_argument);
}

TEST(BinaryIo, ErrorsNameTheFileAndTheField) {
  BinaryWriter w;
  w.put<uint64_t>(1000000);  // a count far beyond the rest of the file
  w.put<uint16_t>(3);
  const std::string bytes = w.take();
  {
    BinaryReader r("/x/m.map", bytes, "map file");
    const std::string e = errorOf([&] { r.getCount(4, "the segments"); });
    EXPECT_NE(e.find("/x/m.map: corrupt map file (the segments"), std::string::npos) << e;
  }
  {
    BinaryReader r("/x/m.map", bytes, "map file");
    r.get<uint64_t>("the header");
    const std::string e = errorOf([&] { r.get<uint32_t>("a descriptor"); });
    EXPECT_EQ(e, "/x/m.map: truncated map file (ends inside a descriptor)");
    EXPECT_EQ(r.position(), 8u);  // a failed read consumes nothing
  }
  {
    BinaryReader r("/x/m.map", bytes, "map file");
    EXPECT_NE(errorOf([&] { r.expectMagic("SSMMAP"); }).find("bad magic"), std::string::npos);
  }
  {
    std::string corrupt = bytes + std::string(8, '\0');
    BinaryReader r("/x/m.map", corrupt, "map file");
    EXPECT_NE(errorOf([&] { r.checksummed(); }).find("checksum mismatch"), std::string::npos);
  }
  {
    BinaryReader r("/x/m.map", bytes, "map file");
    r.get<uint64_t>("the header");
    EXPECT_NE(errorOf([&] { r.expectEnd("the header"); }).find("trailing bytes"),
              std::string::npos);
  }
}

TEST(BinaryIo, Fnv1aIsTheStandardHash) {
  EXPECT_EQ(fnv1a64("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
  // Chained: the hash of two parts equals the hash of their concatenation.
  EXPECT_EQ(fnv1a64("b", 1, fnv1a64("a", 1)), fnv1a64("ab", 2));
}
