#include "semsegmap/pipeline/frame_assembly.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace semsegmap {

namespace {

// Pictures a camera keeps while no scan claims them: a camera that runs far ahead of the LiDAR
// (or a LiDAR that stopped) must not grow the buffer without bound.
constexpr size_t kMaxPicturesPerCamera = 32;

template <typename T, typename Stamp>
void insertByTime(std::deque<T>& q, T value, Stamp stamp) {
  auto at = std::upper_bound(q.begin(), q.end(), stamp(value),
                             [&](double t, const T& v) { return t < stamp(v); });
  q.insert(at, std::move(value));
}

}  // namespace

FrameAssembler::FrameAssembler(const FrameAssemblyConfig& config)
    : config_(config), pictures_(config.cameras) {
  if (!(config.picture_tolerance_s >= 0 && config.max_wait_s >= 0 &&
        config.max_odometry_gap_s > 0 && config.max_waiting_scans > 0))
    throw std::invalid_argument(
        "frame assembly: picture_tolerance_s and max_wait_s must not be negative, "
        "max_odometry_gap_s and max_waiting_scans must be positive");
}

void FrameAssembler::addScan(ScanMessage scan) {
  ++stats_.scans;
  if (!std::isfinite(scan.stamp_s)) throw std::invalid_argument("scan without a finite time stamp");
  if (last_made_s_ && scan.stamp_s <= *last_made_s_) {
    ++stats_.out_of_order;  // its frame's place in the run is gone
    return;
  }
  newest_scan_s_ = std::max(newest_scan_s_, scan.stamp_s);
  insertByTime(waiting_, std::move(scan), [](const ScanMessage& s) { return s.stamp_s; });
}

void FrameAssembler::addPicture(size_t camera, PictureMessage picture) {
  if (camera >= pictures_.size())
    throw std::invalid_argument("picture of camera " + std::to_string(camera) + ": the rig has " +
                                std::to_string(pictures_.size()) + " camera(s)");
  std::deque<PictureMessage>& q = pictures_[camera];
  insertByTime(q, std::move(picture), [](const PictureMessage& p) { return p.stamp_s; });
  if (q.size() > kMaxPicturesPerCamera) q.pop_front();
}

void FrameAssembler::addOdometry(const StampedPose& odometry) {
  auto at = std::upper_bound(odometry_.begin(), odometry_.end(), odometry.timestamp_s,
                             [](double t, const StampedPose& p) { return t < p.timestamp_s; });
  odometry_.insert(at, odometry);
}

// Decided once the camera has a picture at or after t: pictures come in their own order, so no
// nearer one can follow.
FrameAssembler::Wait FrameAssembler::pictureOf(size_t camera, double t,
                                               const PictureMessage** found) const {
  const std::deque<PictureMessage>& q = pictures_[camera];
  *found = nullptr;
  double best = config_.picture_tolerance_s;
  for (const PictureMessage& p : q)
    if (std::abs(p.stamp_s - t) <= best) {
      best = std::abs(p.stamp_s - t);
      *found = &p;
    }
  return !q.empty() && q.back().stamp_s >= t ? Wait::kReady : Wait::kWaiting;
}

FrameAssembler::Wait FrameAssembler::odometryAt(double t, std::optional<Pose>* found) const {
  *found = std::nullopt;
  if (!config_.odometry) return Wait::kReady;
  if (odometry_.empty() || odometry_.back().timestamp_s < t) return Wait::kWaiting;
  *found = poseAt(odometry_, t, config_.max_odometry_gap_s);
  return Wait::kReady;
}

FrameAssembler::Made FrameAssembler::make(const ScanMessage& scan, bool overdue, Frame& out) {
  const double t = scan.stamp_s;
  std::vector<const PictureMessage*> pictures(pictures_.size());
  bool complete = true;
  for (size_t c = 0; c < pictures_.size(); ++c)
    complete &= pictureOf(c, t, &pictures[c]) == Wait::kReady;
  std::optional<Pose> T_odom_base;
  complete &= odometryAt(t, &T_odom_base) == Wait::kReady;
  if (!complete && !overdue) return Made::kWaiting;
  if (config_.odometry && !T_odom_base) {
    ++stats_.without_odometry;
    return Made::kSkipped;
  }
  out = Frame{};
  out.index = stats_.frames++;
  out.timestamp_s = t;
  out.points = scan.points;
  out.point_times = scan.point_times;
  if (T_odom_base) out.T_odom_base = *T_odom_base;
  out.cameras.resize(pictures_.size());
  for (size_t c = 0; c < pictures.size(); ++c) {
    if (!pictures[c]) {
      ++stats_.missing_pictures;
      continue;
    }
    out.cameras[c].rgb = pictures[c]->rgb;
    out.cameras[c].label = pictures[c]->label;
  }
  return Made::kFrame;
}

// What no later scan (time >= t) can use: pictures further back than the tolerance, odometry
// before the last message at or before t (the interpolation needs that one).
void FrameAssembler::forgetBefore(double t) {
  for (std::deque<PictureMessage>& q : pictures_)
    while (!q.empty() && q.front().stamp_s < t - config_.picture_tolerance_s) q.pop_front();
  auto first_after =
      std::upper_bound(odometry_.begin(), odometry_.end(), t,
                       [](double s, const StampedPose& p) { return s < p.timestamp_s; });
  if (first_after - odometry_.begin() > 1) odometry_.erase(odometry_.begin(), first_after - 1);
}

std::vector<Frame> FrameAssembler::takeFrames(bool at_end) {
  std::vector<Frame> out;
  while (!waiting_.empty()) {
    const ScanMessage& scan = waiting_.front();
    const bool overdue = at_end || newest_scan_s_ >= scan.stamp_s + config_.max_wait_s ||
                         waiting_.size() > config_.max_waiting_scans;
    Frame frame;
    const Made made = make(scan, overdue, frame);
    if (made == Made::kWaiting) break;
    if (made == Made::kFrame) out.push_back(std::move(frame));
    last_made_s_ = scan.stamp_s;
    waiting_.pop_front();
    forgetBefore(waiting_.empty() ? *last_made_s_ : waiting_.front().stamp_s);
  }
  return out;
}

std::vector<Frame> FrameAssembler::takeReady() {
  return takeFrames(false);
}

std::vector<Frame> FrameAssembler::flush() {
  return takeFrames(true);
}

}  // namespace semsegmap
