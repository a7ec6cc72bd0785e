// Semantic enrichment: HSV conversion, projection onto hand-made images with known answers,
// camera choice, the z-buffer occlusion test, input checks, the real KITTI sample against the
// devkit formula, and the simulator end to end against its ground-truth point labels.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

#include "build_options.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/enrich/enricher.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/kitti_raw_reader.h"
#include "semsegmap/io/ply_writer.h"

namespace semsegmap {
namespace {

// ---------------------------------------------------------------------------------------------
// Fixtures

// A 40 x 30 camera with a 90-degree horizontal field of view, looking along the LiDAR's
// direction `yaw_deg` (LiDAR x forward, y left, z up; camera x right, y down, z forward).
Camera makeCamera(const std::string& name, double yaw_deg = 0.0,
                  const Eigen::Vector3d& offset_in_lidar = Eigen::Vector3d::Zero()) {
  Camera cam;
  cam.name = name;
  cam.width = 40;
  cam.height = 30;
  cam.fx = cam.fy = 20.0;
  cam.cx = 20.0;
  cam.cy = 15.0;
  const double y = yaw_deg * M_PI / 180.0;
  Pose T_lidar_camera = Pose::Identity();
  T_lidar_camera.linear().col(0) = Eigen::Vector3d(std::sin(y), -std::cos(y), 0.0);
  T_lidar_camera.linear().col(1) = Eigen::Vector3d(0.0, 0.0, -1.0);
  T_lidar_camera.linear().col(2) = Eigen::Vector3d(std::cos(y), std::sin(y), 0.0);
  T_lidar_camera.translation() = offset_in_lidar;
  cam.T_camera_lidar = T_lidar_camera.inverse();
  return cam;
}

// Every pixel a different colour and a label that changes from pixel to pixel, so that a point
// landing one pixel off would get visibly different values.
CameraFrame patternImages(const Camera& cam) {
  CameraFrame cf{Image(cam.width, cam.height, 3), Image(cam.width, cam.height, 1), std::nullopt};
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      uint8_t* p = cf.rgb.at(x, y);
      p[0] = static_cast<uint8_t>(6 * x);
      p[1] = static_cast<uint8_t>(8 * y);
      p[2] = static_cast<uint8_t>(50 + x + y);
      *cf.label.at(x, y) = static_cast<uint8_t>(1 + (x + 3 * y) % 14);
    }
  return cf;
}

CameraFrame uniformImages(const Camera& cam, uint8_t r, uint8_t g, uint8_t b, ClassId label) {
  CameraFrame cf{Image(cam.width, cam.height, 3), Image(cam.width, cam.height, 1), std::nullopt};
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      uint8_t* p = cf.rgb.at(x, y);
      p[0] = r;
      p[1] = g;
      p[2] = b;
      *cf.label.at(x, y) = static_cast<uint8_t>(label);
    }
  return cf;
}

// The LiDAR point that `cam` sees at continuous pixel (u, v), `depth` metres in front of it.
LidarPoint pointAtPixel(const Camera& cam, double u, double v, double depth) {
  const Eigen::Vector3d p_cam((u - cam.cx) / cam.fx * depth, (v - cam.cy) / cam.fy * depth, depth);
  const Eigen::Vector3d p = cam.T_camera_lidar.inverse() * p_cam;
  return LidarPoint{static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()),
                    0.0f};
}

LidarPoint pointAtYaw(double yaw_deg, double range_m) {
  const double y = yaw_deg * M_PI / 180.0;
  return LidarPoint{static_cast<float>(range_m * std::cos(y)),
                    static_cast<float>(range_m * std::sin(y)), 0.0f, 0.0f};
}

void expectColourOf(const EnrichedPoint& p, const Image& rgb, int x, int y) {
  float h, s, v;
  const uint8_t* px = rgb.at(x, y);
  rgbToHsv(px[0], px[1], px[2], h, s, v);
  ASSERT_TRUE(p.has_color);
  EXPECT_FLOAT_EQ(p.h, h);
  EXPECT_FLOAT_EQ(p.s, s);
  EXPECT_FLOAT_EQ(p.v, v);
}

// Unobserved: no colour and no class, which is not the class unknown.
void expectNothing(const EnrichedPoint& p) {
  EXPECT_FALSE(p.has_color);
  EXPECT_FALSE(p.has_class);
  EXPECT_EQ(p.class_id, cls::kUnknown);
  EXPECT_EQ(p.h, 0.0f);
  EXPECT_EQ(p.s, 0.0f);
  EXPECT_EQ(p.v, 0.0f);
}

