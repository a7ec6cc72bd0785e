// Shortest decimal text that parses back to exactly `value` (std::to_chars), so that files
// round-trip bit-exactly yet stay readable (0.1, not 0.10000000000000001): meta.yaml and
// frames.csv (io/dataset_format.h), and the settings a map records (pipeline/map_parameters.h),
// where equal text must mean equal values.
#pragma once

#include <charconv>
#include <string>

namespace semsegmap {

inline std::string formatExactDouble(double value) {
  char text[64];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

}  // namespace semsegmap
