// KITTI calibration and pose files (io/kitti_calib.h): every key the readers ask for, as
// numbers, matrices, rotations and transforms, and the same text as a poses.txt.
#include "fuzz_input.h"
#include "semsegmap/io/kitti_calib.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto path = fuzz::writeInput("calib.txt", fuzz::asText(data, size));
  fuzz::expectCleanRefusal("calib.txt", [&] {
    const KittiCalibFile calib(path);
    for (const char* key : {"P0", "P1", "P2", "P3", "Tr", "Tr_velo_to_cam"})
      if (calib.has(key)) (void)calib.transform3x4(key);
  });
  fuzz::expectCleanRefusal("calib.txt", [&] {
    const KittiCalibFile calib(path);
    if (calib.has("R") && calib.has("T")) (void)calib.transform("R", "T");
    if (calib.has("S_rect_02")) (void)calib.numbers("S_rect_02", 2);
    if (calib.has("P_rect_02")) (void)calib.matrix("P_rect_02", 3, 4);
  });
  fuzz::expectCleanRefusal("calib.txt", [&] {
    const KittiCalibFile velo(path);
    (void)kittiRectifiedCamera(velo, velo, 2);
  });
  fuzz::expectCleanRefusal("calib.txt", [&] { (void)readKittiPoses(path); });
  return 0;
}
