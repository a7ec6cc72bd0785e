#include "semsegmap/core/class_table.h"

#include <set>
#include <stdexcept>

namespace semsegmap {

ClassTable::ClassTable(std::vector<SemanticClass> classes) : classes_(std::move(classes)) {
  std::set<ClassId> ids;
  for (const auto& c : classes_) {
    if (c.name.empty())
      throw std::invalid_argument("class table: class " + std::to_string(c.id) + " has no name");
    if (!ids.insert(c.id).second)
      throw std::invalid_argument("class table: id " + std::to_string(c.id) + " appears twice");
  }
}

ClassTable ClassTable::Default() {
  // Display colors follow the SemanticKITTI palette where a class exists there, so pictures of
  // simulated and real data read the same.
  return ClassTable({
      {cls::kUnknown, "unknown", {0, 0, 0}, false, false},
      {cls::kRoad, "road", {255, 0, 255}, false, true},
      {cls::kSidewalk, "sidewalk", {75, 0, 75}, false, true},
      {cls::kTerrain, "terrain", {150, 240, 80}, false, true},
      {cls::kBuilding, "building", {255, 200, 0}, false, false},
      {cls::kRoof, "roof", {200, 80, 30}, false, false},
      {cls::kFence, "fence", {255, 120, 50}, false, false},
      {cls::kVegetation, "vegetation", {0, 175, 0}, false, false},
      {cls::kTrunk, "trunk", {135, 60, 0}, false, false},
      {cls::kPole, "pole", {255, 240, 150}, false, false},
      {cls::kTrafficSign, "traffic-sign", {255, 0, 0}, false, false},
      {cls::kCar, "car", {100, 150, 245}, true, false},
      {cls::kPerson, "person", {30, 30, 255}, true, false},
      {cls::kOther, "other", {120, 120, 120}, false, false},
      {cls::kSky, "sky", {170, 210, 255}, false, false},
  });
}

bool ClassTable::contains(ClassId id) const {
  for (const auto& c : classes_)
    if (c.id == id) return true;
  return false;
}

const SemanticClass& ClassTable::at(ClassId id) const {
  for (const auto& c : classes_)
    if (c.id == id) return c;
  throw std::out_of_range("class id " + std::to_string(id) + " is not in the class table");
}

std::optional<ClassId> ClassTable::find(const std::string& name) const {
  for (const auto& c : classes_)
    if (c.name == name) return c.id;
  return std::nullopt;
}

bool ClassTable::operator==(const ClassTable& other) const {
  if (classes_.size() != other.classes_.size()) return false;
  for (size_t i = 0; i < classes_.size(); ++i) {
    const auto& a = classes_[i];
    const auto& b = other.classes_[i];
    if (a.id != b.id || a.name != b.name || a.color_rgb != b.color_rgb || a.dynamic != b.dynamic ||
        a.ground != b.ground)
      return false;
  }
  return true;
}

namespace cls {

ClassId confusionPartner(ClassId c, bool pick) {
  switch (c) {
    case kFence:
      return pick ? kBuilding : kVegetation;
    case kBuilding:
      return kFence;
    case kVegetation:
      return kFence;
    case kTerrain:
      return kSidewalk;
    case kSidewalk:
      return kTerrain;
    case kRoof:
      return kBuilding;
    default:
      return c;
  }
}

bool isThin(ClassId c) {
  return c == kPole || c == kTrafficSign || c == kTrunk;
}

}  // namespace cls

}  // namespace semsegmap
