#include "semsegmap/datasets/pose_files.h"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <vector>

#include "semsegmap/core/diagnostics.h"
#include "semsegmap/graph/trajectory.h"
#include "semsegmap/io/kitti_calib.h"
#include "semsegmap/io/trajectory_file.h"

namespace semsegmap {

namespace fs = std::filesystem;

namespace {

// KITTI poses of camera 0 become LiDAR poses when a calibration says how (see PoseFileOptions).
// Returns the calibration used, or nothing.
fs::path applyKittiCalib(const fs::path& poses_path, const fs::path& explicit_calib,
                         const Pose& T_base_lidar, std::vector<StampedPose>& poses) {
  fs::path calib = explicit_calib;
  if (calib.empty()) {
    const fs::path beside = poses_path.parent_path() / "calib.txt";
    if (!fs::exists(beside) || !KittiCalibFile(beside).has("Tr")) return {};
    calib = beside;
    note(poses_path.string() + ": KITTI camera-0 poses, turned into LiDAR poses with Tr from " +
         calib.string() + " (" + optionText("kitti-calib", "FILE") + " to choose)");
  }
  const Pose Tr = KittiCalibFile(calib).transform3x4("Tr");
  std::vector<Pose> camera0;
  for (const StampedPose& p : poses) camera0.push_back(p.T);
  const std::vector<Pose> lidar = kittiLidarPoses(camera0, Tr);
  // The files hold base poses: the LiDAR poses moved onto the base the rig mounts them on.
  const Pose T_lidar_base = T_base_lidar.inverse();
  for (size_t i = 0; i < poses.size(); ++i) poses[i].T = T_base_lidar * lidar[i] * T_lidar_base;
  return calib;
}

using PerFrame = std::vector<std::optional<Pose>>;

// The frame numbers of the source's scans; empty unless every scan is named by one.
std::vector<size_t> frameNumbersOf(FrameSource& source) {
  std::vector<size_t> numbers;
  for (size_t i = 0; i < source.size(); ++i) {
    const std::optional<size_t> number = source.frameNumber(i);
    if (!number) return {};
    numbers.push_back(*number);
  }
  return numbers;
}

// KITTI poses have no times: line N is the pose of the scan numbered N. Scans named otherwise
// take the lines in order only when there is one line per scan; any other count is a guess.
// `rule` is set to the rule used.
PerFrame kittiPosesPerFrame(FrameSource& source, const fs::path& path,
                            const std::vector<StampedPose>& poses, std::string* rule) {
  const std::vector<size_t> numbers = frameNumbersOf(source);
  PerFrame per_frame(source.size());
  if (!numbers.empty()) {
    const size_t last = *std::max_element(numbers.begin(), numbers.end());
    if (last >= poses.size())
      throw std::runtime_error(path.string() + ": " + std::to_string(poses.size()) +
                               " KITTI poses, but the scans go up to frame " +
                               std::to_string(last) + " (line N is the pose of the scan named N)");
    for (size_t i = 0; i < numbers.size(); ++i) per_frame[i] = poses[numbers[i]].T;
    *rule = "KITTI poses matched by frame number";
    note(path.string() + ": KITTI poses matched by frame number: line N is the pose of the scan " +
         "named N (" + std::to_string(numbers.size()) + " scans, frames " +
         std::to_string(numbers.front()) + " to " + std::to_string(last) + ")");
    return per_frame;
  }
  if (poses.size() != source.size())
    throw std::runtime_error(path.string() + ": " + std::to_string(poses.size()) +
                             " KITTI poses for " + std::to_string(source.size()) +
                             " scans whose names are no frame numbers: which line is which "
                             "scan's would be a guess (name the scans by frame number, or give "
                             "TUM poses)");
  for (size_t i = 0; i < poses.size(); ++i) per_frame[i] = poses[i].T;
  *rule = "KITTI poses taken in scan order, one line per scan";
  note(path.string() + ": KITTI poses taken in scan order, one line per scan (the " +
       std::to_string(poses.size()) + " scans' names are no frame numbers)");
  return per_frame;
}

// TUM poses are interpolated to each scan's time, which must then come from the data.
PerFrame tumPosesPerFrame(FrameSource& source, const fs::path& path,
                          const std::vector<StampedPose>& poses, double max_gap_s,
                          std::string* rule) {
  if (!source.info().has_frame_times)
    throw std::runtime_error(path.string() + ": TUM poses are matched to scans by time, but the " +
                             "scans of " + source.info().name +
                             " have no times (names that are no times, no times file): give a "
                             "times file, or KITTI poses");
  PerFrame per_frame(source.size());
  for (size_t i = 0; i < source.size(); ++i)
    per_frame[i] = poseAt(poses, source.frameTime(i), max_gap_s);
  *rule = "TUM poses matched by time";
  note(path.string() + ": TUM poses matched by time, interpolated to each scan's time");
  return per_frame;
}

// Per frame of the source, its pose from the file, or nothing; `origin` says which file and rule.
PerFrame posesPerFrame(FrameSource& source, const fs::path& path, const PoseFileOptions& options,
                       std::string* origin) {
  PoseFile file = readPoseFile(path);
  std::string rule;
  PerFrame poses;
  if (file.timestamped) {
    poses = tumPosesPerFrame(source, path, file.poses, options.max_gap_s, &rule);
  } else {
    const fs::path calib =
        applyKittiCalib(path, options.kitti_calib, source.info().rig.T_base_lidar, file.poses);
    poses = kittiPosesPerFrame(source, path, file.poses, &rule);
    if (!calib.empty()) rule += ", camera 0 moved onto the LiDAR by Tr of " + calib.string();
  }
  *origin = path.string() + " (" + rule + ")";
  return poses;
}

bool sameFile(const fs::path& a, const fs::path& b) {
  std::error_code error;  // a missing or empty path is no file: not the same
  return !a.empty() && !b.empty() && fs::equivalent(a, b, error) && !error;
}

class PosedSource : public FrameSource {
 public:
  PosedSource(std::unique_ptr<FrameSource> source, const PoseFileOptions& options)
      : source_(std::move(source)), info_(source_->info()) {
    std::vector<std::optional<Pose>> odom, gt;
    if (!options.odometry.empty())
      odom = posesPerFrame(*source_, options.odometry, options, &info_.origin.odometry);
    if (!options.ground_truth.empty())
      gt = posesPerFrame(*source_, options.ground_truth, options, &info_.origin.ground_truth);
    for (size_t i = 0; i < source_->size(); ++i) {
      if ((!odom.empty() && !odom[i]) || (!gt.empty() && !gt[i])) continue;
      kept_.push_back(
          {i, odom.empty() ? std::nullopt : odom[i], gt.empty() ? std::nullopt : gt[i]});
    }
    const fs::path& named = !options.odometry.empty() ? options.odometry : options.ground_truth;
    if (kept_.empty())
      throw std::runtime_error(named.string() + ": no scan of " + info_.name +
                               " lies within the poses' time span");
    if (kept_.size() < source_->size())
      note(std::to_string(source_->size() - kept_.size()) + " of " +
           std::to_string(source_->size()) +
           " scans lie outside the poses' time span or in a gap and are left out");
    info_.has_odometry |= !odom.empty();
    info_.has_ground_truth_poses |= !gt.empty();
    // A replaced odometry or ground truth is no longer the other, unless both are one file.
    info_.odometry_is_ground_truth = sameFile(options.odometry, options.ground_truth);
  }
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return kept_.size(); }
  double frameTime(size_t index) override { return source_->frameTime(kept_.at(index).source); }
  std::optional<size_t> frameNumber(size_t index) override {
    return source_->frameNumber(kept_.at(index).source);
  }
  Frame frame(size_t index) override {
    const Kept& k = kept_.at(index);
    Frame f = source_->frame(k.source);
    f.index = index;
    if (k.odom) f.T_odom_base = *k.odom;
    if (k.gt) f.T_world_base = *k.gt;
    return f;
  }

 private:
  struct Kept {
    size_t source;
    std::optional<Pose> odom, gt;
  };
  std::unique_ptr<FrameSource> source_;
  DatasetInfo info_;
  std::vector<Kept> kept_;
};

}  // namespace

std::unique_ptr<FrameSource> withPoseFiles(std::unique_ptr<FrameSource> source,
                                           const PoseFileOptions& options) {
  if (options.odometry.empty() && options.ground_truth.empty()) return source;
  return std::make_unique<PosedSource>(std::move(source), options);
}

}  // namespace semsegmap
