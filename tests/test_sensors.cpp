#include <gtest/gtest.h>

#include <cmath>

#include "semsegmap/sim/camera_sim.h"
#include "semsegmap/sim/lidar_sim.h"
#include "semsegmap/sim/mesh_builder.h"

using namespace semsegmap;
using namespace semsegmap::sim;

namespace {

// A world with one large wall facing the origin at x = 10 and the ground plane.
World wallWorld(const Eigen::Vector3f& wall_albedo = {0.2f, 0.35f, 0.75f}) {
  World w;
  MeshBuilder mb(w.mesh, w.surfaces);
  const uint32_t wall = mb.addSurface({cls::kBuilding, 7, wall_albedo, 0.0f});
  mb.addBox({10.5, 0.0}, -5.0, {1.0, 200.0, 30.0}, 0.0, wall);
  const uint32_t ground = mb.addSurface({cls::kRoad, 8, {0.1f, 0.1f, 0.1f}, 0.0f});
  mb.addGroundPolygon({{-100, -100}, {100, -100}, {100, 100}, {-100, 100}}, -1.9, ground);
  return w;
}

double hueOf(const uint8_t* rgb) {
  const double r = rgb[0] / 255.0, g = rgb[1] / 255.0, b = rgb[2] / 255.0;
  const double mx = std::max({r, g, b}), mn = std::min({r, g, b});
  double h = 0.0;
  if (mx - mn < 1e-9) return 0.0;
  if (mx == r)
    h = std::fmod((g - b) / (mx - mn), 6.0);
  else if (mx == g)
    h = (b - r) / (mx - mn) + 2.0;
  else
    h = (r - g) / (mx - mn) + 4.0;
  h /= 6.0;
  return h < 0 ? h + 1.0 : h;
}

}  // namespace

TEST(LidarSim, BeamAgainstAKnownPlaneReturnsTheRightRange) {
  const World w = wallWorld();
  RayScene scene(w);
  LidarModel lidar;
  lidar.range_noise_m = 0.0;
  lidar.dropout = 0.0;
  const LidarScan exact = simulateLidar(scene, lidar, Pose::Identity(), 1);
  int on_wall = 0;
  for (size_t k = 0; k < exact.points.size(); ++k) {
    if (exact.labels[k].class_id != cls::kBuilding) continue;
    ++on_wall;
    EXPECT_NEAR(exact.points[k].x, 10.0, 1e-3);
    EXPECT_EQ(exact.labels[k].instance_id, 7);
  }
  EXPECT_GT(on_wall, 10000);

  // With noise: range residuals have the configured sigma and no bias.
  lidar.range_noise_m = 0.02;
  const LidarScan noisy = simulateLidar(scene, lidar, Pose::Identity(), 2);
  double sum = 0, sum2 = 0;
  int n = 0;
  for (size_t k = 0; k < noisy.points.size(); ++k) {
    if (noisy.labels[k].class_id != cls::kBuilding) continue;
    const Eigen::Vector3d p(noisy.points[k].x, noisy.points[k].y, noisy.points[k].z);
    const double expected = 10.0 * p.norm() / p.x();  // range to the plane along this beam
    const double e = p.norm() - expected;
    sum += e;
    sum2 += e * e;
    ++n;
  }
  ASSERT_GT(n, 10000);
  EXPECT_NEAR(sum / n, 0.0, 0.002);
  EXPECT_NEAR(std::sqrt(sum2 / n), 0.02, 0.002);
}

TEST(LidarSim, DropoutsAndFieldOfView) {
  const World w = wallWorld();
  RayScene scene(w);
  LidarModel lidar;
  lidar.dropout = 0.0;
  const size_t all = simulateLidar(scene, lidar, Pose::Identity(), 1).points.size();
  lidar.dropout = 0.1;
  const size_t some = simulateLidar(scene, lidar, Pose::Identity(), 1).points.size();
  EXPECT_NEAR(static_cast<double>(some) / all, 0.9, 0.01);
  // Nothing comes from behind: the 270-degree field of view leaves the back 90 degrees blind.
  for (const auto& p : simulateLidar(scene, lidar, Pose::Identity(), 1).points) {
    const double az = std::atan2(p.y, p.x) * 180.0 / M_PI;
    ASSERT_LE(std::abs(az), 135.01);
  }
}

