// makeDescriber: the one place that knows every descriptor kind (those of this build: fpfh with
// SEMSEGMAP_WITH_PCL, the learned ones with SEMSEGMAP_WITH_TORCH).
#include <stdexcept>

#include "semsegmap/describe/descriptor.h"
#include "semsegmap/describe/eigen_descriptor.h"
#if SEMSEGMAP_WITH_PCL
#include "semsegmap/describe/fpfh_descriptor.h"
#endif
#if SEMSEGMAP_WITH_TORCH
#include "semsegmap/describe/learned_describer.h"
#endif

namespace semsegmap {

std::unique_ptr<Describer> makeDescriber(DescriptorKind kind, const DescriberOptions& options) {
#if !SEMSEGMAP_WITH_PCL && !SEMSEGMAP_WITH_TORCH
  static_cast<void>(options);  // what the options set is fpfh's and the learned kinds'
#endif
  const std::string missing = descriptorNotBuilt(kind);
  if (!missing.empty()) throw std::runtime_error(descriptorName(kind) + ": " + missing);
  switch (kind) {
    case DescriptorKind::kEigen:
      return std::make_unique<EigenDescriber>();
    case DescriptorKind::kFpfh: {
#if SEMSEGMAP_WITH_PCL
      FpfhConfig config;
      config.threads = options.threads;
      return std::make_unique<FpfhDescriber>(config);
#else
      break;
#endif
    }
    case DescriptorKind::kSegMapCnn:
    case DescriptorKind::kSemSegMapNet:
    case DescriptorKind::kSmoothNetBow:
#if SEMSEGMAP_WITH_TORCH
      return makeLearnedDescriber(kind, options);
#else
      break;
#endif
  }
  throw std::invalid_argument("unknown descriptor kind");
}

}  // namespace semsegmap