std::string errorOf(const Frame& f, const SensorRig& rig) {
  try {
    enrichFrame(f, rig, EnrichmentConfig{});
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

// ---------------------------------------------------------------------------------------------
// HSV

TEST(RgbToHsv, PrimariesGreyAndBlack) {
  float h, s, v;
  rgbToHsv(255, 0, 0, h, s, v);
  EXPECT_FLOAT_EQ(h, 0.0f);
  EXPECT_FLOAT_EQ(s, 1.0f);
  EXPECT_FLOAT_EQ(v, 1.0f);
  rgbToHsv(0, 255, 0, h, s, v);
  EXPECT_FLOAT_EQ(h, 1.0f / 3.0f);
  EXPECT_FLOAT_EQ(s, 1.0f);
  rgbToHsv(0, 0, 255, h, s, v);
  EXPECT_FLOAT_EQ(h, 2.0f / 3.0f);
  rgbToHsv(255, 255, 0, h, s, v);
  EXPECT_FLOAT_EQ(h, 1.0f / 6.0f);
  rgbToHsv(0, 0, 128, h, s, v);
  EXPECT_FLOAT_EQ(v, 128.0f / 255.0f);
  EXPECT_FLOAT_EQ(s, 1.0f);
  rgbToHsv(128, 128, 128, h, s, v);
  EXPECT_FLOAT_EQ(h, 0.0f);
  EXPECT_FLOAT_EQ(s, 0.0f);
  EXPECT_FLOAT_EQ(v, 128.0f / 255.0f);
  rgbToHsv(0, 0, 0, h, s, v);
  EXPECT_EQ(h, 0.0f);
  EXPECT_EQ(s, 0.0f);
  EXPECT_EQ(v, 0.0f);
  rgbToHsv(200, 100, 50, h, s, v);  // hue 20 degrees, s = 150 / 200
  EXPECT_NEAR(h, 20.0f / 360.0f, 1e-6);
  EXPECT_FLOAT_EQ(s, 0.75f);
}

TEST(RgbToHsv, HueWrapsJustBelowOne) {
  float h, s, v;
  rgbToHsv(255, 0, 1, h, s, v);  // a hair past magenta towards red
  EXPECT_LT(h, 1.0f);
  EXPECT_NEAR(h, 1.0f - 1.0f / (6.0f * 255.0f), 1e-6);
  rgbToHsv(255, 1, 0, h, s, v);  // a hair past red towards yellow
  EXPECT_GT(h, 0.0f);
  EXPECT_NEAR(h, 1.0f / (6.0f * 255.0f), 1e-6);
  // Over a grid of colours hue always stays in [0, 1).
  for (int r = 0; r < 256; r += 15)
    for (int g = 0; g < 256; g += 15)
      for (int b = 0; b < 256; b += 15) {
        rgbToHsv(r, g, b, h, s, v);
        ASSERT_GE(h, 0.0f);
        ASSERT_LT(h, 1.0f);
      }
}

TEST(HsvToRgb, RoundTripsEvery8BitColourOnAGrid) {
  for (int r = 0; r < 256; r += 3)
    for (int g = 0; g < 256; g += 5)
      for (int b = 0; b < 256; b += 7) {
        float h, s, v;
        rgbToHsv(r, g, b, h, s, v);
        uint8_t r2, g2, b2;
        hsvToRgb(h, s, v, r2, g2, b2);
        ASSERT_EQ(r2, r) << r << " " << g << " " << b;
        ASSERT_EQ(g2, g) << r << " " << g << " " << b;
        ASSERT_EQ(b2, b) << r << " " << g << " " << b;
      }
}

// ---------------------------------------------------------------------------------------------
// Projection on hand-made images

TEST(Enrich, PointTakesExactlyThePixelItProjectsInto) {
  // Parallax between camera and LiDAR, so that a forgotten extrinsic lands on another pixel.
  SensorRig rig;
  rig.cameras = {makeCamera("cam", 0.0, Eigen::Vector3d(0.3, 0.1, -0.2))};
  Frame f;
  f.cameras = {patternImages(rig.cameras[0])};
  f.points = {pointAtPixel(rig.cameras[0], 12.5, 7.5, 5.0),
              pointAtPixel(rig.cameras[0], 0.2, 29.9, 8.0),    // corner pixel (0, 29)
              pointAtPixel(rig.cameras[0], 39.5, 0.5, 20.0)};  // corner pixel (39, 0)
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_FLOAT_EQ(cloud[0].x, f.points[0].x);
  EXPECT_FLOAT_EQ(cloud[0].y, f.points[0].y);
  EXPECT_FLOAT_EQ(cloud[0].z, f.points[0].z);
  expectColourOf(cloud[0], f.cameras[0].rgb, 12, 7);
  EXPECT_EQ(cloud[0].class_id, *f.cameras[0].label.at(12, 7));
  expectColourOf(cloud[1], f.cameras[0].rgb, 0, 29);
  EXPECT_EQ(cloud[1].class_id, *f.cameras[0].label.at(0, 29));
  expectColourOf(cloud[2], f.cameras[0].rgb, 39, 0);
  EXPECT_EQ(cloud[2].class_id, *f.cameras[0].label.at(39, 0));
}

// issue 18: a camera of 40000 x 40000 pixels made the z-buffers (12 GB) be allocated inside an
// OpenMP loop, where a failed allocation aborts the process. The size is refused first, and the
// buffers are allocated before the loop, where an allocation error is an exception.
TEST(Enrich, HugeCameraIsRefusedBeforeItsZBufferIsAllocated) {
  SensorRig rig;
  rig.cameras = {makeCamera("huge")};
  rig.cameras[0].width = rig.cameras[0].height = 40000;
  Frame f;
  f.cameras.resize(1);  // no images: the camera's z-buffer is still made
  f.points = {LidarPoint{5, 0, 0, 1}};
  try {
    enrichFrame(f, rig, EnrichmentConfig{});
    ADD_FAILURE() << "a 40000 x 40000 camera was enriched";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("camera 'huge': size 40000x40000 is outside 1..16384"),
              std::string::npos)
        << e.what();
  }
  rig.cameras[0].width = rig.cameras[0].height = 2048;  // a large real camera still works
  EXPECT_EQ(enrichFrame(f, rig, EnrichmentConfig{}).size(), 1u);
}

TEST(Enrich, PointsBehindOrOutsideAreUnobserved) {
  SensorRig rig;
  rig.cameras = {makeCamera("cam")};
  Frame f;
  f.cameras = {patternImages(rig.cameras[0])};
  f.points = {pointAtYaw(180.0, 10.0),                          // behind the camera
              pointAtPixel(rig.cameras[0], 40.5, 10.0, 10.0),   // right of the image
              pointAtPixel(rig.cameras[0], 10.0, -0.5, 10.0),   // above the image
              LidarPoint{0.0f, 0.0f, 0.0f, 0.0f},               // at the camera centre
              pointAtPixel(rig.cameras[0], 20.0, 15.0, 10.0)};  // control: in view
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(i);
    expectNothing(cloud[i]);
  }
  EXPECT_TRUE(cloud[4].has_color);
  EXPECT_TRUE(cloud[4].has_class);
  EXPECT_NE(cloud[4].class_id, cls::kUnknown);
  // A pixel the network called unknown gives the class unknown: observed, not unobserved.
  f.cameras = {uniformImages(rig.cameras[0], 10, 20, 30, cls::kUnknown)};
  const EnrichedCloud unknown = enrichFrame(f, rig, EnrichmentConfig{});
  EXPECT_TRUE(unknown[4].has_class);
  EXPECT_EQ(unknown[4].class_id, cls::kUnknown);
  expectNothing(unknown[0]);
}

