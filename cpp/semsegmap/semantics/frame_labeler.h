// The semantics stage between a dataset and enrichment: every camera picture of a frame that has
// no label image gets labels from the segmentation network, within the budget of its config
// (label_schedule.h says which pictures are labelled and which labels a scan takes).
//
// Two clocks run the same schedule:
// - ReplayLabeler (recordings: `map`, `localize`, the experiments): the network's time per
//   picture is the config's latency_s and time is the data's, so the budget is simulated
//   deterministically: the same inputs give the same labels and files, whatever the machine.
// - LiveLabeler (live_labeler.h; a robot): the network runs on its own thread beside the scans,
//   within budget_cores of the wall clock, and a scan never waits for it.
#pragma once

#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "semsegmap/core/frame.h"
#include "semsegmap/semantics/label_schedule.h"
#include "semsegmap/semantics/segmentation_network.h"

namespace semsegmap {

struct LabelingStats {
  size_t network_runs = 0;  // pictures the network labelled
  size_t own = 0;           // pictures that took their own labels
  size_t reused = 0;        // pictures that took an earlier picture's labels, carried by odometry
  size_t unlabelled = 0;    // pictures with no labels within tolerance_s: no classes from them
  size_t kept = 0;          // pictures that came with label images
  double network_ms = 0.0;  // wall time in the network (with pre- and post-processing)
  // The network's share of the cores over the run: core-seconds it used (its time x its
  // threads; latency_s in a replay) over the time from the first picture to the last scan.
  double busy_core_s = 0.0;
  double span_s = 0.0;
  double share() const { return span_s > 0 ? busy_core_s / span_s : 0.0; }
};

// The labels of one picture (project class ids, the picture's size); `what` names it in errors.
using LabelFunction = std::function<Image(const Image& rgb, const std::string& what)>;

class FrameLabeler {
 public:
  virtual ~FrameLabeler() = default;
  // Fills frame.cameras[k].label (and T_label_lidar) where the picture has no label image (or
  // everywhere, with replace_dataset_labels); frames come in time order with their odometry
  // (frame.T_odom_base). `what` names the frame in errors.
  virtual void label(Frame& frame, const std::string& what) = 0;
  virtual LabelingStats stats() const = 0;
};

// The cameras of `frame` the network labels, given the config.
std::vector<size_t> camerasToLabel(const Frame& frame, const SemanticsConfig& config,
                                   LabelingStats& stats);
// Whether the config labels every picture with no budget at all.
bool labelsEveryPicture(const SemanticsConfig& config);
// A recording replays a budget only with the network's time per picture: throws
// std::invalid_argument "<where>: semantics.budget_cores: ..." without latency_s. `where` names
// the config file (a robot's network needs none: its own time counts).
void checkReplayable(const SemanticsConfig& config, const std::string& where);

class ReplayLabeler : public FrameLabeler {
 public:
  // T_base_lidar: the rig's, to carry labels between the LiDAR's poses. Throws
  // std::invalid_argument when the budget cannot be simulated (budget_cores without latency_s).
  explicit ReplayLabeler(std::shared_ptr<SegmentationNetwork> network,
                         const Pose& T_base_lidar = Pose::Identity());
  ReplayLabeler(const SemanticsConfig& config, LabelFunction network,
                const Pose& T_base_lidar = Pose::Identity());

  void label(Frame& frame, const std::string& what) override;
  LabelingStats stats() const override { return stats_; }

 private:
  void restart();
  // Runs the network on the pictures whose label runs start before `t` (at `t` too when
  // `inclusive`): a run starts when the worker is free, the budget allows and a picture waits.
  void advance(double t, bool inclusive, const std::string& what);
  void labelEveryPicture(Frame& frame, const std::vector<size_t>& cameras, const std::string& what);

  SemanticsConfig config_;
  LabelFunction network_;
  Pose T_base_lidar_;
  LabelSchedule schedule_;
  // When the simulated worker is free again, and when the budget lets it start its next run.
  double free_at_ = -std::numeric_limits<double>::infinity(), next_start_ = free_at_;
  double first_time_ = 0.0, last_time_ = 0.0;
  bool started_ = false;
  LabelingStats stats_;
};

// The labels of a picture by a SegmentationNetwork, which the function keeps alive.
LabelFunction networkFunction(std::shared_ptr<SegmentationNetwork> network);

}  // namespace semsegmap
