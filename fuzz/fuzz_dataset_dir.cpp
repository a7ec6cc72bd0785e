// The project's dataset folder (io/dataset_reader.h): the input is meta.yaml, then a line
// "--- frames.csv ---", then frames.csv; the reader opens the folder and every frame's time.
#include "fuzz_input.h"
#include "semsegmap/io/dataset_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto [meta, frames] = fuzz::splitAt(fuzz::asText(data, size), "\n--- frames.csv ---\n");
  const std::filesystem::path dir = fuzz::scratch() / "dataset";
  std::filesystem::create_directories(dir);
  fuzz::writeInput("dataset/meta.yaml", meta);
  fuzz::writeInput("dataset/frames.csv", frames);
  fuzz::expectCleanRefusal("dataset", [&] {
    DatasetReader reader(dir);
    for (size_t i = 0; i < reader.size(); ++i) (void)reader.frameTime(i);
  });
  return 0;
}
