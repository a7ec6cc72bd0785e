#include "semsegmap/viz/enrich_overlay.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "semsegmap/io/ply_writer.h"
#include "semsegmap/viz/canvas.h"

namespace semsegmap::viz {

namespace {

struct Dot {
  cv::Point pixel;
  float depth;
  ClassId class_id;
  bool has_color;
};

cv::Scalar depthColour(double depth, const EnrichOverlayStyle& style) {
  // Logarithmic, because most LiDAR points are near and a linear scale would paint them all red.
  const double t = std::clamp(
      std::log(std::max(depth, 1e-3) / style.near_m) / std::log(style.far_m / style.near_m), 0.0,
      1.0);
  uint8_t r = 0, g = 0, b = 0;
  hsvToRgb(static_cast<float>(t * 240.0 / 360.0), 1.0f, 1.0f, r, g, b);  // red .. blue
  return cv::Scalar(b, g, r);
}

}  // namespace

Image drawEnrichOverlay(const Image& rgb, const Camera& camera, const EnrichedCloud& cloud,
                        const ClassTable& classes, const std::string& legend,
                        const EnrichOverlayStyle& style) {
  if (rgb.width != camera.width || rgb.height != camera.height || rgb.channels != 3)
    throw std::invalid_argument(
        "overlay: camera '" + camera.name + "': image is " + std::to_string(rgb.width) + "x" +
        std::to_string(rgb.height) + "x" + std::to_string(rgb.channels) + ", expected " +
        std::to_string(camera.width) + "x" + std::to_string(camera.height) + "x3");
  cv::Mat canvas = toBgr(rgb);

  std::vector<Dot> dots;
  for (const EnrichedPoint& p : cloud) {
    const Eigen::Vector3d pc = camera.T_camera_lidar * Eigen::Vector3d(p.x, p.y, p.z);
    const auto uv = camera.project(pc);
    if (!uv || !camera.inImage(*uv)) continue;
    dots.push_back({cv::Point(static_cast<int>(uv->x()), static_cast<int>(uv->y())),
                    static_cast<float>(pc.z()), p.class_id, p.has_color});
  }
  std::sort(dots.begin(), dots.end(), [](const Dot& a, const Dot& b) { return a.depth > b.depth; });

  // Class id -> colour; ids outside the table are drawn grey.
  std::vector<cv::Scalar> lut(65536, cv::Scalar(128, 128, 128));
  for (const auto& c : classes.classes()) lut[c.id] = bgrOf(c);
  std::vector<bool> seen(65536, false);
  for (const Dot& d : dots) {
    const cv::Scalar colour = style.colour == DotColour::kClass ? lut[d.class_id]
                              : d.has_color                     ? depthColour(d.depth, style)
                                                                : cv::Scalar(0, 0, 0);
    seen[d.class_id] = true;
    cv::circle(canvas, d.pixel, style.dot_radius_px, colour, cv::FILLED, cv::LINE_8);
  }

  // One line per '\n' of the legend.
  const double scale = std::clamp(canvas.cols / 1100.0, 0.45, 0.7);
  const int line_px = static_cast<int>(26 * scale / 0.6);
  int y = line_px;
  for (size_t start = 0; start <= legend.size(); y += line_px) {
    const size_t end = std::min(legend.find('\n', start), legend.size());
    drawLabel(canvas, legend.substr(start, end - start), cv::Point(8, y), scale);
    start = end + 1;
  }
  if (style.colour == DotColour::kClass) {
    // Swatches along the bottom, wrapping upwards when a row is full.
    int x = 8, row_y = canvas.rows - 10;
    for (const auto& c : classes.classes()) {
      if (!seen[c.id]) continue;
      int baseline = 0;
      const int w =
          26 + cv::getTextSize(c.name, cv::FONT_HERSHEY_SIMPLEX, 0.45, 1, &baseline).width;
      if (x > 8 && x + w > canvas.cols) {
        x = 8;
        row_y -= 20;
      }
      cv::rectangle(canvas, cv::Rect(x, row_y - 11, 12, 12), cv::Scalar(255, 255, 255), cv::FILLED);
      cv::rectangle(canvas, cv::Rect(x + 1, row_y - 10, 10, 10), bgrOf(c), cv::FILLED);
      drawLabel(canvas, c.name, cv::Point(x + 16, row_y), 0.45);
      x += w;
    }
  }
  if (style.max_width > 0 && canvas.cols > style.max_width) {
    // Shrunk after drawing: the dots keep their places on the picture, the file gets small.
    cv::Mat small;
    const double f = static_cast<double>(style.max_width) / canvas.cols;
    cv::resize(canvas, small, cv::Size(), f, f, cv::INTER_AREA);
    return fromBgr(small);
  }
  return fromBgr(canvas);
}

}  // namespace semsegmap::viz
