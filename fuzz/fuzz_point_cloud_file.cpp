// Point cloud files of any layout (io/point_cloud_file.h): PCD (ASCII, binary,
// binary_compressed) and, for inputs that start with "ply", PLY.
#include "fuzz_input.h"
#include "semsegmap/io/point_cloud_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const std::string_view text = fuzz::asText(data, size);
  const std::string name = text.substr(0, 3) == "ply" ? "scan.ply" : "scan.pcd";
  const auto path = fuzz::writeInput(name, text);
  fuzz::expectCleanRefusal(name, [&] { (void)readPointCloudFile(path); });
  return 0;
}
