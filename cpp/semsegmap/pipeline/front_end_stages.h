// The stages before enrichment that a robot's recording may need: the segmentation network for
// pictures that come without label images, and LiDAR odometry for scans that come without poses.
// A Pipeline given them runs them on every frame, whatever the frame source, so that code that
// embeds the pipeline (C++ or Python) gets what the command line gets.
//
// They run per pipeline. Where several pipelines share the frames of one run (the experiments
// compare configurations on the same frames), a frame source labels and registers the frames once
// instead (datasets/semantic_sources.h, datasets/lidar_odometry_source.h), on the same
// FrameLabeler and LidarOdometry.
#pragma once

#include <memory>
#include <optional>

#include "semsegmap/core/frame.h"
#include "semsegmap/core/frame_source.h"
#include "semsegmap/odometry/lidar_odometry.h"
#include "semsegmap/semantics/frame_labeler.h"

namespace semsegmap {

struct FrontEndStages {
  // Labels each picture without a label image (or every one, with the network's
  // replace_dataset_labels); nullptr: the frames' own labels.
  std::shared_ptr<SegmentationNetwork> network;
  // T_odom_base of each frame from its scan; nullopt: the frames' own odometry.
  std::optional<OdometryConfig> lidar_odometry;
  // How the network keeps to its budget (semantics.rate_hz, budget_cores): replayed on the
  // data's clock (recordings: the same inputs give the same files), on its own thread beside the
  // scans on the wall clock (a robot: semantics/live_labeler.h), or not at all (one scan that
  // must be labelled: a relocalization).
  enum class Labelling { kReplay, kLive, kEveryPicture };
  Labelling labelling = Labelling::kReplay;
  bool any() const { return network != nullptr || lidar_odometry.has_value(); }
};

// What a dataset gives once the stages run on its frames: odometry of the LiDAR's, origins that
// say so. The pipeline and the sessions check their inputs against this.
DatasetInfo infoWithStages(DatasetInfo info, const FrontEndStages& stages);

// Runs the stages on each frame in order.
class FramePreparation {
 public:
  FramePreparation(const FrontEndStages& stages, const DatasetInfo& info);

  // The frame as the stages leave it: `frame` itself when there are none, else a labelled and
  // registered copy, kept until the next call. Frames must come in the run's order (the
  // odometry registers each scan against the ones before).
  const Frame& prepare(const Frame& frame);
  // The frame the last prepare() returned, given the frame passed to it.
  const Frame& last(const Frame& given) const { return active_ ? prepared_ : given; }
  // How often the network ran; nullptr without one.
  std::optional<LabelingStats> labeling() const;

 private:
  bool active_ = false;
  std::unique_ptr<FrameLabeler> labeler_;
  std::unique_ptr<LidarOdometry> odometry_;
  Pose T_base_lidar_ = Pose::Identity();
  Frame prepared_;
};

}  // namespace semsegmap
