// The code blocks of the project's Markdown files, for the tests that run what the README and
// docs show as they show it.
#pragma once

#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "command_result.h"

namespace semsegmap::test_support {

// The code blocks of a Markdown file, each as its lines with `\` continuations joined.
inline std::vector<std::vector<std::string>> codeBlocks(const std::filesystem::path& file) {
  std::istringstream text(readFile(file));
  std::vector<std::vector<std::string>> blocks;
  bool inside = false;
  std::string pending;
  for (std::string l; std::getline(text, l);) {
    if (l.rfind("```", 0) == 0) {
      if (!inside) blocks.emplace_back();
      inside = !inside;
      continue;
    }
    if (!inside) continue;
    if (!l.empty() && l.back() == '\\') {
      pending += l.substr(0, l.size() - 1) + " ";
      continue;
    }
    blocks.back().push_back(pending + l);
    pending.clear();
  }
  return blocks;
}

// The first code block of `file` with a line containing `needle`; fails the test when none has.
inline std::vector<std::string> blockContaining(const std::filesystem::path& file,
                                                const std::string& needle) {
  for (const std::vector<std::string>& block : codeBlocks(file))
    for (const std::string& line : block)
      if (line.find(needle) != std::string::npos) return block;
  throw std::runtime_error(file.string() + ": no code block shows '" + needle + "'");
}

}  // namespace semsegmap::test_support
