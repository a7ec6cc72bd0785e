// What a command run by a test gave back: its exit code and its two outputs (each written to a
// file, so that neither is a terminal), shared by the tests that run the built binary.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace semsegmap::test_support {

struct Result {
  int code = -1;
  std::string out, err;
};

inline std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace semsegmap::test_support
