// A class map: what the class ids of a segmentation network (or of label images written by
// another tool) mean among the project's classes (core/class_table.h). Networks speak their
// training set's ids (Cityscapes' 19 training classes, ADE20K's 150); read as the project's own
// ids, Cityscapes' road (0) would silently become unknown. So every foreign id goes through a
// map, and an id the map does not list is an error, never a default.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/image.h"

namespace semsegmap {

struct ClassMapEntry {
  int source_id = 0;        // the network's output channel, or the foreign label value
  std::string source_name;  // its name in the source's class list (documentation, errors)
  ClassId target = cls::kUnknown;
};

class ClassMap {
 public:
  ClassMap() = default;
  // Throws std::invalid_argument naming the map when a source id is negative, above 65535 or
  // listed twice.
  ClassMap(std::string name, std::vector<ClassMapEntry> entries);
  // The project's own ids, each to itself: label images already in the project's classes.
  static ClassMap Identity(const ClassTable& classes);

  const std::string& name() const { return name_; }
  const std::vector<ClassMapEntry>& entries() const { return entries_; }
  std::optional<ClassId> find(int source_id) const;
  // The first of the source ids 0 .. n-1 that the map does not list; nothing when it lists all.
  std::optional<int> firstMissing(int n) const;

 private:
  std::string name_;
  std::vector<ClassMapEntry> entries_;
  std::vector<int32_t> target_by_id_;  // -1: not listed
};

// A label image (1 channel) in the source's ids, turned into the project's ids. Throws
// std::runtime_error "<what>: pixel (x, y) has class id N, which class map M does not list".
Image mapLabelImage(const Image& source, const ClassMap& map, const std::string& what);

}  // namespace semsegmap
