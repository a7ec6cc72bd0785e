#include "semsegmap/semantics/class_map.h"

#include <stdexcept>

namespace semsegmap {

ClassMap::ClassMap(std::string name, std::vector<ClassMapEntry> entries)
    : name_(std::move(name)), entries_(std::move(entries)) {
  for (const auto& e : entries_) {
    if (e.source_id < 0 || e.source_id > 65535)
      throw std::invalid_argument("class map " + name_ + ": source id " +
                                  std::to_string(e.source_id) + " is outside 0..65535");
    if (static_cast<size_t>(e.source_id) >= target_by_id_.size())
      target_by_id_.resize(static_cast<size_t>(e.source_id) + 1, -1);
    if (target_by_id_[e.source_id] >= 0)
      throw std::invalid_argument("class map " + name_ + ": source id " +
                                  std::to_string(e.source_id) + " is listed twice");
    target_by_id_[e.source_id] = e.target;
  }
}

ClassMap ClassMap::Identity(const ClassTable& classes) {
  std::vector<ClassMapEntry> entries;
  for (const auto& c : classes.classes()) entries.push_back({c.id, c.name, c.id});
  return ClassMap("semsegmap", std::move(entries));
}

std::optional<ClassId> ClassMap::find(int source_id) const {
  if (source_id < 0 || static_cast<size_t>(source_id) >= target_by_id_.size() ||
      target_by_id_[source_id] < 0)
    return std::nullopt;
  return static_cast<ClassId>(target_by_id_[source_id]);
}

std::optional<int> ClassMap::firstMissing(int n) const {
  for (int id = 0; id < n; ++id)
    if (!find(id)) return id;
  return std::nullopt;
}

Image mapLabelImage(const Image& source, const ClassMap& map, const std::string& what) {
  if (source.channels != 1)
    throw std::runtime_error(what + ": a label image has 1 channel, this one has " +
                             std::to_string(source.channels));
  // The project's ids fit 8 bits (label images are 8-bit PNGs); a map to a larger id cannot be
  // stored, so it is refused here rather than wrapped around.
  int32_t lut[256];
  for (int id = 0; id < 256; ++id) {
    const std::optional<ClassId> to = map.find(id);
    lut[id] = to && *to < 256 ? static_cast<int32_t>(*to) : -1;
  }
  Image out(source.width, source.height, 1);
  for (size_t i = 0; i < source.data.size(); ++i) {
    const int32_t to = lut[source.data[i]];
    if (to < 0) {
      const size_t x = i % static_cast<size_t>(source.width), y = i / source.width;
      throw std::runtime_error(what + ": pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                               ") has class id " + std::to_string(source.data[i]) +
                               ", which class map " + map.name() + " does not list");
    }
    out.data[i] = static_cast<uint8_t>(to);
  }
  return out;
}

}  // namespace semsegmap