TEST(Enrich, PointSeenByTwoCamerasTakesTheNearerImageCentre) {
  SensorRig rig;
  rig.cameras = {makeCamera("left", 25.0), makeCamera("right", -25.0)};
  Frame f;
  f.cameras = {uniformImages(rig.cameras[0], 255, 0, 0, cls::kBuilding),
               uniformImages(rig.cameras[1], 0, 0, 255, cls::kCar)};
  f.points = {pointAtYaw(10.0, 10.0),    // 15 deg from left's axis, 35 from right's: both see it
              pointAtYaw(-5.0, 10.0),    // 30 from left's, 20 from right's
              pointAtYaw(60.0, 10.0),    // left only
              pointAtYaw(-60.0, 10.0)};  // right only
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  auto fromLeft = [](const EnrichedPoint& p) {
    return p.has_color && p.h == 0.0f && p.class_id == cls::kBuilding;
  };
  auto fromRight = [](const EnrichedPoint& p) {
    return p.has_color && p.h == 2.0f / 3.0f && p.class_id == cls::kCar;
  };
  // Both cameras really do see the first two points (90-degree fields of view 50 degrees apart).
  for (int c = 0; c < 2; ++c)
    for (int i = 0; i < 2; ++i) {
      const Camera& cam = rig.cameras[c];
      const auto uv = cam.project(cam.T_camera_lidar *
                                  Eigen::Vector3d(f.points[i].x, f.points[i].y, f.points[i].z));
      ASSERT_TRUE(uv && cam.inImage(*uv)) << cam.name << " point " << i;
    }
  EXPECT_TRUE(fromLeft(cloud[0]));
  EXPECT_TRUE(fromRight(cloud[1]));
  EXPECT_TRUE(fromLeft(cloud[2]));
  EXPECT_TRUE(fromRight(cloud[3]));
}

