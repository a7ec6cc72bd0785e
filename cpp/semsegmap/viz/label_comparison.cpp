#include "semsegmap/viz/label_comparison.h"

#include <opencv2/imgproc.hpp>

#include <set>
#include <stdexcept>

#include "semsegmap/viz/canvas.h"

namespace semsegmap::viz {

namespace {

cv::Mat comparisonRow(const LabelComparison& r, const ClassTable& classes, int max_width) {
  std::vector<cv::Mat> parts = {toBgr(r.rgb), colorizeLabels(r.truth, classes),
                                colorizeLabels(r.predicted, classes)};
  for (cv::Mat& p : parts)  // every part at the picture's size, labels by nearest neighbour
    if (p.size() != parts[0].size()) cv::resize(p, p, parts[0].size(), 0, 0, cv::INTER_NEAREST);
  cv::Mat row;
  cv::hconcat(parts, row);
  if (max_width > 0 && row.cols > max_width)
    cv::resize(row, row, cv::Size(max_width, row.rows * max_width / row.cols), 0, 0,
               cv::INTER_AREA);
  const int third = row.cols / 3;
  drawLabel(row, r.title, {8, 22});
  drawLabel(row, "truth", {third + 8, 22});
  drawLabel(row, "network", {2 * third + 8, 22});
  return row;
}

// The classes that appear in any row's truth or prediction, in colour boxes with their names.
cv::Mat legend(const std::vector<LabelComparison>& rows, const ClassTable& classes, int width) {
  std::set<uint8_t> shown;
  for (const LabelComparison& r : rows) {
    shown.insert(r.truth.data.begin(), r.truth.data.end());
    shown.insert(r.predicted.data.begin(), r.predicted.data.end());
  }
  cv::Mat strip(34, width, CV_8UC3, cv::Scalar(40, 40, 40));
  int x = 8;
  for (const SemanticClass& c : classes.classes()) {
    if (!shown.count(static_cast<uint8_t>(c.id)) || x > width - 60) continue;
    cv::rectangle(strip, cv::Rect(x, 9, 16, 16), bgrOf(c), cv::FILLED);
    drawLabel(strip, c.name, {x + 20, 23}, 0.5);
    x += 28 + static_cast<int>(c.name.size()) * 10;
  }
  return strip;
}

}  // namespace

Image drawLabelComparisons(const std::vector<LabelComparison>& rows, const ClassTable& classes,
                           int max_width) {
  if (rows.empty()) throw std::invalid_argument("no pictures to draw");
  std::vector<cv::Mat> drawn;
  for (const LabelComparison& r : rows) drawn.push_back(comparisonRow(r, classes, max_width));
  for (cv::Mat& d : drawn)  // rows of pictures of other sizes, at the first row's width
    if (d.cols != drawn[0].cols)
      cv::resize(d, d, cv::Size(drawn[0].cols, d.rows * drawn[0].cols / d.cols));
  drawn.push_back(legend(rows, classes, drawn[0].cols));
  cv::Mat sheet;
  cv::vconcat(drawn, sheet);
  return fromBgr(sheet);
}

}  // namespace semsegmap::viz
