#include "semsegmap/pipeline/live_session.h"

#include <algorithm>
#include <utility>

namespace semsegmap {

LiveSession::LiveSession(const LiveConfig& config, Process process)
    : config_(config), process_(std::move(process)), assembler_(config.assembly) {
  if (config.max_queued_frames == 0)
    throw std::invalid_argument("live session: max_queued_frames must be at least 1");
  worker_ = std::thread([this] { work(); });
}

LiveSession::~LiveSession() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stopping_ = true;
  }
  queued_.notify_all();
  room_.notify_all();
  if (worker_.joinable()) worker_.join();
}

void LiveSession::rethrow() {
  std::lock_guard<std::mutex> lock(queue_mutex_);
  if (failure_) std::rethrow_exception(failure_);
}

void LiveSession::addScan(ScanMessage scan) {
  rethrow();
  std::vector<Frame> ready;
  {
    std::lock_guard<std::mutex> lock(in_mutex_);
    if (finished_) throw std::logic_error("live session: a scan after finish()");
    arrivals_.emplace_back(scan.stamp_s, Clock::now());
    assembler_.addScan(std::move(scan));
    ready = assembler_.takeReady();
  }
  enqueue(std::move(ready));
}

void LiveSession::addPicture(size_t camera, PictureMessage picture) {
  rethrow();
  std::vector<Frame> ready;
  {
    std::lock_guard<std::mutex> lock(in_mutex_);
    assembler_.addPicture(camera, std::move(picture));
    ready = assembler_.takeReady();
  }
  enqueue(std::move(ready));
}

void LiveSession::addOdometry(const StampedPose& odometry) {
  rethrow();
  std::vector<Frame> ready;
  {
    std::lock_guard<std::mutex> lock(in_mutex_);
    assembler_.addOdometry(odometry);
    ready = assembler_.takeReady();
  }
  enqueue(std::move(ready));
}

void LiveSession::addFrame(Frame frame) {
  rethrow();
  std::vector<Frame> one;
  one.push_back(std::move(frame));
  enqueue(std::move(one));
}

void LiveSession::enqueue(std::vector<Frame> frames) {
  for (Frame& frame : frames) {
    Clock::time_point arrival = Clock::now();
    {
      // The frame's scan arrived before it was made: its entry is among the first.
      std::lock_guard<std::mutex> lock(in_mutex_);
      while (!arrivals_.empty() && arrivals_.front().first < frame.timestamp_s)
        arrivals_.pop_front();
      if (!arrivals_.empty() && arrivals_.front().first == frame.timestamp_s) {
        arrival = arrivals_.front().second;
        arrivals_.pop_front();
      }
    }
    std::unique_lock<std::mutex> lock(queue_mutex_);
    // A worker that failed works on nothing more: waiting for room would never end.
    if (config_.never_drop)
      room_.wait(
          lock, [&] { return queue_.size() < config_.max_queued_frames || stopping_ || failure_; });
    if (failure_) std::rethrow_exception(failure_);
    if (queue_.size() >= config_.max_queued_frames) {
      queue_.pop_front();
      ++stats_.dropped;
    }
    queue_.push_back({std::move(frame), arrival});
    stats_.max_queued = std::max(stats_.max_queued, queue_.size());
    lock.unlock();
    queued_.notify_one();
  }
}

void LiveSession::work() {
  for (;;) {
    Queued next;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queued_.wait(lock, [&] { return !queue_.empty() || closing_ || stopping_; });
      if (stopping_ || queue_.empty()) return;  // stopped, or closed and worked off
      next = std::move(queue_.front());
      queue_.pop_front();
    }
    room_.notify_one();
    std::vector<LivePose> poses;
    try {
      poses = process_(next.frame);
    } catch (...) {
      {
        std::lock_guard<std::mutex> lock(queue_mutex_);
        failure_ = std::current_exception();
      }
      room_.notify_all();
      return;
    }
    const double ms =
        std::chrono::duration<double, std::milli>(Clock::now() - next.arrival).count();
    std::lock_guard<std::mutex> lock(queue_mutex_);
    ++stats_.processed;
    latency_sum_ms_ += ms;
    stats_.max_latency_ms = std::max(stats_.max_latency_ms, ms);
    for (LivePose& p : poses) {
      p.latency_ms = ms;
      out_.push_back(std::move(p));
      ++stats_.localized;
    }
  }
}

void LiveSession::finish() {
  std::vector<Frame> rest;
  {
    std::lock_guard<std::mutex> lock(in_mutex_);
    if (finished_) throw std::logic_error("live session: finish() twice");
    finished_ = true;
    rest = assembler_.flush();
  }
  enqueue(std::move(rest));
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    closing_ = true;
  }
  queued_.notify_all();
  if (worker_.joinable()) worker_.join();
  rethrow();
}

std::vector<LivePose> LiveSession::poll() {
  rethrow();
  std::lock_guard<std::mutex> lock(queue_mutex_);
  return std::exchange(out_, {});
}

LiveStats LiveSession::stats() const {
  LiveStats s;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    s = stats_;
    s.mean_latency_ms = s.processed > 0 ? latency_sum_ms_ / static_cast<double>(s.processed) : 0;
  }
  std::lock_guard<std::mutex> lock(in_mutex_);
  s.assembly = assembler_.stats();
  return s;
}

LiveSession::Process localizingProcess(LocalizationSession& session) {
  return [&session](const Frame& frame) {
    std::optional<LocalizationRecord> found = session.process(frame);
    std::vector<LivePose> out;
    if (!found) return out;
    LivePose p;
    p.record = std::move(*found);
    p.T_odom_base = session.run().trajectory_odom.back();
    p.T_map_odom = p.record.T_map_base * p.T_odom_base.inverse();
    out.push_back(std::move(p));
    return out;
  };
}

}  // namespace semsegmap
