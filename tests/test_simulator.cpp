#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "semsegmap/io/dataset_reader.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/sim/camera_sim.h"
#include "semsegmap/sim/simulator.h"

using namespace semsegmap;
using namespace semsegmap::sim;

namespace {

SimConfig tinyConfig(Run run = Run::S2) {
  SimConfig c;
  c.world = worldPreset("tiny", 1);
  c.run = run;
  return c;
}

bool sameFrame(const Frame& a, const Frame& b) {
  if (a.points.size() != b.points.size() || a.cameras.size() != b.cameras.size()) return false;
  if (std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(LidarPoint)) != 0)
    return false;
  if (a.point_labels != b.point_labels) return false;
  for (size_t c = 0; c < a.cameras.size(); ++c)
    if (!(a.cameras[c].rgb == b.cameras[c].rgb) || !(a.cameras[c].label == b.cameras[c].label))
      return false;
  return true;
}

std::filesystem::path tempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("semsegmap_test_" + name + "_" +
                    std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
  std::filesystem::remove_all(dir);
  return dir;
}

}  // namespace

TEST(Simulator, SameSeedsGiveByteIdenticalFrames) {
  Simulator a(tinyConfig()), b(tinyConfig());
  EXPECT_TRUE(sameFrame(a.frame(7), b.frame(7)));
  SimConfig other = tinyConfig();
  other.traffic_seed = 99;
  Simulator c(other);
  EXPECT_FALSE(sameFrame(a.frame(7), c.frame(7)));
}

TEST(Simulator, IsAStreamingFrameSourceWithGroundTruth) {
  Simulator sim(tinyConfig());
  FrameSource& source = sim;
  ASSERT_GT(source.size(), 100u);
  const Frame f = source.frame(3);
  EXPECT_EQ(f.index, 3u);
  EXPECT_NEAR(f.timestamp_s, 0.6, 1e-9);
  ASSERT_TRUE(f.T_world_base.has_value());
  EXPECT_EQ(f.points.size(), f.point_labels.size());
  EXPECT_GT(f.points.size(), 50000u);
  ASSERT_EQ(f.cameras.size(), 3u);
  for (const auto& cam : f.cameras) {
    EXPECT_EQ(cam.rgb.width, 640);
    EXPECT_EQ(cam.rgb.height, 480);
    EXPECT_EQ(cam.label.channels, 1);
  }
  EXPECT_TRUE(source.info().has_point_labels);
  EXPECT_THROW(source.frame(source.size()), std::out_of_range);
}

TEST(Simulator, LidarAndCameraAgreeOnClasses) {
  // The label pixel a LiDAR point projects into carries the point's class, for points that the
  // camera sees (its depth at that pixel matches the point's; parallax hides the others).
  Simulator sim(tinyConfig());
  const SensorRig& rig = sim.info().rig;
  size_t visible = 0, agree = 0;
  for (size_t index : {5, 60, 120}) {
    const Frame f = sim.frame(index);
    const Pose T_world_lidar = *f.T_world_base * rig.T_base_lidar;
    for (const auto& cam : rig.cameras) {
      const CameraRender r = renderCamera(
          sim.scene(), cam, T_world_lidar * cam.T_camera_lidar.inverse(), sim.lighting(), 1, true);
      for (size_t k = 0; k < f.points.size(); ++k) {
        const Eigen::Vector3d p_cam =
            cam.T_camera_lidar * Eigen::Vector3d(f.points[k].x, f.points[k].y, f.points[k].z);
        const auto uv = cam.project(p_cam);
        if (!uv || !cam.inImage(*uv)) continue;
        const int u = static_cast<int>(uv->x()), v = static_cast<int>(uv->y());
        const float depth = r.depth[static_cast<size_t>(v) * cam.width + u];
        if (std::abs(depth - p_cam.z()) > 0.1 + 0.03 * p_cam.z()) continue;
        ++visible;
        agree += *r.label.at(u, v) == f.point_labels[k].class_id;
      }
    }
  }
  ASSERT_GT(visible, 50000u);
  EXPECT_GE(static_cast<double>(agree) / visible, 0.95) << agree << " of " << visible;
}

TEST(Simulator, ConditionsAndRunsFollowThePaper) {
  EXPECT_EQ(Simulator(tinyConfig(Run::S3)).lighting().name, "sunrise");
  EXPECT_EQ(Simulator(tinyConfig(Run::S2)).lighting().name, "sunny");
  SimConfig c = tinyConfig(Run::S2);
  c.condition = "sunrise";
  EXPECT_EQ(Simulator(c).lighting().name, "sunrise");
  c.condition = "night";
  EXPECT_THROW(Simulator{c}, std::invalid_argument);
  // Runs see different parked cars unless told otherwise.
  EXPECT_NE(Simulator(tinyConfig(Run::S2)).trafficSeed(),
            Simulator(tinyConfig(Run::S3)).trafficSeed());
}

TEST(Simulator, DatasetWriteReadRoundTrip) {
  SimConfig c = tinyConfig();
  c.max_frames = 2;
  Simulator sim(c);
  const auto dir = tempDir("roundtrip");
  {
    DatasetWriter writer(dir, sim.info());
    for (size_t i = 0; i < sim.size(); ++i) writer.write(sim.frame(i));
  }
  DatasetReader reader(dir);
  ASSERT_EQ(reader.size(), 2u);
  EXPECT_EQ(reader.info().rig.cameras.size(), 3u);
  EXPECT_TRUE(reader.info().classes == sim.info().classes);
  for (size_t i = 0; i < 2; ++i) {
    const Frame a = sim.frame(i), b = reader.frame(i);
    EXPECT_TRUE(sameFrame(a, b)) << "frame " << i;
    EXPECT_NEAR(a.timestamp_s, b.timestamp_s, 1e-12);
    ASSERT_TRUE(b.T_world_base.has_value());
    EXPECT_LT(translationError(*a.T_world_base, *b.T_world_base), 1e-9);
    EXPECT_LT(translationError(a.T_odom_base, b.T_odom_base), 1e-9);
  }
  // A truncated LiDAR file is reported with its name.
  const auto lidar = dir / "lidar" / "000001.bin";
  std::filesystem::resize_file(lidar, std::filesystem::file_size(lidar) - 6);
  try {
    reader.frame(1);
    FAIL() << "expected an error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("000001.bin"), std::string::npos) << e.what();
  }
  std::filesystem::remove_all(dir);
}
