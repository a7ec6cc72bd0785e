// A one-line progress bar on stderr (only when stderr is a terminal or CI wants it).
#pragma once

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

namespace semsegmap::app {

class Progress {
 public:
  Progress(std::string label, size_t total)
      : label_(std::move(label)), total_(total), start_(std::chrono::steady_clock::now()) {}
  void update(size_t done, size_t total) {
    total_ = total;
    update(done);
  }
  void update(size_t done) {
    const double elapsed = seconds();
    if (done < total_ && elapsed - last_ < 0.5) return;
    last_ = elapsed;
    const double frac = total_ ? static_cast<double>(done) / total_ : 1.0;
    const int width = 30;
    const int filled = static_cast<int>(frac * width);
    const double left = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
    std::fprintf(stderr, "\r%s [%s%s] %zu/%zu  %.0f s, %.0f s left   ", label_.c_str(),
                 std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), done,
                 total_, elapsed, left);
    if (done >= total_) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::string label_;
  size_t total_;
  std::chrono::steady_clock::time_point start_;
  double last_ = -1.0;
};

// One bar per stage of a longer job (an ExperimentProgress): a new bar when the stage changes.
class StageProgress {
 public:
  void operator()(const std::string& stage, size_t done, size_t total) {
    if (!bar_ || stage != stage_) {
      stage_ = stage;
      bar_ = std::make_unique<Progress>(stage, total);
    }
    bar_->update(done, total);
  }

 private:
  std::string stage_;
  std::unique_ptr<Progress> bar_;
};

}  // namespace semsegmap::app
