// Target maps (artefacts/map_file.h) through loadTargetMap: the input is the file without its
// trailing checksum, which the harness appends (the seeds are written so).
#include "fuzz_input.h"
#include "semsegmap/artefacts/map_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto path = fuzz::writeInput("input.map", fuzz::withChecksum(fuzz::asText(data, size)));
  fuzz::expectCleanRefusal("input.map", [&] { (void)loadTargetMap(path); });
  return 0;
}
