// What every harness shares: the parsers read files, so each input is written to a file of its
// own folder (one per process, removed at exit), and the parser is called on it. A parser may
// refuse the input only with a one-line std::exception that names the file; anything else (a
// crash, a sanitizer report, std::bad_alloc, a multi-line or anonymous message) ends the run, so
// that libFuzzer keeps the input as a finding.
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <new>
#include <string>
#include <string_view>

#include "semsegmap/core/binary_io.h"

namespace semsegmap::fuzz {

class ScratchDir {
 public:
  ScratchDir()
      : path_(std::filesystem::temp_directory_path() /
              ("semsegmap_fuzz_" + std::to_string(::getpid()))) {
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

inline const std::filesystem::path& scratch() {
  static ScratchDir dir;
  return dir.path();
}

inline std::filesystem::path writeInput(const std::string& name, std::string_view bytes) {
  const std::filesystem::path path = scratch() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());
  return path;
}

inline std::string_view asText(const uint8_t* data, size_t size) {
  return std::string_view(reinterpret_cast<const char*>(data), size);
}

// The input split at the first `separator` (the rest empty when there is none): for harnesses
// whose parser reads two files.
inline std::pair<std::string_view, std::string_view> splitAt(std::string_view input,
                                                             std::string_view separator) {
  const size_t at = input.find(separator);
  if (at == std::string_view::npos) return {input, {}};
  return {input.substr(0, at), input.substr(at + separator.size())};
}

// The input with the checksum of the formats that end in one (core/binary_io.h) appended: the
// harnesses of those formats fuzz what comes after the check, which a mutated file would fail.
inline std::string withChecksum(std::string_view body) {
  std::string bytes(body);
  const uint64_t sum = fnv1a64(bytes.data(), bytes.size(), kProjectFnvSeed);
  bytes.append(reinterpret_cast<const char*>(&sum), sizeof sum);
  return bytes;
}

[[noreturn]] inline void finding(const std::string& what) {
  std::fprintf(stderr, "semsegmap fuzz finding: %s\n", what.c_str());
  std::abort();
}

// Runs `parse`; a refusal must be a one-line std::exception whose message contains `names`
// (the file's name, or what the parser is told the input is).
template <typename Parse>
void expectCleanRefusal(const std::string& names, Parse&& parse) {
  try {
    parse();
  } catch (const std::bad_alloc&) {
    finding("std::bad_alloc: a size read from the input was allocated unchecked");
  } catch (const std::exception& e) {
    const std::string message = e.what();
    if (message.find('\n') != std::string::npos) finding("a multi-line error message: " + message);
    if (message.find(names) == std::string::npos)
      finding("an error that does not name " + names + ": " + message);
  }
}

}  // namespace semsegmap::fuzz
