// The one JSON detail every writer of results needs: a string literal with its quotes escaped.
#pragma once

#include <string>

namespace semsegmap {

inline std::string jsonQuoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out + "\"";
}

}  // namespace semsegmap
