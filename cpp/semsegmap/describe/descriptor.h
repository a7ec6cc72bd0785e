// Segment descriptors (paper section III-C): one interface, batched, for the learned SemSegMap
// network, the SegMap CNN baseline, the eigenvalue and FPFH baselines, and 3DSmoothNet's local
// descriptors as a bag of words (the paper's fourth baseline).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/segment/segment.h"

namespace semsegmap {

enum class DescriptorKind { kEigen, kFpfh, kSegMapCnn, kSemSegMapNet, kSmoothNetBow };

// "eigen", "fpfh", "segmap-cnn", "semsegmap-net", "3dsmoothnet"; parse throws
// std::invalid_argument.
std::string descriptorName(DescriptorKind kind);
DescriptorKind parseDescriptorKind(const std::string& name);

// The kinds described by a trained network of a model file (describe/learned_net.h).
inline bool isLearnedDescriptor(DescriptorKind kind) {
  return kind == DescriptorKind::kSemSegMapNet || kind == DescriptorKind::kSegMapCnn ||
         kind == DescriptorKind::kSmoothNetBow;
}

// Why this build cannot describe with `kind`, in one line, or "" when it can: the learned kinds
// need libtorch (the build option SEMSEGMAP_WITH_TORCH), fpfh needs PCL (SEMSEGMAP_WITH_PCL).
// Every kind keeps its name either way, so that maps and model files of any build can be read.
std::string descriptorNotBuilt(DescriptorKind kind);

// What a descriptor sees of a segment observation: its points (map frame, with colour and
// class) and its size in points (the triplet loss weighs pairs by the ratio of the two).
struct DescriptorInput {
  const EnrichedCloud* points = nullptr;
};

class Describer {
 public:
  virtual ~Describer() = default;
  virtual DescriptorKind kind() const = 0;
  virtual int dimension() const = 0;
  // Identifies the exact model (weights) so that a target map built with one model is never
  // queried with descriptors of another; constant for the hand-made descriptors.
  virtual std::string fingerprint() const = 0;
  // One row per input, in order. Thread-compatible: one Describer per thread.
  virtual Eigen::MatrixXf describe(const std::vector<DescriptorInput>& batch) = 0;
};

class DescriptorNetImpl;  // describe/learned_net.h

struct DescriberOptions {
  std::shared_ptr<DescriptorNetImpl> net;  // required for the learned descriptors (loadNet)
  int threads = 0;                         // 0: all cores
  // 3dsmoothnet: keypoints a segment is described at instead of the model's; 0: the model's.
  int smoothnet_keypoints = 0;
};

// Throws std::invalid_argument for a learned kind without a network or with one of another kind,
// std::runtime_error "<kind>: <descriptorNotBuilt>" for a kind this build does not have.
std::unique_ptr<Describer> makeDescriber(DescriptorKind kind, const DescriberOptions& options);

// What a session that describes segments needs: throws std::invalid_argument naming `who` when
// it was given no describer, at construction instead of a null dereference later.
inline const Describer& requireDescriber(const std::shared_ptr<Describer>& describer,
                                         const std::string& who) {
  if (!describer) throw std::invalid_argument(who + ": no describer given (makeDescriber)");
  return *describer;
}

}  // namespace semsegmap
