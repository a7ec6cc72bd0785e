#include "semsegmap/semantics/label_schedule.h"

#include <cmath>
#include <iterator>

namespace semsegmap {

namespace {
// Times come from the data: two readings of one stamp may differ in the last bits.
constexpr double kSameTime = 1e-6;
}  // namespace

LabelSchedule::LabelSchedule(size_t cameras, double rate_hz, double tolerance_s)
    : rate_hz_(rate_hz),
      tolerance_s_(tolerance_s),
      pending_(cameras),
      last_taken_(cameras, -std::numeric_limits<double>::infinity()),
      labelled_(cameras) {}

void LabelSchedule::offer(size_t camera, double time, const Image& rgb, const Pose& T_odom_lidar) {
  pending_.at(camera) = PendingPicture{camera, time, rgb, T_odom_lidar};
}

std::optional<size_t> LabelSchedule::next() const {
  std::optional<size_t> best;
  for (size_t k = 0; k < pending_.size(); ++k) {
    if (!pending_[k]) continue;
    if (rate_hz_ > 0 && pending_[k]->time < last_taken_[k] + 1.0 / rate_hz_ - kSameTime) continue;
    if (!best || last_taken_[k] < last_taken_[*best]) best = k;
  }
  return best;
}

PendingPicture LabelSchedule::take(size_t camera) {
  PendingPicture p = std::move(*pending_.at(camera));
  pending_[camera].reset();
  last_taken_[camera] = p.time;
  return p;
}

void LabelSchedule::deliver(const PendingPicture& picture, Image labels, double available) {
  std::deque<Labelled>& done = labelled_.at(picture.camera);
  Labelled l{picture.time, available, std::move(labels), picture.T_odom_lidar};
  auto it = done.end();
  while (it != done.begin() && std::prev(it)->time > l.time) --it;
  done.insert(it, std::move(l));
}

AttachCounts LabelSchedule::attach(Frame& frame, const std::vector<size_t>& cameras,
                                   const Pose& T_odom_lidar, double now) {
  AttachCounts counts;
  const double t = frame.timestamp_s;
  for (size_t k : cameras) {
    std::deque<Labelled>& done = labelled_.at(k);
    // The newest usable labels; older ones are never taken again (scans come in time order).
    const Labelled* use = nullptr;
    size_t used = 0;
    for (size_t i = 0; i < done.size(); ++i)
      if (done[i].available <= now && done[i].time <= t + kSameTime) {
        use = &done[i];
        used = i;
      }
    CameraFrame& camera = frame.cameras.at(k);
    if (!use || t - use->time > tolerance_s_) {
      ++counts.unlabelled;
      camera.label = Image();
      camera.T_label_lidar.reset();
    } else {
      camera.label = use->labels;
      const bool own = std::abs(use->time - t) <= kSameTime;
      if (own)
        camera.T_label_lidar.reset();
      else
        camera.T_label_lidar = use->T_odom_lidar.inverse() * T_odom_lidar;
      ++(own ? counts.own : counts.earlier);
    }
    if (use) done.erase(done.begin(), done.begin() + static_cast<std::ptrdiff_t>(used));
  }
  return counts;
}

}  // namespace semsegmap
