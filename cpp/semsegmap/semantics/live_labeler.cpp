#include "semsegmap/semantics/live_labeler.h"

#include <algorithm>
#include <utility>

namespace semsegmap {

LiveLabeler::LiveLabeler(std::shared_ptr<SegmentationNetwork> network, const Pose& T_base_lidar)
    : LiveLabeler(network->config(), networkFunction(network), T_base_lidar) {}

LiveLabeler::LiveLabeler(const SemanticsConfig& config, LabelFunction network,
                         const Pose& T_base_lidar)
    : config_(config),
      network_(std::move(network)),
      T_base_lidar_(T_base_lidar),
      schedule_(0, config.rate_hz, config.tolerance_s),
      worker_([this] { work(); }) {}

LiveLabeler::~LiveLabeler() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

bool LiveLabeler::mayStart() const {
  return schedule_.next().has_value() && Clock::now() >= next_start_;
}

void LiveLabeler::work() {
  std::unique_lock<std::mutex> lock(mutex_);
  const double threads = std::max(1, config_.threads);
  while (true) {
    // Wakes for a picture, and at the end of its rest when one waits.
    while (!stopping_ && !mayStart()) {
      if (schedule_.next())
        wake_.wait_until(lock, next_start_);
      else
        wake_.wait(lock);
    }
    if (stopping_) return;
    const size_t k = *schedule_.next();
    PendingPicture picture = schedule_.take(k);
    const std::string what = what_ + ", camera " + std::to_string(k);
    busy_ = true;
    lock.unlock();
    const Clock::time_point start = Clock::now();
    Image labels;
    std::exception_ptr failure;
    try {
      labels = network_(picture.rgb, what);
    } catch (...) {
      failure = std::current_exception();
    }
    const double d = std::chrono::duration<double>(Clock::now() - start).count();
    lock.lock();
    busy_ = false;
    if (failure) {
      failure_ = failure;
      idle_.notify_all();
      return;  // the network refused a picture: it will refuse the next ones too
    }
    ++stats_.network_runs;
    stats_.network_ms += d * 1e3;
    stats_.busy_core_s += d * threads;
    if (config_.budget_cores > 0)
      next_start_ = start + std::chrono::duration_cast<Clock::duration>(
                                std::chrono::duration<double>(d * threads / config_.budget_cores));
    schedule_.deliver(picture, std::move(labels), 0.0);
    idle_.notify_all();
  }
}

void LiveLabeler::label(Frame& frame, const std::string& what) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (failure_) std::rethrow_exception(std::exchange(failure_, nullptr));
  const std::vector<size_t> cameras = camerasToLabel(frame, config_, stats_);
  if (cameras.empty()) return;
  frame.camera_semantics = true;
  if (schedule_.cameras() < frame.cameras.size())
    schedule_ = LabelSchedule(frame.cameras.size(), config_.rate_hz, config_.tolerance_s);
  if (!started_) first_ = Clock::now();
  started_ = true;
  const Pose T_odom_lidar = frame.T_odom_base * T_base_lidar_;
  for (size_t k : cameras)
    schedule_.offer(k, frame.timestamp_s, frame.cameras[k].rgb, T_odom_lidar);
  what_ = what;
  wake_.notify_all();
  const AttachCounts counts = schedule_.attach(frame, cameras, T_odom_lidar);
  stats_.own += counts.own;
  stats_.reused += counts.earlier;
  stats_.unlabelled += counts.unlabelled;
}

LabelingStats LiveLabeler::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  LabelingStats s = stats_;
  if (started_) s.span_s = std::chrono::duration<double>(Clock::now() - first_).count();
  return s;
}

void LiveLabeler::waitIdle() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return failure_ || (!busy_ && !schedule_.next()); });
}

}  // namespace semsegmap
