// Rig files (io/rig_file.h, docs/rig-format.md).
#include "fuzz_input.h"
#include "semsegmap/io/rig_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto path = fuzz::writeInput("rig.yaml", fuzz::asText(data, size));
  fuzz::expectCleanRefusal("rig.yaml", [&] { (void)readRigFile(path); });
  return 0;
}