TEST(Enrich, ZBufferRejectsAFarPointBehindANearOne) {
  // The camera sits a metre to the left of the LiDAR: the parallax lets the LiDAR see far points
  // that the near ones hide from the camera.
  SensorRig rig;
  rig.cameras = {makeCamera("cam", 0.0, Eigen::Vector3d(0.0, 1.0, 0.0))};
  const Camera& cam = rig.cameras[0];
  Frame f;
  f.cameras = {patternImages(cam)};
  f.points = {
      pointAtPixel(cam, 10.5, 10.5, 5.0),   // 0: near
      pointAtPixel(cam, 10.5, 10.5, 12.0),  // 1: far, same pixel: hidden
      pointAtPixel(cam, 12.5, 12.5, 12.0),  // 2: far, 2 px away diagonally: still hidden
      pointAtPixel(cam, 14.5, 10.5, 12.0),  // 3: far, 4 px away: outside the radius, visible
      pointAtPixel(cam, 10.5, 11.5, 5.1),   // 4: just behind the near one, within tolerance
      pointAtPixel(cam, 30.5, 20.5, 12.0),  // 5: far, nothing in front: visible
  };
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  expectColourOf(cloud[0], f.cameras[0].rgb, 10, 10);
  EXPECT_EQ(cloud[0].class_id, *f.cameras[0].label.at(10, 10));
  expectNothing(cloud[1]);
  expectNothing(cloud[2]);
  expectColourOf(cloud[3], f.cameras[0].rgb, 14, 10);
  expectColourOf(cloud[4], f.cameras[0].rgb, 10, 11);
  expectColourOf(cloud[5], f.cameras[0].rgb, 30, 20);

  // A radius of 0 only compares with the very same pixel.
  EnrichmentConfig same_pixel;
  same_pixel.occlusion_radius_px = 0;
  const EnrichedCloud cloud0 = enrichFrame(f, rig, same_pixel);
  expectNothing(cloud0[1]);
  expectColourOf(cloud0[2], f.cameras[0].rgb, 12, 12);
}

TEST(Enrich, SurfaceAtAGrazingAngleDoesNotHideItself) {
  // A flat road seen by the simulated rig's front camera: far away, neighbouring LiDAR rings land
  // a pixel or two apart but metres apart in depth. The camera sees the road as the LiDAR does
  // (their parallax is a fraction of a pixel there), so every ring must keep its colour.
  const SensorRig sim = defaultSimRig();
  SensorRig rig;
  rig.cameras = {sim.cameras[1]};
  ASSERT_EQ(rig.cameras[0].name, "front");
  Frame f;
  f.cameras = {uniformImages(rig.cameras[0], 90, 90, 90, cls::kRoad)};
  const double lidar_height_m = sim.T_base_lidar.translation().z();
  for (int row = 0; row < sim.lidar.rows; ++row)
    for (int col = 0; col < sim.lidar.columns; ++col) {
      const Eigen::Vector3d d = sim.lidar.beamDirection(row, col);
      if (d.z() > -1e-3) continue;  // never reaches the road
      const Eigen::Vector3d p = d * (lidar_height_m / -d.z());
      if (p.head<2>().norm() < 60.0 && p.x() > 1.0)
        f.points.push_back(LidarPoint{static_cast<float>(p.x()), static_cast<float>(p.y()),
                                      static_cast<float>(p.z()), 0.0f});
    }
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  size_t in_image = 0, coloured = 0;
  for (size_t i = 0; i < cloud.size(); ++i) {
    const Camera& cam = rig.cameras[0];
    const auto uv = cam.project(cam.T_camera_lidar *
                                Eigen::Vector3d(f.points[i].x, f.points[i].y, f.points[i].z));
    if (!uv || !cam.inImage(*uv)) continue;
    ++in_image;
    coloured += cloud[i].has_color;
  }
  EXPECT_GT(in_image, 10000u);
  EXPECT_EQ(coloured, in_image);
}

TEST(Enrich, PointHiddenFromOneCameraTakesTheOther) {
  // The LiDAR sees the far point past a post that hides it from the left camera only, which
  // sits a metre to the left of the LiDAR.
  SensorRig rig;
  rig.cameras = {makeCamera("left", 25.0, Eigen::Vector3d(0.0, 1.0, 0.0)),
                 makeCamera("right", -25.0)};
  Frame f;
  f.cameras = {uniformImages(rig.cameras[0], 255, 0, 0, cls::kBuilding),
               uniformImages(rig.cameras[1], 0, 0, 255, cls::kCar)};
  const LidarPoint far_point = pointAtYaw(10.0, 20.0);  // nearer the left camera's centre
  // A post on the left camera's line of sight to the far point, out of the right camera's view.
  const Eigen::Vector3d seen =
      rig.cameras[0].T_camera_lidar * Eigen::Vector3d(far_point.x, far_point.y, far_point.z);
  const Eigen::Vector3d post = rig.cameras[0].T_camera_lidar.inverse() * (seen * 0.2);
  f.points = {far_point, LidarPoint{static_cast<float>(post.x()), static_cast<float>(post.y()),
                                    static_cast<float>(post.z()), 0.0f}};
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  EXPECT_TRUE(cloud[0].has_color);
  EXPECT_EQ(cloud[0].class_id, cls::kCar);  // from the right camera
  EXPECT_EQ(cloud[1].class_id, cls::kBuilding);
}

