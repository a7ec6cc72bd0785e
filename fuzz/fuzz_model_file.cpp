// Model files of the learned descriptors (artefacts/model_file.h): read, then (with libtorch) the
// network built from them, as `descriptor.model` is loaded.
#include "fuzz_input.h"
#include "semsegmap/artefacts/model_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto path = fuzz::writeInput("input.model", fuzz::asText(data, size));
#if SEMSEGMAP_WITH_TORCH
  fuzz::expectCleanRefusal("input.model", [&] { (void)loadNet(path); });
#else
  fuzz::expectCleanRefusal("input.model", [&] { (void)readModelFile(path); });
#endif
  return 0;
}
