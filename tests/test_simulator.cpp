#include <gtest/gtest.h>

#include <algorithm>
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

// The presets render what their sensors see: a 360-degree HDL-64E sees behind the vehicle, a
// 70-degree solid-state LiDAR only ahead; without cameras and point classes a frame is what a
// LiDAR without a camera gives, with the instance ground truth kept for training.
TEST(Simulator, LidarPresetsAndALidarWithoutCamera) {
  SimConfig c = tinyConfig();
  c.render_cameras = false;
  c.point_classes = false;
  auto widest_azimuth = [&](const char* preset, size_t* points) {
    c.rig.lidar = lidarPreset(preset);
    Simulator sim(c);
    const Frame f = sim.frame(5);
    EXPECT_TRUE(f.cameras.empty());
    EXPECT_FALSE(sim.info().point_labels_have_classes);
    size_t instances = 0;
    for (const PointLabel& l : f.point_labels) {
      EXPECT_EQ(l.class_id, cls::kUnknown);
      instances += l.instance_id != 0;
    }
    EXPECT_GT(instances, f.points.size() / 2) << preset;
    double widest = 0;
    for (const LidarPoint& p : f.points)
      widest = std::max(widest, std::abs(std::atan2(p.y, p.x)) * 180.0 / M_PI);
    *points = f.points.size();
    return widest;
  };
  size_t hdl64 = 0, vlp32 = 0, solid = 0;
  EXPECT_GT(widest_azimuth("hdl64", &hdl64), 175.0);
  EXPECT_GT(widest_azimuth("vlp32", &vlp32), 175.0);
  EXPECT_LT(widest_azimuth("solid", &solid), 35.1);
  EXPECT_LT(vlp32, hdl64);  // half the beams
  EXPECT_GT(solid, 1000u);
  EXPECT_THROW(lidarPreset("hdl65"), std::invalid_argument);
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

namespace {

// Share of pixels that differ between two label images.
double changedShare(const Image& a, const Image& b) {
  size_t changed = 0;
  for (size_t i = 0; i < a.data.size(); ++i) changed += a.data[i] != b.data[i];
  return static_cast<double>(changed) / a.data.size();
}

Image twoClasses(ClassId left, ClassId right) {  // 640 x 480, split at x = 320
  Image img(640, 480, 1);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) *img.at(x, y) = static_cast<uint8_t>(x < 320 ? left : right);
  return img;
}

}  // namespace

TEST(LabelNoise, EachEffectChangesWhatItShould) {
  const Image wall = twoClasses(cls::kBuilding, cls::kBuilding);
  // Boundaries move by at most boundary_px, and only boundaries move.
  const Image split = twoClasses(cls::kBuilding, cls::kRoad);
  const Image shifted = applyLabelNoise(split, {8.0, 0, 0, 0}, 1);
  EXPECT_GT(changedShare(split, shifted), 0.002);
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x)
      if (*shifted.at(x, y) != *split.at(x, y)) {
        ASSERT_LE(std::abs(x - 320), 9) << x << "," << y;
      }
  EXPECT_EQ(applyLabelNoise(wall, {8.0, 0, 0, 0}, 1), wall);
  // Confusion and wrong regions take about their share of the picture (averaged over seeds:
  // the blobs are large, so one picture varies).
  double confused = 0, region = 0;
  for (uint64_t seed = 0; seed < 16; ++seed) {
    confused += changedShare(wall, applyLabelNoise(wall, {0, 0.25, 0, 0}, seed)) / 16;
    region += changedShare(wall, applyLabelNoise(wall, {0, 0, 0, 0.08}, seed)) / 16;
  }
  EXPECT_NEAR(confused, 0.25, 0.06);
  EXPECT_LT(region, 0.08 * 1.6);  // a third of the regions draw the wall's own class
  EXPECT_GT(region, 0.02);
  // Thin objects: all missed at share 1, each pixel then takes its background.
  Image pole = wall;
  for (int y = 100; y < 400; ++y)
    for (int x = 300; x < 306; ++x) *pole.at(x, y) = cls::kPole;
  EXPECT_EQ(applyLabelNoise(pole, {0, 0, 1.0, 0}, 3), wall);
  // Sky is never a wrong region, and unknown stays unknown.
  const Image sky = twoClasses(cls::kSky, cls::kUnknown);
  EXPECT_EQ(applyLabelNoise(sky, {0, 0, 0, 1.0}, 5), sky);
}

TEST(LabelNoise, LevelsAreDeterministicAndGrowWorse) {
  EXPECT_THROW(labelNoiseOfLevel(4), std::invalid_argument);
  Simulator perfect(tinyConfig());
  double previous = 0.0;
  for (int level = 0; level <= kMaxLabelNoiseLevel; ++level) {
    SimConfig c = tinyConfig();
    c.label_noise = level;
    Simulator noisy(c);
    double share = 0.0;
    for (size_t i : {0, 5}) {
      const Frame a = perfect.frame(i), b = noisy.frame(i);
      EXPECT_EQ(a.point_labels, b.point_labels);  // the LiDAR's ground truth stays exact
      for (size_t k = 0; k < a.cameras.size(); ++k)
        share += changedShare(a.cameras[k].label, b.cameras[k].label) / (2 * a.cameras.size());
    }
    std::printf("label noise %d: %.1f %% of the pixels changed\n", level, 100 * share);
    if (level == 0) {
      EXPECT_EQ(share, 0.0);
    } else if (level == 1) {
      EXPECT_GT(share, 0.01);
    } else if (level == 3) {
      EXPECT_LT(share, 0.35);
    }
    if (level > 0) {
      EXPECT_GT(share, previous * 1.3) << level;
    }
    previous = share;
    // Deterministic: the same frame twice, from another simulator of the same seeds.
    EXPECT_TRUE(sameFrame(noisy.frame(5), Simulator(c).frame(5)));
  }
}
