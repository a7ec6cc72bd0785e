// KITTI scans and SemanticKITTI labels (io/dataset_format.h): the input as a .bin of float32
// x, y, z, intensity and as a .label of uint32 per point.
#include "fuzz_input.h"
#include "semsegmap/io/dataset_format.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto scan = fuzz::writeInput("scan.bin", fuzz::asText(data, size));
  fuzz::expectCleanRefusal("scan.bin", [&] { (void)readLidarBin(scan); });
  const auto labels = fuzz::writeInput("scan.label", fuzz::asText(data, size));
  fuzz::expectCleanRefusal("scan.label", [&] { (void)readLabelBin(labels); });
  return 0;
}
