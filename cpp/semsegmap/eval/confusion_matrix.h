// Counts of (ground-truth class, predicted class) pairs: what both ways of measuring labels share,
// pixels of a label image (eval labels) and classified LiDAR points (eval semantics). Per-class
// IoU and accuracy follow from it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>

#include "semsegmap/core/class_table.h"

namespace semsegmap {

class ConfusionMatrix {
 public:
  void add(ClassId truth, ClassId predicted, size_t n = 1);
  ConfusionMatrix& operator+=(const ConfusionMatrix& o);
  size_t count(ClassId truth, ClassId predicted) const;
  size_t truthCount(ClassId c) const;      // pairs whose truth is c
  size_t predictedCount(ClassId c) const;  // pairs predicted as c
  size_t total() const;
  size_t correct() const;  // pairs whose prediction is their truth
  // TP / (TP + FP + FN) of a class; -1 when the class is in neither truth nor prediction.
  double iou(ClassId c) const;

 private:
  // Keyed by truth << 16 | predicted. Sparse: a table's ids can be large (16 bits) while a
  // frame meets a few classes, and eval semantics keeps two matrices per frame.
  std::map<uint32_t, size_t> counts_;
};

}  // namespace semsegmap
