// The project's dataset folder (io/dataset_reader.h): the input is meta.yaml, then a line
// "--- frames.csv ---", then frames.csv, and optionally "--- lidar ---" and "--- labels ---"
// with the bytes of a scan and of its point labels, written as the files of frames 0-2. The
// reader opens the folder, every frame's time, and loads the first frames' files.
#include <algorithm>

#include "fuzz_input.h"
#include "semsegmap/io/dataset_format.h"
#include "semsegmap/io/dataset_reader.h"

namespace {

// The file of frames 0-2 in `folder` (none when `bytes` is empty).
void writeFrameFiles(const std::string& folder, std::string_view bytes) {
  if (bytes.empty()) return;
  std::filesystem::create_directories(semsegmap::fuzz::scratch() / "dataset" / folder);
  for (size_t i = 0; i < 3; ++i)
    semsegmap::fuzz::writeInput("dataset/" + folder + "/" + semsegmap::frameFileName(i, "bin"),
                                bytes);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto [meta, rest] = fuzz::splitAt(fuzz::asText(data, size), "\n--- frames.csv ---\n");
  const auto [frames, files] = fuzz::splitAt(rest, "\n--- lidar ---\n");
  const auto [scan, labels] = fuzz::splitAt(files, "\n--- labels ---\n");
  const std::filesystem::path dir = fuzz::scratch() / "dataset";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  fuzz::writeInput("dataset/meta.yaml", meta);
  fuzz::writeInput("dataset/frames.csv", frames);
  writeFrameFiles("lidar", scan);
  writeFrameFiles("lidar_gt", labels);
  fuzz::expectCleanRefusal("dataset", [&] {
    DatasetReader reader(dir, 3);
    for (size_t i = 0; i < reader.size(); ++i) (void)reader.frameTime(i);
    for (size_t i = 0; i < std::min<size_t>(reader.size(), 3); ++i) (void)reader.frame(i);
  });
  return 0;
}
