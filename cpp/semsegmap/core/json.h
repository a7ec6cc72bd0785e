// Results and summaries are JSON, built with nlohmann::ordered_json (keys stay in the order they
// are set, so a file reads top-down as its writer builds it) and laid out by one function.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace semsegmap {

// The text of a JSON file: a 2-space indent and a final newline. Bytes of strings that are not
// valid UTF-8 are replaced rather than failing the write.
std::string jsonText(const nlohmann::ordered_json& json);

// jsonText(json), written atomically (core/atomic_file.h).
void writeJsonAtomically(const std::filesystem::path& path, const nlohmann::ordered_json& json);

// A value the run does not know (an error without ground truth, a mean of nothing) is null in
// every result file: a zero there would read as a measurement.
template <class T>
nlohmann::ordered_json orNull(const std::optional<T>& value) {
  return value ? nlohmann::ordered_json(*value) : nlohmann::ordered_json(nullptr);
}

}  // namespace semsegmap
