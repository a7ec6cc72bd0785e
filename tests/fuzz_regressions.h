// The inputs the fuzz harnesses (fuzz/) found, kept as hex under tests/fuzz_regressions/<harness>/
// (whitespace ignored, as `xxd -p` writes it; an empty file is an empty input): each test suite
// runs its parsers' reproducers through the same call as the harness and expects what the harness
// expects, a one-line std::exception that names the file.
#pragma once

#include <gtest/gtest.h>

#include <cctype>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace semsegmap::test_support {

inline std::string bytesOfHex(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::string hex, bytes;
  for (char c; in.get(c);)
    if (std::isxdigit(static_cast<unsigned char>(c))) hex += c;
  for (size_t i = 0; i + 1 < hex.size(); i += 2)
    bytes += static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16));
  return bytes;
}

// (file name, bytes) of every reproducer of `harness`.
inline std::vector<std::pair<std::string, std::string>> fuzzRegressions(
    const std::string& harness) {
  const std::filesystem::path dir =
      std::filesystem::path(SEMSEGMAP_SOURCE_DIR) / "tests/fuzz_regressions" / harness;
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (entry.path().extension() == ".hex")
      out.emplace_back(entry.path().filename().string(), bytesOfHex(entry.path()));
  EXPECT_FALSE(out.empty()) << "no reproducers in " << dir;
  return out;
}

// `parse` may take the input (a finding that was a hang or a crash on a valid file); when it
// refuses it, with one line that contains `names`.
template <typename Parse>
void expectNoFinding(const std::string& reproducer, const std::string& names, Parse&& parse) {
  try {
    parse();
  } catch (const std::exception& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << reproducer << ": " << message;
    EXPECT_NE(message.find(names), std::string::npos) << reproducer << ": " << message;
  }
}

// `parse` must refuse the input, with one line that contains `names`.
template <typename Parse>
void expectCleanRefusal(const std::string& reproducer, const std::string& names, Parse&& parse) {
  try {
    parse();
    ADD_FAILURE() << reproducer << ": accepted";
  } catch (const std::exception& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << reproducer << ": " << message;
    EXPECT_NE(message.find(names), std::string::npos) << reproducer << ": " << message;
  }
}

}  // namespace semsegmap::test_support
