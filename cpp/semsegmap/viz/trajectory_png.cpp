#include "semsegmap/viz/trajectory_png.h"

#include <algorithm>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "semsegmap/io/image_io.h"
#include "semsegmap/viz/canvas.h"

namespace semsegmap::viz {

void writeTrajectoriesPng(const std::filesystem::path& png, const std::string& title,
                          const std::vector<TrajectoryCurve>& curves,
                          const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>& links) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  for (const auto& c : curves)
    for (const auto& T : c.poses) {
      lo = lo.cwiseMin(T.translation().head<2>());
      hi = hi.cwiseMax(T.translation().head<2>());
    }
  if (lo.x() > hi.x()) lo = hi = Eigen::Vector2d::Zero();
  lo -= Eigen::Vector2d::Constant(20.0);
  hi += Eigen::Vector2d::Constant(20.0);
  const double mpp = std::max(0.1, std::max(hi.x() - lo.x(), hi.y() - lo.y()) / 1600.0);
  const int w = static_cast<int>((hi.x() - lo.x()) / mpp) + 1;
  // A curve without a name (one more piece of a curve named before) gets no legend row.
  const auto rows = static_cast<int>(std::count_if(
      curves.begin(), curves.end(), [](const TrajectoryCurve& c) { return !c.name.empty(); }));
  const int h = static_cast<int>((hi.y() - lo.y()) / mpp) + 1 + 30 * rows;
  cv::Mat canvas(h, w, CV_8UC3, cv::Scalar(24, 24, 24));
  auto px = [&](const Eigen::Vector3d& p) {
    return cv::Point(static_cast<int>((p.x() - lo.x()) / mpp),
                     static_cast<int>((hi.y() - p.y()) / mpp));
  };
  for (const auto& [a, b] : links)
    cv::line(canvas, px(a), px(b), cv::Scalar(60, 200, 255), 1, cv::LINE_AA);
  int row = 0;
  for (const TrajectoryCurve& c : curves) {
    std::vector<cv::Point> path;
    for (const auto& T : c.poses) path.push_back(px(T.translation()));
    const cv::Scalar color(c.b, c.g, c.r);
    if (path.size() > 1) cv::polylines(canvas, path, false, color, 2, cv::LINE_AA);
    if (c.name.empty()) continue;
    const int y = h - 12 - 30 * (rows - 1 - row++);
    cv::line(canvas, {12, y - 5}, {42, y - 5}, color, 3);
    drawLabel(canvas, c.name, {50, y}, 0.55);
  }
  drawLabel(canvas, title, {12, 28}, 0.7);
  if (!links.empty()) drawLabel(canvas, "orange: loop closures", {12, 54}, 0.55);
  writePng(png, fromBgr(canvas));
}

}  // namespace semsegmap::viz
