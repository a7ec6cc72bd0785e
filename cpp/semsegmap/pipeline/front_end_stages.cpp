#include "semsegmap/pipeline/front_end_stages.h"

#include <string>

#include "semsegmap/semantics/live_labeler.h"

namespace semsegmap {

DatasetInfo infoWithStages(DatasetInfo info, const FrontEndStages& stages) {
  if (stages.lidar_odometry) {
    info.has_odometry = true;
    info.odometry_is_ground_truth = false;
    info.origin.odometry = "LiDAR odometry on the scans (the pipeline's)";
  }
  if (stages.network) {
    const std::string own = info.origin.label_images;
    info.origin.label_images =
        own.empty() ? "the semantics: network" : own + ", else the semantics: network";
  }
  return info;
}

FramePreparation::FramePreparation(const FrontEndStages& stages, const DatasetInfo& info)
    : active_(stages.any()), T_base_lidar_(info.rig.T_base_lidar) {
  using L = FrontEndStages::Labelling;
  if (stages.network && stages.labelling == L::kLive) {
    labeler_ = std::make_unique<LiveLabeler>(stages.network, T_base_lidar_);
  } else if (stages.network) {
    SemanticsConfig c = stages.network->config();
    if (stages.labelling == L::kEveryPicture) c.rate_hz = c.budget_cores = c.latency_s = 0;
    labeler_ = std::make_unique<ReplayLabeler>(c, networkFunction(stages.network), T_base_lidar_);
  }
  if (stages.lidar_odometry) odometry_ = std::make_unique<LidarOdometry>(*stages.lidar_odometry);
}

const Frame& FramePreparation::prepare(const Frame& frame) {
  if (!active_) return frame;
  prepared_ = frame;
  // Odometry first: labels of earlier pictures are carried to the scan by it.
  if (odometry_) {
    const OdometryResult r =
        odometry_->registerFrame(prepared_.points, prepared_.point_times, prepared_.timestamp_s);
    prepared_.T_odom_base = baseOdometryFromLidar(r.T_odom_lidar, T_base_lidar_);
  }
  if (labeler_) labeler_->label(prepared_, "frame " + std::to_string(frame.index));
  return prepared_;
}

std::optional<LabelingStats> FramePreparation::labeling() const {
  if (!labeler_) return std::nullopt;
  return labeler_->stats();
}

}  // namespace semsegmap
