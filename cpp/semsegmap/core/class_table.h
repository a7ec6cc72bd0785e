// The semantic classes every stage speaks: id, name, display color and the two flags the local
// map filters on (dynamic objects and ground).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace semsegmap {

using ClassId = uint16_t;

struct SemanticClass {
  ClassId id = 0;
  std::string name;
  std::array<uint8_t, 3> color_rgb{0, 0, 0};
  bool dynamic = false;
  bool ground = false;
};

// Ids of the default table, fixed so that label images and files stay comparable across runs.
namespace cls {
constexpr ClassId kUnknown = 0;
constexpr ClassId kRoad = 1;
constexpr ClassId kSidewalk = 2;
constexpr ClassId kTerrain = 3;
constexpr ClassId kBuilding = 4;
constexpr ClassId kRoof = 5;
constexpr ClassId kFence = 6;
constexpr ClassId kVegetation = 7;
constexpr ClassId kTrunk = 8;
constexpr ClassId kPole = 9;
constexpr ClassId kTrafficSign = 10;
constexpr ClassId kCar = 11;
constexpr ClassId kPerson = 12;
constexpr ClassId kOther = 13;
constexpr ClassId kSky = 14;

// How segmentation networks are wrong about the default table, shared by the simulator's label
// noise and the descriptors' training augmentation so that both mimic the same errors. The
// class a confused region takes: walls, fences and hedges, terrain and sidewalks, roofs and
// walls are what networks mix up; `pick` chooses between two partners. A class without a
// partner is returned as it is.
ClassId confusionPartner(ClassId c, bool pick);
// Poles, signs and trunks: what a network misses and labels as what is behind it.
bool isThin(ClassId c);
}  // namespace cls

class ClassTable {
 public:
  ClassTable() = default;
  // Takes ownership of the classes; ids must be unique and names non-empty.
  explicit ClassTable(std::vector<SemanticClass> classes);

  // The table of the built-in simulator, also used for converted real data.
  static ClassTable Default();

  const std::vector<SemanticClass>& classes() const { return classes_; }
  bool contains(ClassId id) const;
  // Throws std::out_of_range naming the id when it is not in the table.
  const SemanticClass& at(ClassId id) const;
  std::optional<ClassId> find(const std::string& name) const;

  bool operator==(const ClassTable& other) const;

 private:
  std::vector<SemanticClass> classes_;
};

}  // namespace semsegmap
