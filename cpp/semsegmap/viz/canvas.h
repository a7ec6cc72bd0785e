// Internal to viz/: conversions between the plain Image and OpenCV matrices for drawing.
#pragma once

#include <opencv2/core.hpp>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/image.h"

namespace semsegmap::viz {

// RGB Image -> BGR cv::Mat (a copy), and back.
cv::Mat toBgr(const Image& rgb);
Image fromBgr(const cv::Mat& bgr);
// A label image drawn with the class table's display colours (BGR).
cv::Mat colorizeLabels(const Image& label, const ClassTable& classes);
cv::Scalar bgrOf(const SemanticClass& c);
// Text with a dark outline so it reads on any background.
void drawLabel(cv::Mat& canvas, const std::string& text, cv::Point at, double scale = 0.6);

}  // namespace semsegmap::viz
