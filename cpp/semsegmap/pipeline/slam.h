// Loop closure while mapping (paper section III-D, after SegMap): the local map is built on
// odometry; every finished segment joins a map anchored at the pose of the frame that finished
// it; the current local segments are localized against the older part of that map, and each
// localization becomes a loop edge in a pose graph of odometry edges. After an optimization the
// map's segments follow their corrected poses.
#pragma once

#include <vector>

#include "semsegmap/graph/trajectory.h"
#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

struct LoopClosure {
  size_t frame_index = 0;         // the current frame
  size_t old_frame_index = 0;     // the frame the matched old segments were finished at (median)
  size_t node = 0, old_node = 0;  // the same two as indices into SlamRun::trajectory
  int inliers = 0;
  double correction_m = 0.0;  // how far the localization moved the current pose estimate
};

struct SlamRun {
  std::vector<StampedPose> trajectory;       // optimized, one pose per frame
  std::vector<StampedPose> trajectory_odom;  // odometry only (the initial estimate)
  std::vector<Pose> trajectory_gt;           // empty without ground truth
  std::vector<FrameStamp> frames;            // per frame run: the data's names (trajectory.csv)
  std::vector<LoopClosure> loops;
  TargetMap map;  // the segments at their corrected positions (duplicates removed)
  RunStats stats;
  double graph_ms = 0.0;  // pose graph optimization, summed
  // The odometry was the ground truth itself (DatasetInfo): its error says nothing.
  bool odometry_is_ground_truth = false;
  // The frames' times (the StampedPoses') are the data's; false: made up from the rate
  // (DatasetInfo::has_frame_times), so that no file must carry them as times (`semsegmap slam`
  // then writes no TUM file).
  bool has_frame_times = true;
};

SlamRun runSlam(FrameSource& source, const PipelineConfig& config,
                std::shared_ptr<Describer> describer, const RunOptions& options = {});

}  // namespace semsegmap
