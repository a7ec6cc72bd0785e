// A request to stop a run between frames, given by the caller: the library's frame loops check
// it before each frame and end early, with the frames done whole. The library never installs a
// signal handler itself (that is process-wide state a program decides on); a program that wants
// Ctrl-C to end a run cleanly sets the flag from its own handler (apps/semsegmap/interrupt.h).
#pragma once

#include <atomic>

namespace semsegmap {

// A cheap value that points at the caller's flag; a default one never asks to stop. The flag
// must outlive every copy. std::atomic<bool> is lock-free, so a signal handler may set it.
class StopToken {
 public:
  StopToken() = default;
  explicit StopToken(const std::atomic<bool>& flag) : flag_(&flag) {}
  bool stopRequested() const { return flag_ != nullptr && flag_->load(std::memory_order_relaxed); }

 private:
  static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler sets the flag");
  const std::atomic<bool>* flag_ = nullptr;
};

}  // namespace semsegmap
