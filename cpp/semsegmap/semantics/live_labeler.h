// The segmentation network on a robot: its own worker thread beside the scans, within a budget.
// label() hands the scan's pictures to the worker and returns at once with each camera's newest
// labels (label_schedule.h): a scan never waits for the network. The worker takes the newest
// picture of the camera whose labels are oldest, and after a run of d seconds on `threads`
// threads rests until d x threads / budget_cores seconds have passed since the run began, so that
// on average it uses at most budget_cores of the machine (0: no rest).
#pragma once

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>

#include "semsegmap/semantics/frame_labeler.h"

namespace semsegmap {

class LiveLabeler : public FrameLabeler {
 public:
  using Clock = std::chrono::steady_clock;

  LiveLabeler(std::shared_ptr<SegmentationNetwork> network, const Pose& T_base_lidar);
  LiveLabeler(const SemanticsConfig& config, LabelFunction network, const Pose& T_base_lidar);
  ~LiveLabeler() override;  // stops the worker after its current picture
  LiveLabeler(const LiveLabeler&) = delete;
  LiveLabeler& operator=(const LiveLabeler&) = delete;

  // Rethrows the worker's exception (a picture the network refused), once.
  void label(Frame& frame, const std::string& what) override;
  LabelingStats stats() const override;
  // Blocks until the worker has nothing it may take now (tests, and the end of a run).
  void waitIdle();

 private:
  void work();
  bool mayStart() const;  // under mutex_

  SemanticsConfig config_;
  LabelFunction network_;
  Pose T_base_lidar_;
  mutable std::mutex mutex_;
  std::condition_variable wake_, idle_;
  LabelSchedule schedule_;
  Clock::time_point next_start_, first_;
  bool started_ = false, busy_ = false, stopping_ = false;
  std::string what_;  // the frame whose pictures the worker takes, for its errors
  std::exception_ptr failure_;
  LabelingStats stats_;
  std::thread worker_;
};

}  // namespace semsegmap
