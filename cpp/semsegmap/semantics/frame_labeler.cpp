#include "semsegmap/semantics/frame_labeler.h"

#include <chrono>
#include <cmath>

namespace semsegmap {

FrameLabeler::FrameLabeler(std::shared_ptr<SegmentationNetwork> network)
    : network_(std::move(network)) {}

void FrameLabeler::label(Frame& frame, const std::string& what) {
  const SemanticsConfig& c = network_->config();
  if (latest_.size() < frame.cameras.size()) latest_.resize(frame.cameras.size());
  for (size_t k = 0; k < frame.cameras.size(); ++k) {
    CameraFrame& camera = frame.cameras[k];
    if (camera.rgb.empty()) continue;
    if (!camera.label.empty() && !c.replace_dataset_labels) {
      ++stats_.kept;
      continue;
    }
    Latest& latest = latest_[k];
    const double age = frame.timestamp_s - latest.time;
    // Reused only forwards in time: a scan before the labels' picture does not take them.
    const bool fresh_enough = latest.valid && age >= 0 && age <= c.tolerance_s &&
                              latest.labels.width == camera.rgb.width &&
                              latest.labels.height == camera.rgb.height;
    if (c.rate_hz > 0 && fresh_enough && age < 1.0 / c.rate_hz) {
      camera.label = latest.labels;
      ++stats_.reused;
      continue;
    }
    const auto start = std::chrono::steady_clock::now();
    camera.label = network_->label(camera.rgb, what + ", camera " + std::to_string(k));
    stats_.network_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ++stats_.network_runs;
    latest = {true, frame.timestamp_s, camera.label};
  }
}

}  // namespace semsegmap
