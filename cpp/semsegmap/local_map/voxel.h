// One voxel of the local map: what every point that fell into it says, fused.
#pragma once

#include <array>
#include <cstdint>
#include <utility>

#include <Eigen/Core>

#include "semsegmap/core/class_table.h"

namespace semsegmap {

using VoxelKey = uint64_t;  // three 21-bit signed grid indices packed

VoxelKey packVoxelKey(const Eigen::Vector3i& index);
Eigen::Vector3i unpackVoxelKey(VoxelKey key);

// Vote counts for a few labels in a voxel (classes, or ground-truth instances). Counts are 32-bit,
// so they never overflow in practice. When more distinct labels arrive than there are slots,
// the Misra-Gries rule (decrement all, free the zeros) keeps every label that holds more than
// 1 / (kSlots + 1) of the votes, so the majority is always right.
template <typename Label, int kSlots>
class Votes {
 public:
  void add(Label label, uint32_t count = 1);
  // The label with most votes (0 / default when empty) and its count.
  std::pair<Label, uint32_t> majority() const;
  uint32_t countOf(Label label) const;

 private:
  std::array<Label, kSlots> labels_{};
  std::array<uint32_t, kSlots> counts_{};
};

struct Voxel {
  uint32_t n_points = 0;
  Eigen::Vector3f centroid = Eigen::Vector3f::Zero();  // running mean, map frame
  // Colour: hue as a running mean of unit vectors on the hue circle (so 0.95 and 0.05 average
  // to 0.0, not 0.5), saturation and value as plain running means, over coloured points only.
  uint32_t n_colored = 0;
  float hue_cos = 0, hue_sin = 0, saturation = 0, value = 0;
  Votes<ClassId, 4> classes;     // of the points that came with a class (has_class)
  Votes<uint16_t, 3> instances;  // ground truth, when known
  uint32_t n_classified = 0;     // points that came with a class, dynamic ones included
  uint32_t n_dynamic = 0;        // points of dynamic classes (counted, not voted: DynamicRemoval)
  uint32_t pending_scan = 0;     // the update that last considered it for activation (1-based)
  bool active = false;

  float hue() const;  // in [0, 1)
  // False while no point of it came with a static class: it is unobserved, and semanticClass()
  // (then cls::kUnknown) means nothing. Votes of earlier frames stay, so a voxel keeps the class
  // a camera gave it after it has left the picture.
  bool hasClass() const { return classes.majority().second > 0; }
  ClassId semanticClass() const { return classes.majority().first; }
};

// ---- implementation of the small template ----

template <typename Label, int kSlots>
void Votes<Label, kSlots>::add(Label label, uint32_t count) {
  for (int k = 0; k < kSlots; ++k)
    if (counts_[k] > 0 && labels_[k] == label) {
      counts_[k] += count;
      return;
    }
  for (int k = 0; k < kSlots; ++k)
    if (counts_[k] == 0) {
      labels_[k] = label;
      counts_[k] = count;
      return;
    }
  uint32_t smallest = count;
  for (int k = 0; k < kSlots; ++k) smallest = std::min(smallest, counts_[k]);
  for (int k = 0; k < kSlots; ++k) counts_[k] -= smallest;
  if (count > smallest)
    for (int k = 0; k < kSlots; ++k)
      if (counts_[k] == 0) {
        labels_[k] = label;
        counts_[k] = count - smallest;
        return;
      }
}

template <typename Label, int kSlots>
std::pair<Label, uint32_t> Votes<Label, kSlots>::majority() const {
  std::pair<Label, uint32_t> best{Label{}, 0};
  for (int k = 0; k < kSlots; ++k)
    if (counts_[k] > best.second) best = {labels_[k], counts_[k]};
  return best;
}

template <typename Label, int kSlots>
uint32_t Votes<Label, kSlots>::countOf(Label label) const {
  for (int k = 0; k < kSlots; ++k)
    if (counts_[k] > 0 && labels_[k] == label) return counts_[k];
  return 0;
}

}  // namespace semsegmap
