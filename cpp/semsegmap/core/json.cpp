#include "semsegmap/core/json.h"

#include "semsegmap/core/atomic_file.h"

namespace semsegmap {

std::string jsonText(const nlohmann::ordered_json& json) {
  return json.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) + "\n";
}

void writeJsonAtomically(const std::filesystem::path& path, const nlohmann::ordered_json& json) {
  writeBytesAtomically(path, jsonText(json));
}

}  // namespace semsegmap
