// The training cache (artefacts/training_cache.h), with the provenance the seed generator writes;
// the input is the file without its trailing checksum, which the harness appends.
#include "fuzz_input.h"
#include "semsegmap/artefacts/training_cache.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto path = fuzz::writeInput("input.cache", fuzz::withChecksum(fuzz::asText(data, size)));
  fuzz::expectCleanRefusal("input.cache", [&] { (void)readTrainingCache(path, "fuzz seed"); });
  return 0;
}