TEST(Enrich, WithoutLabelImagesClassesComeFromPointLabels) {
  SensorRig rig;
  rig.cameras = {makeCamera("cam")};
  Frame f;
  CameraFrame cf = patternImages(rig.cameras[0]);
  cf.label = Image();  // colour only, like SemanticKITTI's images
  f.cameras = {cf};
  f.points = {pointAtPixel(rig.cameras[0], 5.5, 6.5, 7.0), pointAtYaw(180.0, 5.0)};
  f.point_labels = {PointLabel{cls::kPole, 17}, PointLabel{cls::kVegetation, 0}};
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  expectColourOf(cloud[0], cf.rgb, 5, 6);
  EXPECT_EQ(cloud[0].class_id, cls::kPole);
  EXPECT_EQ(cloud[0].instance_id, 17);
  // Labels belong to the points, so they hold outside the cameras too.
  EXPECT_FALSE(cloud[1].has_color);
  EXPECT_TRUE(cloud[1].has_class);
  EXPECT_EQ(cloud[1].class_id, cls::kVegetation);

  // No images at all: classes and instances from the points, no colour.
  f.cameras.clear();
  const EnrichedCloud bare = enrichFrame(f, rig, EnrichmentConfig{});
  EXPECT_FALSE(bare[0].has_color);
  EXPECT_EQ(bare[0].class_id, cls::kPole);
  EXPECT_EQ(bare[0].instance_id, 17);
  // Point labels that carry instances alone (all of class unknown) give no class.
  f.point_labels = {PointLabel{cls::kUnknown, 17}, PointLabel{cls::kUnknown, 0}};
  const EnrichedCloud instances_only = enrichFrame(f, rig, EnrichmentConfig{});
  EXPECT_FALSE(instances_only[0].has_class);
  EXPECT_EQ(instances_only[0].instance_id, 17);
}

TEST(Enrich, LabelImagesWinOverPointLabelsButInstancesAreCopied) {
  SensorRig rig;
  rig.cameras = {makeCamera("cam")};
  Frame f;
  f.cameras = {uniformImages(rig.cameras[0], 10, 20, 30, cls::kRoad)};
  f.points = {pointAtPixel(rig.cameras[0], 5.5, 6.5, 7.0), pointAtYaw(180.0, 5.0)};
  f.point_labels = {PointLabel{cls::kCar, 3}, PointLabel{cls::kCar, 4}};
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  EXPECT_EQ(cloud[0].class_id, cls::kRoad);
  EXPECT_EQ(cloud[0].instance_id, 3);
  EXPECT_FALSE(cloud[1].has_class);  // the camera semantics do not reach it
  EXPECT_EQ(cloud[1].class_id, cls::kUnknown);
  EXPECT_EQ(cloud[1].instance_id, 4);
}

// A network on a budget: the labels of an earlier picture are read where the point was when it
// was taken (CameraFrame::T_label_lidar), the colour where it is now.
TEST(Enrich, LabelsOfAnEarlierPictureAreReadWhereThePointWasThen) {
  SensorRig rig;
  rig.cameras = {makeCamera("cam")};
  const Camera& cam = rig.cameras[0];
  Frame f;
  CameraFrame cf = patternImages(cam);
  Pose T_then_now = Pose::Identity();
  T_then_now.translation() = Eigen::Vector3d(0.0, 2.0, 0.0);  // 2 m to the left then
  cf.T_label_lidar = T_then_now;
  f.cameras = {cf};
  f.points = {pointAtPixel(cam, 20.5, 10.5, 10.0), pointAtPixel(cam, 0.5, 10.5, 2.0)};
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  const LidarPoint& p = f.points[0];
  const auto then = cam.project(cam.T_camera_lidar * (T_then_now * Eigen::Vector3d(p.x, p.y, p.z)));
  ASSERT_TRUE(then && cam.inImage(*then));
  const int x = static_cast<int>(then->x()), y = static_cast<int>(then->y());
  ASSERT_NE(x, 20) << "the motion must move the point in the picture";
  expectColourOf(cloud[0], cf.rgb, 20, 10);
  ASSERT_TRUE(cloud[0].has_class);
  EXPECT_EQ(cloud[0].class_id, *cf.label.at(x, y));
  // A near point at the left edge was outside the earlier picture: coloured, without class.
  EXPECT_TRUE(cloud[1].has_color);
  EXPECT_FALSE(cloud[1].has_class);
}

// A run whose classes come from the cameras (Frame::camera_semantics) gives a scan no camera
// has labels for yet no classes at all: the point labels are ground truth, never an input.
TEST(Enrich, AScanWithoutLabelsYetTakesNoClassFromPointLabels) {
  SensorRig rig;
  rig.cameras = {makeCamera("cam")};
  Frame f;
  CameraFrame cf = patternImages(rig.cameras[0]);
  cf.label = Image();
  f.cameras = {cf};
  f.camera_semantics = true;
  f.points = {pointAtPixel(rig.cameras[0], 5.5, 6.5, 7.0)};
  f.point_labels = {PointLabel{cls::kPole, 17}};
  const EnrichedCloud cloud = enrichFrame(f, rig, EnrichmentConfig{});
  expectColourOf(cloud[0], cf.rgb, 5, 6);
  EXPECT_FALSE(cloud[0].has_class);
  EXPECT_EQ(cloud[0].instance_id, 17);
}

