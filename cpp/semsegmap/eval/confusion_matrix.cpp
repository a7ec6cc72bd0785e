#include "semsegmap/eval/confusion_matrix.h"

namespace semsegmap {

namespace {
uint32_t keyOf(ClassId truth, ClassId predicted) {
  return static_cast<uint32_t>(truth) << 16 | predicted;
}
ClassId truthOf(uint32_t key) {
  return static_cast<ClassId>(key >> 16);
}
ClassId predictedOf(uint32_t key) {
  return static_cast<ClassId>(key & 0xffff);
}
}  // namespace

void ConfusionMatrix::add(ClassId truth, ClassId predicted, size_t n) {
  if (n > 0) counts_[keyOf(truth, predicted)] += n;
}

ConfusionMatrix& ConfusionMatrix::operator+=(const ConfusionMatrix& o) {
  for (const auto& [key, n] : o.counts_) counts_[key] += n;
  return *this;
}

size_t ConfusionMatrix::count(ClassId truth, ClassId predicted) const {
  const auto it = counts_.find(keyOf(truth, predicted));
  return it == counts_.end() ? 0 : it->second;
}

size_t ConfusionMatrix::truthCount(ClassId c) const {
  size_t sum = 0;
  for (const auto& [key, n] : counts_) sum += truthOf(key) == c ? n : 0;
  return sum;
}

size_t ConfusionMatrix::predictedCount(ClassId c) const {
  size_t sum = 0;
  for (const auto& [key, n] : counts_) sum += predictedOf(key) == c ? n : 0;
  return sum;
}

size_t ConfusionMatrix::total() const {
  size_t sum = 0;
  for (const auto& [key, n] : counts_) sum += n;
  return sum;
}

size_t ConfusionMatrix::correct() const {
  size_t sum = 0;
  for (const auto& [key, n] : counts_) sum += truthOf(key) == predictedOf(key) ? n : 0;
  return sum;
}

double ConfusionMatrix::iou(ClassId c) const {
  const size_t tp = count(c, c);
  const size_t union_ = truthCount(c) + predictedCount(c) - tp;
  return union_ ? static_cast<double>(tp) / static_cast<double>(union_) : -1.0;
}

}  // namespace semsegmap
