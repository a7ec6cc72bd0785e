// Names of the descriptor kinds as they appear in configs, map files and on the command line.
#include <stdexcept>

#include "semsegmap/describe/descriptor.h"

namespace semsegmap {

std::string descriptorName(DescriptorKind kind) {
  switch (kind) {
    case DescriptorKind::kEigen:
      return "eigen";
    case DescriptorKind::kFpfh:
      return "fpfh";
    case DescriptorKind::kSegMapCnn:
      return "segmap-cnn";
    case DescriptorKind::kSemSegMapNet:
      return "semsegmap-net";
    case DescriptorKind::kSmoothNetBow:
      return "3dsmoothnet";
  }
  // Only reachable through a cast of an out-of-range integer.
  throw std::invalid_argument("descriptorName: invalid DescriptorKind value " +
                              std::to_string(static_cast<int>(kind)));
}

DescriptorKind parseDescriptorKind(const std::string& name) {
  for (const DescriptorKind kind :
       {DescriptorKind::kEigen, DescriptorKind::kFpfh, DescriptorKind::kSegMapCnn,
        DescriptorKind::kSemSegMapNet, DescriptorKind::kSmoothNetBow}) {
    if (descriptorName(kind) == name) return kind;
  }
  throw std::invalid_argument("unknown descriptor '" + name +
                              "' (expected eigen, fpfh, segmap-cnn, semsegmap-net or 3dsmoothnet)");
}

std::string descriptorNotBuilt(DescriptorKind kind) {
  switch (kind) {
    case DescriptorKind::kEigen:
      return "";
    case DescriptorKind::kFpfh:
      return SEMSEGMAP_WITH_PCL ? ""
                                : "this build has no FPFH (built without PCL, reconfigure with "
                                  "-DSEMSEGMAP_WITH_PCL=ON)";
    case DescriptorKind::kSegMapCnn:
    case DescriptorKind::kSemSegMapNet:
    case DescriptorKind::kSmoothNetBow:
      return SEMSEGMAP_WITH_TORCH ? ""
                                  : "this build has no learned descriptors (built without "
                                    "libtorch, reconfigure with -DSEMSEGMAP_WITH_TORCH=ON)";
  }
  throw std::invalid_argument("descriptorNotBuilt: invalid DescriptorKind value " +
                              std::to_string(static_cast<int>(kind)));
}

}  // namespace semsegmap
