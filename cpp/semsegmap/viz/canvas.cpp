#include "semsegmap/viz/canvas.h"

#include <opencv2/imgproc.hpp>

namespace semsegmap::viz {

cv::Mat toBgr(const Image& rgb) {
  cv::Mat view(rgb.height, rgb.width, CV_8UC3, const_cast<uint8_t*>(rgb.data.data()));
  cv::Mat bgr;
  cv::cvtColor(view, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

Image fromBgr(const cv::Mat& bgr) {
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  Image out(rgb.cols, rgb.rows, 3);
  for (int y = 0; y < rgb.rows; ++y)
    std::copy(rgb.ptr<uint8_t>(y), rgb.ptr<uint8_t>(y) + 3 * rgb.cols, out.at(0, y));
  return out;
}

cv::Scalar bgrOf(const SemanticClass& c) {
  return cv::Scalar(c.color_rgb[2], c.color_rgb[1], c.color_rgb[0]);
}

cv::Mat colorizeLabels(const Image& label, const ClassTable& classes) {
  cv::Vec3b lut[256];
  for (int k = 0; k < 256; ++k) lut[k] = cv::Vec3b(0, 0, 0);
  for (const auto& c : classes.classes())
    if (c.id < 256) lut[c.id] = cv::Vec3b(c.color_rgb[2], c.color_rgb[1], c.color_rgb[0]);
  cv::Mat out(label.height, label.width, CV_8UC3);
  for (int y = 0; y < label.height; ++y)
    for (int x = 0; x < label.width; ++x) out.at<cv::Vec3b>(y, x) = lut[*label.at(x, y)];
  return out;
}

void drawLabel(cv::Mat& canvas, const std::string& text, cv::Point at, double scale) {
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), 4,
              cv::LINE_AA);
  cv::putText(canvas, text, at, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 1,
              cv::LINE_AA);
}

}  // namespace semsegmap::viz
