#include "semsegmap/datasets/lidar_odometry_source.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace semsegmap {

namespace {

class LidarOdometrySource : public FrameSource {
 public:
  LidarOdometrySource(std::unique_ptr<FrameSource> source, const OdometryConfig& config)
      : source_(std::move(source)), odometry_(config), info_(source_->info()) {
    info_.has_odometry = true;
    info_.odometry_is_ground_truth = false;
    info_.origin.odometry = "LiDAR odometry on the scans";
    T_base_lidar_ = info_.rig.T_base_lidar;
  }

  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return source_->size(); }
  double frameTime(size_t index) override { return source_->frameTime(index); }
  std::optional<size_t> frameNumber(size_t index) override { return source_->frameNumber(index); }

  Frame frame(size_t index) override {
    if (index >= size()) throwFrameOutOfRange(info_.name, index, size());
    if (index < poses_.size()) {
      Frame f = source_->frame(index);
      f.T_odom_base = poses_[index];
      return f;
    }
    Frame f;
    while (poses_.size() <= index) {
      f = source_->frame(poses_.size());
      const OdometryResult r = odometry_.registerFrame(f.points, f.point_times, f.timestamp_s);
      poses_.push_back(baseOdometryFromLidar(r.T_odom_lidar, T_base_lidar_));
    }
    f.T_odom_base = poses_[index];
    return f;
  }

 private:
  std::unique_ptr<FrameSource> source_;
  LidarOdometry odometry_;
  DatasetInfo info_;
  Pose T_base_lidar_ = Pose::Identity();
  std::vector<Pose> poses_;
};

}  // namespace

std::unique_ptr<FrameSource> withLidarOdometry(std::unique_ptr<FrameSource> source,
                                               const OdometryConfig& config) {
  if (!source) throw std::invalid_argument("withLidarOdometry: no dataset");
  return std::make_unique<LidarOdometrySource>(std::move(source), config);
}

}  // namespace semsegmap
