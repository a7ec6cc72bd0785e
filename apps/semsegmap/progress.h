// Progress on stderr. On a terminal one line is redrawn in place ('\r', at most twice a second);
// into a file or a pipe (a log) plain lines are written instead: one each time another tenth of
// the work is done or 30 s have passed, and the final one.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

namespace semsegmap::app {

inline bool stderrIsTerminal() {
  return isatty(fileno(stderr)) != 0;
}

// Whether a progress line is drawn on the terminal and not yet ended: what is printed next on
// stderr (an error) must start on a line of its own, not after the bar.
inline bool& progressLineOpen() {
  static bool open = false;
  return open;
}

// Ends a progress line left open, so that the next message starts at the left margin.
inline void endProgressLine() {
  if (!progressLineOpen()) return;
  std::fputc('\n', stderr);
  progressLineOpen() = false;
}

// When and how a progress line is written; the text is up to its user.
class ProgressLine {
 public:
  explicit ProgressLine(bool terminal = stderrIsTerminal()) : terminal_(terminal) {}

  // Whether to write a line now: `fraction` of the work is done after `elapsed` seconds;
  // `last` is the final update (written once, however often it is reported).
  bool due(double fraction, double elapsed, bool last) {
    if (finished_) return false;
    const int tenth = static_cast<int>(fraction * 10.0);
    bool now = last;
    if (terminal_)
      now |= elapsed - last_time_ >= 0.5;
    else
      now |= tenth > last_tenth_ || elapsed - last_time_ >= 30.0;
    if (!now) return false;
    last_time_ = elapsed;
    last_tenth_ = tenth;
    finished_ = last;
    return true;
  }
  void write(const std::string& text, bool last) const {
    if (terminal_)
      std::fprintf(stderr, "\r%s   %s", text.c_str(), last ? "\n" : "");
    else
      std::fprintf(stderr, "%s\n", text.c_str());
    progressLineOpen() = terminal_ && !last;
    std::fflush(stderr);
  }

 private:
  bool terminal_;
  bool finished_ = false;
  double last_time_ = -1.0;  // the first update draws the line on a terminal
  int last_tenth_ = 0;
};

inline std::string progressBar(double fraction, int width) {
  const int filled = std::max(0, std::min(width, static_cast<int>(fraction * width)));
  return "[" + std::string(filled, '#') + std::string(width - filled, '.') + "]";
}

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
    const double frac = total_ ? static_cast<double>(done) / total_ : 1.0;
    const bool last = done >= total_;
    if (!line_.due(frac, elapsed, last)) return;
    const double left = frac > 0 ? elapsed * (1.0 - frac) / frac : 0.0;
    char numbers[96];
    std::snprintf(numbers, sizeof numbers, " %zu/%zu  %.0f s, %.0f s left", done, total_, elapsed,
                  left);
    line_.write(label_ + " " + progressBar(frac, 30) + numbers, last);
  }
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::string label_;
  size_t total_;
  std::chrono::steady_clock::time_point start_;
  ProgressLine line_;
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
    done_ = done;
    total_ = total;
    started_ = started_ || done > 0;
  }
  // Whether any work was reported done: an experiment stopped before has nothing to keep.
  bool started() const { return started_; }
  // How far it got, for the line of an interrupted run: "in localize S2 at 3 of 10".
  std::string where() const {
    if (stage_.empty()) return "before its first frame";
    return "in " + stage_ + " at " + std::to_string(done_) + " of " + std::to_string(total_);
  }

 private:
  std::string stage_;
  std::unique_ptr<Progress> bar_;
  size_t done_ = 0, total_ = 0;
  bool started_ = false;
};

}  // namespace semsegmap::app
