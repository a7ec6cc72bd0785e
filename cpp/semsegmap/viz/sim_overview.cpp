#include "semsegmap/viz/sim_overview.h"

#include <opencv2/imgproc.hpp>

#include "semsegmap/io/image_io.h"
#include "semsegmap/sim/ray_scene.h"
#include "semsegmap/viz/canvas.h"

namespace semsegmap::viz {

void writeSimOverview(const sim::WorldConfig& config, const std::filesystem::path& png,
                      double mpp) {
  const sim::World world = sim::generateWorld(config, 1);
  sim::RayScene scene(world);
  const ClassTable classes = ClassTable::Default();
  const int w = static_cast<int>((world.max_xy.x() - world.min_xy.x()) / mpp);
  const int h = static_cast<int>((world.max_xy.y() - world.min_xy.y()) / mpp);
  cv::Mat canvas(h, w, CV_8UC3);
  auto toPixel = [&](const Eigen::Vector2d& p) {
    return cv::Point(static_cast<int>((p.x() - world.min_xy.x()) / mpp),
                     static_cast<int>((world.max_xy.y() - p.y()) / mpp));
  };
#pragma omp parallel for schedule(dynamic, 8)
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3f o(static_cast<float>(world.min_xy.x() + (x + 0.5) * mpp),
                              static_cast<float>(world.max_xy.y() - (y + 0.5) * mpp), 100.0f);
      const sim::RayHit hit = scene.intersect(o, Eigen::Vector3f(0, 0, -1), 0.0f, 200.0f);
      cv::Vec3b px(255, 255, 255);
      if (hit.hit) {
        const auto& c = classes.at(hit.surface->class_id).color_rgb;
        // Brighter with height, so buildings and trees stand out of the ground.
        const float height = 100.0f - hit.t;
        const float k = std::clamp(0.55f + 0.06f * height, 0.55f, 1.0f);
        px = cv::Vec3b(static_cast<uint8_t>(c[2] * k), static_cast<uint8_t>(c[1] * k),
                       static_cast<uint8_t>(c[0] * k));
      }
      canvas.at<cv::Vec3b>(y, x) = px;
    }

  const struct {
    sim::Run run;
    cv::Scalar bgr;
  } runs[] = {{sim::Run::S0, {255, 80, 0}},
              {sim::Run::S1, {0, 200, 0}},
              {sim::Run::S2, {0, 0, 255}},
              {sim::Run::S3, {0, 230, 255}}};
  int legend_y = 30;
  for (const auto& r : runs) {
    const sim::Trajectory t =
        sim::makeTrajectory(world.roads, r.run, sim::TrajectoryConfig{}, sim::OdometryNoise{}, 1);
    std::vector<cv::Point> pts;
    for (const auto& T : t.T_world_base) pts.push_back(toPixel(T.translation().head<2>()));
    cv::polylines(canvas, pts, false, r.bgr, 3, cv::LINE_AA);
    cv::arrowedLine(canvas, pts.front(), pts[std::min<size_t>(12, pts.size() - 1)], r.bgr, 3,
                    cv::LINE_AA, 0, 0.5);
    char text[96];
    std::snprintf(text, sizeof(text), "%s  %.0f m", sim::runName(r.run).c_str(), t.length_m);
    cv::line(canvas, {20, legend_y - 6}, {60, legend_y - 6}, r.bgr, 4);
    drawLabel(canvas, text, {70, legend_y}, 0.7);
    legend_y += 28;
  }
  char text[96];
  std::snprintf(text, sizeof(text), "world seed %llu, %zu objects, %.1f m/px",
                static_cast<unsigned long long>(config.seed), world.objects.size(), mpp);
  drawLabel(canvas, text, {20, h - 20}, 0.7);
  writePng(png, fromBgr(canvas));
}

}  // namespace semsegmap::viz
