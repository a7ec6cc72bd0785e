#include "semsegmap/viz/label_overlay.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <stdexcept>

#include "semsegmap/viz/canvas.h"

namespace semsegmap::viz {

namespace {

// The classes present, most pixels first, as coloured boxes with their shares.
void drawLegend(cv::Mat& canvas, const Image& labels, const ClassTable& classes, int x0) {
  std::vector<size_t> count(256, 0);
  for (uint8_t id : labels.data) ++count[id];
  std::vector<int> present;
  for (int id = 0; id < 256; ++id)
    if (count[id] > 0) present.push_back(id);
  std::sort(present.begin(), present.end(), [&](int a, int b) { return count[a] > count[b]; });
  const double scale = std::max(0.4, canvas.rows / 1000.0);
  const int line = static_cast<int>(24 * scale / 0.5);
  int y = line;
  for (int id : present) {
    const SemanticClass* c = classes.contains(static_cast<ClassId>(id))
                                 ? &classes.at(static_cast<ClassId>(id))
                                 : nullptr;
    const cv::Scalar colour = c ? bgrOf(*c) : cv::Scalar(0, 0, 0);
    cv::rectangle(canvas, cv::Rect(x0 + 8, y - line / 2, line / 2, line / 2), colour, cv::FILLED);
    char text[96];
    std::snprintf(text, sizeof(text), "%s %.1f%%", c ? c->name.c_str() : "?",
                  100.0 * count[id] / labels.data.size());
    drawLabel(canvas, text, {x0 + 12 + line / 2, y}, scale);
    y += line;
  }
}

}  // namespace

Image drawLabelOverlay(const Image& rgb, const Image& labels, const ClassTable& classes,
                       const std::string& title, int max_width) {
  if (rgb.width != labels.width || rgb.height != labels.height || labels.channels != 1)
    throw std::invalid_argument("label overlay: the labels are not the picture's size");
  const cv::Mat picture = toBgr(rgb);
  cv::Mat blended;
  cv::addWeighted(picture, 0.4, colorizeLabels(labels, classes), 0.6, 0.0, blended);
  cv::Mat canvas;
  cv::hconcat(picture, blended, canvas);
  drawLabel(canvas, title, {8, std::max(20, canvas.rows / 24)}, std::max(0.5, canvas.rows / 800.0));
  drawLegend(canvas, labels, classes, picture.cols);
  if (max_width > 0 && canvas.cols > max_width) {
    const double s = static_cast<double>(max_width) / canvas.cols;
    cv::resize(canvas, canvas, cv::Size(), s, s, cv::INTER_AREA);
  }
  return fromBgr(canvas);
}

}  // namespace semsegmap::viz