TEST(LidarSim, SameSeedSameScanWhateverTheThreads) {
  const World w = wallWorld();
  RayScene scene(w);
  const LidarModel lidar;
  const LidarScan a = simulateLidar(scene, lidar, planarPose(1, 2, 0, 0.3), 11);
  const LidarScan b = simulateLidar(scene, lidar, planarPose(1, 2, 0, 0.3), 11);
  ASSERT_EQ(a.points.size(), b.points.size());
  EXPECT_EQ(0, std::memcmp(a.points.data(), b.points.data(), a.points.size() * sizeof(LidarPoint)));
  const LidarScan c = simulateLidar(scene, lidar, planarPose(1, 2, 0, 0.3), 12);
  EXPECT_NE(0, std::memcmp(a.points.data(), c.points.data(),
                           std::min(a.points.size(), c.points.size()) * sizeof(LidarPoint)));
}

TEST(CameraSim, LabelsDepthAndColourOfAWall) {
  const World w = wallWorld();
  RayScene scene(w);
  const Camera cam = defaultSimRig().cameras[1];  // looks along +x
  const Pose T_world_camera = cam.T_camera_lidar.inverse();
  const CameraRender r = renderCamera(scene, cam, T_world_camera, lightingFor("sunny"), 1, true);
  EXPECT_EQ(*r.label.at(320, 240), cls::kBuilding);
  EXPECT_EQ(*r.label.at(320, 479), cls::kRoad);
  // The front camera sits 0.35 m ahead of the LiDAR: the wall is 9.65 m away along the axis.
  EXPECT_NEAR(r.depth[240 * cam.width + 320], 9.65, 1e-3);
  // The wall is blue, and stays blue at sunrise although its RGB changes.
  const CameraRender dawn = renderCamera(scene, cam, T_world_camera, lightingFor("sunrise"), 1);
  const uint8_t* sunny_px = r.rgb.at(320, 200);
  const uint8_t* dawn_px = dawn.rgb.at(320, 200);
  EXPECT_GT(sunny_px[2], sunny_px[0]);
  EXPECT_NE(std::vector<uint8_t>(sunny_px, sunny_px + 3),
            std::vector<uint8_t>(dawn_px, dawn_px + 3));
  const double dh = std::abs(hueOf(sunny_px) - hueOf(dawn_px));
  EXPECT_LT(std::min(dh, 1.0 - dh), 0.1) << hueOf(sunny_px) << " vs " << hueOf(dawn_px);
}

TEST(CameraSim, ShadowsDarkenWhatTheSunCannotSee) {
  // A wall facing away from the sun is lit by ambient light only, so it is darker.
  const World w = wallWorld({0.6f, 0.6f, 0.6f});
  RayScene scene(w);
  const Camera cam = defaultSimRig().cameras[1];
  Lighting toward = lightingFor("sunny");
  toward.to_sun = Eigen::Vector3f(-1, 0, 1).normalized();  // sun behind the camera: wall lit
  Lighting away = toward;
  away.to_sun = Eigen::Vector3f(1, 0, 1).normalized();  // sun behind the wall
  const auto lit = renderCamera(scene, cam, cam.T_camera_lidar.inverse(), toward, 1);
  const auto dark = renderCamera(scene, cam, cam.T_camera_lidar.inverse(), away, 1);
  EXPECT_GT(lit.rgb.at(320, 200)[1], dark.rgb.at(320, 200)[1] + 60);
  // The ground in front of the wall is in the wall's shadow when the sun is behind it.
  EXPECT_GT(lit.rgb.at(320, 470)[1], dark.rgb.at(320, 470)[1] + 10);
}
