#include "semsegmap/core/diagnostics.h"

#include <iostream>
#include <mutex>

namespace semsegmap {
namespace {

std::function<void(const std::string&)>& sink() {
  static std::function<void(const std::string&)> s;
  return s;
}

// Readers may note from worker threads (frames prefetched in parallel): one line at a time.
std::mutex& printing() {
  static std::mutex m;
  return m;
}

void emit(const std::string& line) {
  const std::lock_guard<std::mutex> lock(printing());
  if (sink())
    sink()(line);
  else
    std::cerr << line << "\n" << std::flush;
}

}  // namespace

void note(const std::string& text) {
  emit("note: " + text);
}

void warn(const std::string& text) {
  emit("warning: " + text);
}

void setMessageSink(std::function<void(const std::string& line)> s) {
  const std::lock_guard<std::mutex> lock(printing());
  sink() = std::move(s);
}

}  // namespace semsegmap