// ---------------------------------------------------------------------------------------------
// Input checks

TEST(Enrich, ImageSizeMismatchNamesCameraAndSizes) {
  SensorRig rig;
  rig.cameras = {makeCamera("front")};
  Frame f;
  f.points = {pointAtYaw(0.0, 5.0)};
  f.cameras = {patternImages(rig.cameras[0])};
  f.cameras[0].rgb = Image(39, 30, 3);
  std::string msg = errorOf(f, rig);
  EXPECT_NE(msg.find("'front'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("39x30"), std::string::npos) << msg;
  EXPECT_NE(msg.find("40x30"), std::string::npos) << msg;

  f.cameras = {patternImages(rig.cameras[0])};
  f.cameras[0].label = Image(40, 30, 3);  // a colour image where labels belong
  msg = errorOf(f, rig);
  EXPECT_NE(msg.find("'front'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("label"), std::string::npos) << msg;

  f.cameras = {patternImages(rig.cameras[0])};
  f.cameras[0].rgb = Image(40, 30, 1);  // grey where colour belongs
  msg = errorOf(f, rig);
  EXPECT_NE(msg.find("'front'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("rgb"), std::string::npos) << msg;
}

TEST(Enrich, CameraCountMismatchNamesTheRigCameras) {
  SensorRig rig;
  rig.cameras = {makeCamera("left", 45.0), makeCamera("right", -45.0)};
  Frame f;
  f.points = {pointAtYaw(0.0, 5.0)};
  f.cameras = {patternImages(rig.cameras[0])};
  const std::string msg = errorOf(f, rig);
  EXPECT_NE(msg.find("'left'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("'right'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("1 camera images"), std::string::npos) << msg;
  // No images at all is allowed (a LiDAR-only frame).
  f.cameras.clear();
  EXPECT_NO_THROW(enrichFrame(f, rig, EnrichmentConfig{}));
}

TEST(Enrich, NonFinitePointsAndLabelCountThrowNamingThem) {
  SensorRig rig;
  rig.cameras = {makeCamera("cam")};
  Frame f;
  f.cameras = {patternImages(rig.cameras[0])};
  f.points = {pointAtYaw(0.0, 5.0), pointAtYaw(0.0, 5.0), pointAtYaw(0.0, 5.0)};
  f.points[2].y = std::nanf("");
  std::string msg = errorOf(f, rig);
  EXPECT_NE(msg.find("point 2 "), std::string::npos) << msg;
  f.points[2].y = INFINITY;
  msg = errorOf(f, rig);
  EXPECT_NE(msg.find("point 2 "), std::string::npos) << msg;

  f.points[2].y = 0.0f;
  f.point_labels = {PointLabel{}, PointLabel{}};
  msg = errorOf(f, rig);
  EXPECT_NE(msg.find("2 point labels for 3 points"), std::string::npos) << msg;
}

// ---------------------------------------------------------------------------------------------
// PLY

TEST(Ply, WritesBinaryLittleEndianWithColourAndClass) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "semsegmap_test_ply";
  std::filesystem::create_directories(dir);
  const auto path = dir / "cloud.ply";
  EnrichedCloud cloud(2);
  cloud[0].x = 1.5f;
  cloud[0].y = -2.0f;
  cloud[0].z = 0.25f;
  rgbToHsv(200, 100, 50, cloud[0].h, cloud[0].s, cloud[0].v);
  cloud[0].has_color = true;
  cloud[0].class_id = 300;  // above 255, so a one-byte class would show
  cloud[1].x = 7.0f;
  writeEnrichedPly(path, cloud);

  const std::string bytes = readFileBytes(path);
  const std::string end = "end_header\n";
  const size_t body = bytes.find(end);
  ASSERT_NE(body, std::string::npos);
  const std::string header = bytes.substr(0, body);
  EXPECT_EQ(header.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(header.find("element vertex 2\n"), std::string::npos);
  EXPECT_NE(header.find("property ushort class\nproperty uchar has_color\n"), std::string::npos);
  const std::string data = bytes.substr(body + end.size());
  ASSERT_EQ(data.size(), 2u * 18u);
  auto u8 = [&](size_t k) { return static_cast<uint8_t>(data[k]); };
  auto f32 = [&](size_t k) {
    const uint32_t bits = u8(k) | u8(k + 1) << 8 | u8(k + 2) << 16 | uint32_t(u8(k + 3)) << 24;
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
  };
  EXPECT_EQ(f32(0), 1.5f);
  EXPECT_EQ(f32(4), -2.0f);
  EXPECT_EQ(f32(8), 0.25f);
  EXPECT_EQ(u8(12), 200);
  EXPECT_EQ(u8(13), 100);
  EXPECT_EQ(u8(14), 50);
  EXPECT_EQ(u8(15) | u8(16) << 8, 300);
  EXPECT_EQ(u8(17), 1);
  EXPECT_EQ(f32(18), 7.0f);
  EXPECT_EQ(u8(18 + 12) + u8(18 + 13) + u8(18 + 14), 0);
  EXPECT_EQ(u8(18 + 17), 0);
  // Only the file itself is left in the folder (the temporary was renamed).
  size_t files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) files += e.is_regular_file();
  EXPECT_EQ(files, 1u);
  std::filesystem::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Real data: the KITTI raw sample against the devkit's projection formula

// "key: numbers" lines of a KITTI calibration file, parsed here independently of the library.
std::map<std::string, std::vector<double>> readCalib(const std::filesystem::path& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::map<std::string, std::vector<double>> out;
  std::string line;
  while (std::getline(in, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::istringstream values(line.substr(colon + 1));
    std::vector<double> v;
    double x;
    while (values >> x) v.push_back(x);
    out[line.substr(0, colon)] = v;
  }
  return out;
}

TEST(EnrichKitti, ColoursMatchTheDevkitProjection) {
  const std::filesystem::path day =
      std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti_raw_2011_09_26_sample" / "2011_09_26";
  const std::filesystem::path drive = day / "sample_sync";
  if (!std::filesystem::exists(drive)) GTEST_SKIP() << "no KITTI sample at " << drive;

  // The README's formula: x = P_rect_02 * R_rect_00 * [R|T]_velo_to_cam * X (homogeneous).
  auto cam_to_cam = readCalib(day / "calib_cam_to_cam.txt");
  auto velo_to_cam = readCalib(day / "calib_velo_to_cam.txt");
  ASSERT_EQ(cam_to_cam["P_rect_02"].size(), 12u);
  ASSERT_EQ(cam_to_cam["R_rect_00"].size(), 9u);
  ASSERT_EQ(velo_to_cam["R"].size(), 9u);
  ASSERT_EQ(velo_to_cam["T"].size(), 3u);
  Eigen::Matrix<double, 3, 4> P;
  for (int k = 0; k < 12; ++k) P(k / 4, k % 4) = cam_to_cam["P_rect_02"][k];
  Eigen::Matrix4d R_rect = Eigen::Matrix4d::Identity(), Tr = Eigen::Matrix4d::Identity();
  for (int k = 0; k < 9; ++k) {
    R_rect(k / 3, k % 3) = cam_to_cam["R_rect_00"][k];
    Tr(k / 3, k % 3) = velo_to_cam["R"][k];
  }
  for (int k = 0; k < 3; ++k) Tr(k, 3) = velo_to_cam["T"][k];
  const Eigen::Matrix<double, 3, 4> M = P * R_rect * Tr;

  KittiRawReader reader(drive);
  const Frame frame = reader.frame(0);
  const EnrichedCloud cloud = enrichFrame(frame, reader.info().rig, EnrichmentConfig{});
  ASSERT_EQ(cloud.size(), frame.points.size());
  const Image image = readPng(drive / "image_02" / "data" / "0000000000.png");
  ASSERT_EQ(image.width, 1242);
  ASSERT_EQ(image.height, 375);

  std::vector<size_t> clear_in_image;  // projected by hand well inside a pixel
  size_t in_image = 0, in_image_coloured = 0;
  for (size_t i = 0; i < frame.points.size(); ++i) {
    const LidarPoint& p = frame.points[i];
    const Eigen::Vector3d x = M * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
    const bool inside = x.z() > 0 && x.x() / x.z() >= 0 && x.x() / x.z() < image.width &&
                        x.y() / x.z() >= 0 && x.y() / x.z() < image.height;
    if (!inside) {
      ASSERT_FALSE(cloud[i].has_color) << "point " << i << " is outside the image";
      continue;
    }
    ++in_image;
    in_image_coloured += cloud[i].has_color;
    const double u = x.x() / x.z(), v = x.y() / x.z();
    // Away from pixel borders, where rounding in the last digit could pick the neighbour.
    const double fu = u - std::floor(u), fv = v - std::floor(v);
    if (cloud[i].has_color && fu > 0.01 && fu < 0.99 && fv > 0.01 && fv < 0.99)
      clear_in_image.push_back(i);
  }
  // The sample's scan has ~20k points in front of the camera; few are hidden by parallax.
  EXPECT_GT(in_image, 10000u);
  EXPECT_GT(in_image_coloured, 0.8 * in_image);
  ASSERT_GE(clear_in_image.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    const size_t i = clear_in_image[k * clear_in_image.size() / 20];
    const LidarPoint& p = frame.points[i];
    const Eigen::Vector3d x = M * Eigen::Vector4d(p.x, p.y, p.z, 1.0);
    // Pixel x covers [x, x + 1) (Camera::inImage's convention), so the pixel is the floor.
    const int px = static_cast<int>(std::floor(x.x() / x.z()));
    const int py = static_cast<int>(std::floor(x.y() / x.z()));
    SCOPED_TRACE("point " + std::to_string(i) + " at pixel " + std::to_string(px) + ", " +
                 std::to_string(py));
    expectColourOf(cloud[i], image, px, py);
    EXPECT_EQ(cloud[i].class_id, cls::kUnknown);  // KITTI raw has no semantics
  }
}

// ---------------------------------------------------------------------------------------------
// Simulation end to end: camera classes on the points against the LiDAR's ground truth

#if !SEMSEGMAP_WITH_SIM
TEST(EnrichSim, ABuildWithoutTheSimulatorSaysSoInOneLine) {
  try {
    openDataset("sim:world=1,run=S2,preset=tiny");
    ADD_FAILURE() << "a sim: dataset opened without the simulator";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(),
                 "dataset 'sim:world=1,run=S2,preset=tiny': this build has no simulator (built "
                 "without Embree, reconfigure with -DSEMSEGMAP_WITH_SIM=ON)");
  }
}
#endif

TEST(EnrichSim, CameraClassesAgreeWithGroundTruthPointLabels) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,frames=3");
  ASSERT_EQ(source->size(), 3u);
  ASSERT_EQ(source->info().rig.cameras.size(), 3u);
  // The same frames without the occlusion test, to check that it removes mostly wrong colours.
  EnrichmentConfig no_occlusion;
  no_occlusion.occlusion_radius_px = 0;
  no_occlusion.occlusion_tolerance_m = 1e9;
  size_t wrong = 0, wrong_without = 0, coloured_total = 0, coloured_without = 0;
  for (size_t k = 0; k < source->size(); ++k) {
    const Frame frame = source->frame(k);
    const EnrichedCloud cloud = enrichFrame(frame, source->info().rig, EnrichmentConfig{});
    ASSERT_EQ(cloud.size(), frame.points.size());
    ASSERT_EQ(frame.point_labels.size(), frame.points.size());
    size_t coloured = 0, agree = 0;
    for (size_t i = 0; i < cloud.size(); ++i) {
      if (!cloud[i].has_color) continue;
      ++coloured;
      agree += cloud[i].class_id == frame.point_labels[i].class_id;
      EXPECT_EQ(cloud[i].instance_id, frame.point_labels[i].instance_id);
    }
    const double ratio = coloured ? static_cast<double>(agree) / coloured : 0.0;
    std::cout << "frame " << k << ": " << coloured << " of " << cloud.size()
              << " points coloured, class agrees with ground truth for " << 100.0 * ratio << " %\n";
    // The three cameras cover the LiDAR's 270 degrees except its highest and lowest beams.
    EXPECT_GT(coloured, cloud.size() * 9 / 10) << "frame " << k;
    EXPECT_GE(ratio, 0.90) << "frame " << k;
    wrong += coloured - agree;
    coloured_total += coloured;

    const EnrichedCloud plain = enrichFrame(frame, source->info().rig, no_occlusion);
    for (size_t i = 0; i < plain.size(); ++i) {
      coloured_without += plain[i].has_color;
      wrong_without += plain[i].has_color && plain[i].class_id != frame.point_labels[i].class_id;
    }
  }
  std::cout << "without the occlusion test: " << coloured_without << " coloured, " << wrong_without
            << " with a wrong class; with it: " << coloured_total << ", " << wrong << "\n";
  EXPECT_LT(wrong, 0.8 * wrong_without);
  EXPECT_GT(coloured_total, 0.97 * coloured_without);
}

// The commonest real rig: one front camera on a 360-degree LiDAR. A quarter of the scan is in
// the picture, with a class; the rest is unobserved, never class unknown.
TEST(EnrichSim, AFrontCameraOnA360DegreeLidarLeavesMostPointsUnobserved) {
  SEMSEGMAP_SKIP_WITHOUT_SIM();
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,frames=1,lidar=hdl64,cameras=front");
  ASSERT_EQ(source->info().rig.cameras.size(), 1u);
  EXPECT_EQ(source->info().rig.cameras[0].name, "front");
  const Frame frame = source->frame(0);
  ASSERT_EQ(frame.cameras.size(), 1u);
  const EnrichedCloud cloud = enrichFrame(frame, source->info().rig, EnrichmentConfig{});
  size_t classified = 0;
  for (const EnrichedPoint& p : cloud) {
    classified += p.has_class;
    if (!p.has_class) {
      EXPECT_FALSE(p.has_color);
    }
  }
  const double share = static_cast<double>(classified) / static_cast<double>(cloud.size());
  std::cout << "front camera: " << classified << " of " << cloud.size() << " points have a class\n";
  EXPECT_GT(share, 0.12);
  EXPECT_LT(share, 0.40);
  try {
    openDataset("sim:world=1,run=S2,preset=tiny,cameras=back");
    ADD_FAILURE() << "a camera the rig lacks was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "simulator: no camera 'back' on the rig (left, front, right)");
  }
}

}  // namespace
}  // namespace semsegmap
