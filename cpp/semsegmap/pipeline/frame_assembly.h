// A robot's drivers publish scans, pictures and odometry each on its own, at its own rate and
// with its own delay; the pipeline takes one Frame per scan. The assembler makes the frames: a
// scan gets each camera's picture nearest its time (within picture_tolerance_s) and the
// odometry interpolated at its time.
//
// It waits by the data's time, not the clock's: a scan waits for what it lacks until a scan
// max_wait_s later has arrived, so the same messages in the same order give the same frames,
// live or replayed. Then it goes on without the pictures that did not come (its points are
// coloured by the cameras that did, the others' unobserved) and is skipped, counted, without
// odometry: a scan is never given a pose the odometry did not give.
#pragma once

#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/stamped_pose.h"

namespace semsegmap {

struct ScanMessage {
  double stamp_s = 0.0;
  std::vector<LidarPoint> points;
  std::vector<float> point_times;  // optional, as Frame::point_times
};

struct PictureMessage {
  double stamp_s = 0.0;
  Image rgb;
  Image label;  // optional: the network labels pictures without one
};

struct FrameAssemblyConfig {
  size_t cameras = 0;                 // pictures come for cameras 0..cameras-1 of the rig
  bool odometry = true;               // odometry messages come (else the LiDAR odometry's)
  double picture_tolerance_s = 0.05;  // a picture this near a scan's time is the scan's
  double max_wait_s = 0.3;            // a scan waits until a scan this much later came
  double max_odometry_gap_s = 0.5;    // odometry messages further apart are not interpolated
  size_t max_waiting_scans = 16;      // more: the oldest goes on with what it has
};

struct AssemblyStats {
  size_t scans = 0;             // received
  size_t frames = 0;            // made
  size_t out_of_order = 0;      // scans older than a frame already made: dropped
  size_t without_odometry = 0;  // skipped: no odometry around their time
  size_t missing_pictures = 0;  // a camera's picture a frame went on without
};

class FrameAssembler {
 public:
  explicit FrameAssembler(const FrameAssemblyConfig& config);

  void addScan(ScanMessage scan);
  void addPicture(size_t camera, PictureMessage picture);  // throws for a camera not in the rig
  void addOdometry(const StampedPose& odometry);

  // The frames that are complete, or have waited long enough, in their scans' order; numbered
  // (Frame::index) from 0 in the order made.
  std::vector<Frame> takeReady();
  // Every waiting scan with what it has: at the end of a recording.
  std::vector<Frame> flush();
  const AssemblyStats& stats() const { return stats_; }

 private:
  enum class Wait { kReady, kWaiting };
  enum class Made { kWaiting, kSkipped, kFrame };
  Wait pictureOf(size_t camera, double t, const PictureMessage** found) const;
  Wait odometryAt(double t, std::optional<Pose>* found) const;
  Made make(const ScanMessage& scan, bool overdue, Frame& out);
  std::vector<Frame> takeFrames(bool at_end);
  void forgetBefore(double t);
  FrameAssemblyConfig config_;
  std::deque<ScanMessage> waiting_;                   // by time
  std::vector<std::deque<PictureMessage>> pictures_;  // per camera, by time
  std::vector<StampedPose> odometry_;                 // by time
  std::optional<double> last_made_s_;
  double newest_scan_s_ = -1e300;
  AssemblyStats stats_;
};

}  // namespace semsegmap
