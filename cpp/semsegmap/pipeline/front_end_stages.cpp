#include "semsegmap/pipeline/front_end_stages.h"

#include <string>

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
  if (stages.network) labeler_ = std::make_unique<FrameLabeler>(stages.network);
  if (stages.lidar_odometry) odometry_ = std::make_unique<LidarOdometry>(*stages.lidar_odometry);
}

const Frame& FramePreparation::prepare(const Frame& frame) {
  if (!active_) return frame;
  prepared_ = frame;
  if (labeler_) labeler_->label(prepared_, "frame " + std::to_string(frame.index));
  if (odometry_) {
    const OdometryResult r =
        odometry_->registerFrame(prepared_.points, prepared_.point_times, prepared_.timestamp_s);
    prepared_.T_odom_base = baseOdometryFromLidar(r.T_odom_lidar, T_base_lidar_);
  }
  return prepared_;
}

}  // namespace semsegmap
