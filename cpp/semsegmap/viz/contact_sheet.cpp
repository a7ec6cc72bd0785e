#include <cmath>
#include <opencv2/imgproc.hpp>

#include "semsegmap/io/image_io.h"
#include "semsegmap/viz/canvas.h"
#include "semsegmap/viz/sim_overview.h"

namespace semsegmap::viz {

namespace {

// The LiDAR scan as the sensor sees it: one pixel per beam, coloured by range.
cv::Mat rangeImage(const Frame& f, const LidarModel& lidar) {
  cv::Mat range(lidar.rows, lidar.columns, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::Mat gray(1, 256, CV_8UC1);
  for (int k = 0; k < 256; ++k) gray.at<uint8_t>(0, k) = static_cast<uint8_t>(k);
  cv::Mat lut;
  cv::applyColorMap(gray, lut, cv::COLORMAP_TURBO);
  for (const auto& p : f.points) {
    const double r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    const double az = std::atan2(p.y, p.x) * 180.0 / M_PI;
    const double el = std::asin(p.z / r) * 180.0 / M_PI;
    const int col = static_cast<int>((0.5 * lidar.hfov_deg - az) / lidar.hfov_deg * lidar.columns);
    const int row = static_cast<int>(std::lround(
        (lidar.vfov_up_deg - el) / (lidar.vfov_up_deg - lidar.vfov_down_deg) * (lidar.rows - 1)));
    if (col < 0 || col >= lidar.columns || row < 0 || row >= lidar.rows) continue;
    const int v = std::clamp(static_cast<int>(255.0 * (1.0 - std::min(r, 60.0) / 60.0)), 0, 255);
    range.at<cv::Vec3b>(row, col) = lut.at<cv::Vec3b>(0, v);
  }
  return range;
}

}  // namespace

void writeCameraContactSheet(const sim::WorldConfig& world, sim::Run run, size_t frame_index,
                             const std::filesystem::path& png) {
  const ClassTable classes = ClassTable::Default();
  std::vector<cv::Mat> rows;
  Frame sunny_frame;
  LidarModel lidar;
  for (const char* condition : {"sunny", "sunrise"}) {
    sim::SimConfig c;
    c.world = world;
    c.run = run;
    c.condition = condition;
    c.traffic_seed = 1;
    sim::Simulator simulator(c);
    lidar = simulator.info().rig.lidar;
    const Frame f = simulator.frame(std::min(frame_index, simulator.size() - 1));
    std::vector<cv::Mat> cams;
    for (const auto& cam : f.cameras) cams.push_back(toBgr(cam.rgb));
    cv::Mat row;
    cv::hconcat(cams, row);
    drawLabel(row, std::string(condition) + ": left | front | right", {12, 28}, 0.8);
    rows.push_back(row);
    if (std::string(condition) == "sunny") sunny_frame = f;
  }
  std::vector<cv::Mat> labels;
  for (const auto& cam : sunny_frame.cameras) labels.push_back(colorizeLabels(cam.label, classes));
  cv::Mat label_row;
  cv::hconcat(labels, label_row);
  drawLabel(label_row, "class labels", {12, 28}, 0.8);
  rows.push_back(label_row);

  cv::Mat range = rangeImage(sunny_frame, lidar);
  cv::Mat range_big;
  cv::resize(range, range_big, cv::Size(label_row.cols, lidar.rows * 3), 0, 0, cv::INTER_NEAREST);
  drawLabel(range_big, "LiDAR range image (270 deg, near = red, far = blue)", {12, 28}, 0.8);
  rows.push_back(range_big);

  cv::Mat sheet;
  cv::vconcat(rows, sheet);
  writePng(png, fromBgr(sheet));
}

}  // namespace semsegmap::viz
