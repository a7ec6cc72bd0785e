#include "semsegmap/core/diagnostics.h"

#include <algorithm>
#include <atomic>
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

std::atomic<OptionSpelling>& spelling() {
  static std::atomic<OptionSpelling> s{OptionSpelling::kCommandLine};
  return s;
}

}  // namespace

void setOptionSpelling(OptionSpelling s) {
  spelling() = s;
}

std::string optionText(const std::string& name, const std::string& value, bool literal) {
  if (spelling() == OptionSpelling::kCommandLine) return "--" + name + " " + value;
  std::string keyword = name;
  std::replace(keyword.begin(), keyword.end(), '-', '_');
  return keyword + "=" + (literal ? "\"" + value + "\"" : value);
}

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
