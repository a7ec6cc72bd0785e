#include "semsegmap/viz/localization_png.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "semsegmap/io/image_io.h"
#include "semsegmap/viz/canvas.h"

namespace semsegmap::viz {

namespace {

// Green below 1 m, yellow to orange up to 5 m, red beyond: the thresholds of the paper's table.
cv::Scalar errorColor(double e) {
  if (e < 0) return {255, 200, 80};
  if (e < 1.0) return {80, 220, 60};
  if (e < 5.0) return {0, 200.0 - 25.0 * e, 255};
  return {40, 40, 230};
}

// One entry of the legend at the bottom left, `row` lines up from the last.
void drawLegendEntry(cv::Mat& canvas, int row, const cv::Scalar& colour, const std::string& text) {
  const int y = canvas.rows - 30 - 20 * row;
  cv::circle(canvas, {20, y}, 6, colour, cv::FILLED);
  drawLabel(canvas, text, {32, y + 5}, 0.5);
}

// The title, what the dots' colours mean at the bottom left and what the picture shows. Without
// ground truth no error is known: one entry in the colour every dot has, no error scale.
void drawLegend(cv::Mat& canvas, const LocalizationPicture& pic, double mpp) {
  drawLabel(canvas, pic.title, {12, 28}, 0.7);
  const bool unknown = std::any_of(pic.localizations.begin(), pic.localizations.end(),
                                   [](const auto& l) { return l.second < 0; });
  if (!pic.has_ground_truth) {
    drawLegendEntry(canvas, 0, errorColor(-1.0), "localization (no ground truth)");
  } else {
    const int first = unknown ? 1 : 0;  // a frame without ground truth in a run with it
    if (unknown) drawLegendEntry(canvas, 0, errorColor(-1.0), "no ground truth");
    drawLegendEntry(canvas, first, errorColor(10.0), "> 5 m");
    drawLegendEntry(canvas, first + 1, errorColor(3.0), "1-5 m");
    drawLegendEntry(canvas, first + 2, errorColor(0.5), "error < 1 m");
  }
  char scale[160];
  std::snprintf(scale, sizeof(scale),
                "grey: %zu map segments; white: %s; magenta: matches of one localization; "
                "%.2f m/px",
                pic.map_centroids.size(),
                pic.has_ground_truth ? "ground-truth trajectory" : "odometry (its own frame)", mpp);
  drawLabel(canvas, scale, {12, 52}, 0.5);
}

}  // namespace

void writeLocalizationPng(const std::filesystem::path& png, const LocalizationPicture& pic) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  auto extend = [&](double x, double y) {
    lo = lo.cwiseMin(Eigen::Vector2d(x, y));
    hi = hi.cwiseMax(Eigen::Vector2d(x, y));
  };
  // Framed on the query run with the map around it as far as the robot could see (a target map
  // is often much larger than the run localized against it).
  for (const auto& T : pic.trajectory) extend(T.translation().x(), T.translation().y());
  if (pic.trajectory.empty())
    for (const auto& c : pic.map_centroids) extend(c.x(), c.y());
  if (lo.x() > hi.x()) lo = hi = Eigen::Vector2d::Zero();
  lo -= Eigen::Vector2d::Constant(pic.trajectory.empty() ? 15.0 : 60.0);
  hi += Eigen::Vector2d::Constant(pic.trajectory.empty() ? 15.0 : 60.0);
  const double extent = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  const double mpp = std::max(0.1, extent / 1800.0);
  const int w = static_cast<int>((hi.x() - lo.x()) / mpp) + 1;
  const int h = static_cast<int>((hi.y() - lo.y()) / mpp) + 1;
  cv::Mat canvas(h, w, CV_8UC3, cv::Scalar(24, 24, 24));
  auto px = [&](double x, double y) {
    return cv::Point(static_cast<int>((x - lo.x()) / mpp), static_cast<int>((hi.y() - y) / mpp));
  };
  const cv::Scalar grey(120, 120, 120);
  for (const auto& p : pic.map_points) {
    const cv::Point q = px(p.x(), p.y());
    if (q.x >= 0 && q.y >= 0 && q.x < w && q.y < h)
      canvas.at<cv::Vec3b>(q) = cv::Vec3b(130, 130, 130);
  }
  if (pic.map_points.empty())
    for (const auto& c : pic.map_centroids)
      cv::circle(canvas, px(c.x(), c.y()), 3, grey, cv::FILLED, cv::LINE_AA);
  std::vector<cv::Point> path;
  for (const auto& T : pic.trajectory) path.push_back(px(T.translation().x(), T.translation().y()));
  if (path.size() > 1)
    cv::polylines(canvas, path, false, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  // Worst last, so that wrong localizations are never hidden under good ones.
  std::vector<std::pair<Eigen::Vector3d, double>> dots = pic.localizations;
  std::stable_sort(dots.begin(), dots.end(),
                   [](const auto& a, const auto& b) { return a.second < b.second; });
  for (const auto& [p, e] : dots)
    cv::circle(canvas, px(p.x(), p.y()), 5, errorColor(e), cv::FILLED, cv::LINE_AA);
  for (const auto& [local, target] : pic.matches) {
    cv::line(canvas, px(pic.highlight.x(), pic.highlight.y()), px(local.x(), local.y()),
             cv::Scalar(255, 140, 60), 1, cv::LINE_AA);
    cv::line(canvas, px(local.x(), local.y()), px(target.x(), target.y()), cv::Scalar(255, 0, 255),
             2, cv::LINE_AA);
    cv::circle(canvas, px(target.x(), target.y()), 4, cv::Scalar(255, 0, 255), 2, cv::LINE_AA);
  }
  if (!pic.matches.empty())
    cv::circle(canvas, px(pic.highlight.x(), pic.highlight.y()), 9, cv::Scalar(255, 255, 255), 2,
               cv::LINE_AA);
  drawLegend(canvas, pic, mpp);
  writePng(png, fromBgr(canvas));
}

}  // namespace semsegmap::viz
