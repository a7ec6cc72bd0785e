#include "semsegmap/viz/segments_png.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "semsegmap/io/image_io.h"
#include "semsegmap/viz/canvas.h"

namespace semsegmap::viz {

void segmentColor(SegmentId id, uint8_t& r, uint8_t& g, uint8_t& b) {
  const double h = std::fmod(static_cast<double>(id) * 0.618033988749895, 1.0);
  const double s = 0.55 + 0.4 * std::fmod(static_cast<double>(id) * 0.37, 1.0);
  const double v = 0.95;
  const double h6 = h * 6.0;
  const int i = static_cast<int>(h6) % 6;
  const double f = h6 - std::floor(h6);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double rgb[3];
  switch (i) {
    case 0:
      rgb[0] = v, rgb[1] = t, rgb[2] = p;
      break;
    case 1:
      rgb[0] = q, rgb[1] = v, rgb[2] = p;
      break;
    case 2:
      rgb[0] = p, rgb[1] = v, rgb[2] = t;
      break;
    case 3:
      rgb[0] = p, rgb[1] = q, rgb[2] = v;
      break;
    case 4:
      rgb[0] = t, rgb[1] = p, rgb[2] = v;
      break;
    default:
      rgb[0] = v, rgb[1] = p, rgb[2] = q;
      break;
  }
  r = static_cast<uint8_t>(rgb[0] * 255);
  g = static_cast<uint8_t>(rgb[1] * 255);
  b = static_cast<uint8_t>(rgb[2] * 255);
}

void writeSegmentsPng(const std::filesystem::path& png, const std::vector<Segment>& segments,
                      const std::vector<Pose>& trajectory, const std::string& title, double mpp) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  auto extend = [&](double x, double y) {
    lo = lo.cwiseMin(Eigen::Vector2d(x, y));
    hi = hi.cwiseMax(Eigen::Vector2d(x, y));
  };
  for (const auto& s : segments)
    for (const auto& p : s.last().points) extend(p.x, p.y);
  for (const auto& T : trajectory) extend(T.translation().x(), T.translation().y());
  if (lo.x() > hi.x()) lo = hi = Eigen::Vector2d::Zero();
  lo -= Eigen::Vector2d::Constant(5.0);
  hi += Eigen::Vector2d::Constant(5.0);
  // Keep the picture a sensible size whatever the extent: at most 3000 px, at least 800 px.
  const double extent = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  mpp = std::clamp(mpp, extent / 3000.0, std::max(extent / 3000.0, extent / 800.0));
  const int w = static_cast<int>((hi.x() - lo.x()) / mpp) + 1;
  const int h = static_cast<int>((hi.y() - lo.y()) / mpp) + 1;
  cv::Mat canvas(h, w, CV_8UC3, cv::Scalar(24, 24, 24));
  auto toPixel = [&](double x, double y) {
    return cv::Point(static_cast<int>((x - lo.x()) / mpp), static_cast<int>((hi.y() - y) / mpp));
  };
  // Lower points first, so that the top of each segment is what shows from above.
  std::vector<std::pair<float, std::pair<cv::Point, cv::Vec3b>>> dots;
  for (const auto& s : segments) {
    uint8_t r, g, b;
    segmentColor(s.id, r, g, b);
    for (const auto& p : s.last().points)
      dots.push_back({p.z, {toPixel(p.x, p.y), cv::Vec3b(b, g, r)}});
  }
  std::sort(dots.begin(), dots.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [z, d] : dots)
    if (d.first.x >= 0 && d.first.y >= 0 && d.first.x < w && d.first.y < h)
      canvas.at<cv::Vec3b>(d.first) = d.second;
  std::vector<cv::Point> path;
  for (const auto& T : trajectory)
    path.push_back(toPixel(T.translation().x(), T.translation().y()));
  if (path.size() > 1)
    cv::polylines(canvas, path, false, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  drawLabel(canvas, title, {12, 28}, 0.7);
  char scale[64];
  std::snprintf(scale, sizeof(scale), "%zu segments, %.2f m/px", segments.size(), mpp);
  drawLabel(canvas, scale, {12, h - 14}, 0.6);
  writePng(png, fromBgr(canvas));
}

}  // namespace semsegmap::viz
