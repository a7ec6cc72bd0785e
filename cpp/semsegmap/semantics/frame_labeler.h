// The semantics stage between a dataset and enrichment: every camera picture of a frame that has
// no label image gets one from the segmentation network. The network may run at a lower rate
// than the LiDAR: a camera whose network ran less than 1 / rate_hz ago gives its latest labels
// again, as long as they are at most tolerance_s old.
#pragma once

#include <memory>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/semantics/segmentation_network.h"

namespace semsegmap {

struct LabelingStats {
  size_t network_runs = 0;  // pictures the network labelled
  size_t reused = 0;        // pictures that took their camera's latest labels
  size_t kept = 0;          // pictures that came with label images
  double network_ms = 0.0;  // time spent in the network (with pre- and post-processing)
};

class FrameLabeler {
 public:
  explicit FrameLabeler(std::shared_ptr<SegmentationNetwork> network);

  // Fills frame.cameras[k].label where it is empty (or everywhere, with
  // replace_dataset_labels); `what` names the frame in errors.
  void label(Frame& frame, const std::string& what);
  const LabelingStats& stats() const { return stats_; }
  const SegmentationNetwork& network() const { return *network_; }

 private:
  struct Latest {
    bool valid = false;
    double time = 0.0;
    Image labels;
  };
  std::shared_ptr<SegmentationNetwork> network_;
  std::vector<Latest> latest_;  // per camera
  LabelingStats stats_;
};

}  // namespace semsegmap
