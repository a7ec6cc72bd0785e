// Which pictures a segmentation network on a budget labels, and which labels each scan takes.
// The network cannot label every picture of every camera in real time on a CPU (three cameras at
// 10 Hz would need 2.4 s of a real network a second), so it labels some and the scans in between
// take each camera's newest labels, carried to the scan by odometry (CameraFrame::T_label_lidar).
//
// The policy is the same whatever clock runs it (the data's in a replay, the wall's on a robot;
// frame_labeler.h): the worker takes the newest picture of the camera whose labels are oldest,
// never one sooner than 1 / rate_hz after that camera's last, and a scan takes labels at most
// tolerance_s older than itself, or none (its points are then coloured without classes).
#pragma once

#include <cstddef>
#include <deque>
#include <limits>
#include <optional>
#include <vector>

#include "semsegmap/core/frame.h"

namespace semsegmap {

// A picture waiting for the network, with the LiDAR's odometry pose when it was taken.
struct PendingPicture {
  size_t camera = 0;
  double time = 0.0;
  Image rgb;
  Pose T_odom_lidar = Pose::Identity();
};

struct AttachCounts {
  size_t own = 0;         // pictures that took their own labels
  size_t earlier = 0;     // pictures that took an earlier picture's labels
  size_t unlabelled = 0;  // pictures with no labels within the tolerance
};

class LabelSchedule {
 public:
  LabelSchedule(size_t cameras, double rate_hz, double tolerance_s);

  // The camera's newest picture; one not yet taken is replaced (the network is behind: the newest
  // picture is what the scans to come will need).
  void offer(size_t camera, double time, const Image& rgb, const Pose& T_odom_lidar);
  // The camera whose picture the network should take next, or nothing to take.
  std::optional<size_t> next() const;
  double pendingTime(size_t camera) const { return pending_.at(camera)->time; }
  size_t cameras() const { return pending_.size(); }
  PendingPicture take(size_t camera);
  // The labels of a taken picture, usable from `available` on (the data's time when replayed).
  void deliver(const PendingPicture& picture, Image labels, double available);
  // Gives each camera of `cameras` in `frame` the newest labels usable at `now`, carried by the
  // odometry from their picture to this scan; `frame.timestamp_s` is the scan's time.
  AttachCounts attach(Frame& frame, const std::vector<size_t>& cameras, const Pose& T_odom_lidar,
                      double now = std::numeric_limits<double>::infinity());

 private:
  struct Labelled {
    double time = 0.0;       // of the picture
    double available = 0.0;  // from when the scans may use them
    Image labels;
    Pose T_odom_lidar = Pose::Identity();
  };
  double rate_hz_, tolerance_s_;
  std::vector<std::optional<PendingPicture>> pending_;
  std::vector<double> last_taken_;              // picture time of each camera's last label run
  std::vector<std::deque<Labelled>> labelled_;  // per camera, by picture time
};

}  // namespace semsegmap
