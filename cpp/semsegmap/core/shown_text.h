// Text read from a file, as an error message shows it: every error is one line, so control
// characters (a newline in a corrupt name) are escaped as \xNN, and a long value is cut.
#pragma once

#include <cstdio>
#include <sstream>
#include <string>
#include <string_view>

namespace semsegmap {

inline std::string shownText(std::string_view text, size_t max_chars = 80) {
  std::string out;
  for (const char c : text.substr(0, max_chars)) {
    const auto byte = static_cast<unsigned char>(c);
    if (byte >= 0x20 && byte != 0x7f) {
      out += c;
    } else {
      char escaped[5];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out += escaped;
    }
  }
  if (text.size() > max_chars) out += "...";
  return out;
}

// A number as a stream prints it (6 significant digits: 10, 0.1, 1e+308): std::to_string's
// fixed six decimals read badly in a message.
inline std::string shownNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

}  // namespace semsegmap
