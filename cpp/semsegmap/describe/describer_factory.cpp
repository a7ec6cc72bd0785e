// makeDescriber: the one place that knows every descriptor kind.
#include "semsegmap/describe/descriptor.h"
#include "semsegmap/describe/eigen_descriptor.h"
#include "semsegmap/describe/fpfh_descriptor.h"
#include "semsegmap/describe/learned_describer.h"

namespace semsegmap {

std::unique_ptr<Describer> makeDescriber(DescriptorKind kind, const DescriberOptions& options) {
  switch (kind) {
    case DescriptorKind::kEigen:
      return std::make_unique<EigenDescriber>();
    case DescriptorKind::kFpfh: {
      FpfhConfig config;
      config.threads = options.threads;
      return std::make_unique<FpfhDescriber>(config);
    }
    case DescriptorKind::kSegMapCnn:
    case DescriptorKind::kSemSegMapNet:
      return makeLearnedDescriber(kind, options);
  }
  throw std::invalid_argument("unknown descriptor kind");
}

}  // namespace semsegmap
