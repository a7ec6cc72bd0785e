// Configuration YAML (settings/config.h): the pipeline, odometry and semantics sections.
#include "fuzz_input.h"
#include "semsegmap/settings/config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto path = fuzz::writeInput("config.yaml", fuzz::asText(data, size));
  fuzz::expectCleanRefusal("config.yaml", [&] { (void)loadPipelineConfig(path); });
  fuzz::expectCleanRefusal("config.yaml", [&] { (void)loadOdometryConfig(path); });
  fuzz::expectCleanRefusal("config.yaml", [&] { (void)loadSemanticsConfig(path); });
  return 0;
}
