// Class maps (settings/class_map_file.h) against the project's class table, and the info file of a
// label set (io/label_set.h), both YAML.
#include "fuzz_input.h"
#include "semsegmap/core/class_table.h"
#include "semsegmap/io/label_set.h"
#include "semsegmap/settings/class_map_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  static const ClassTable classes = ClassTable::Default();
  const auto path = fuzz::writeInput("classes.yaml", fuzz::asText(data, size));
  fuzz::expectCleanRefusal("classes.yaml", [&] { (void)readClassMap(path, classes); });
  std::filesystem::create_directories(fuzz::scratch() / "labels");
  fuzz::writeInput("labels/labels.yaml", fuzz::asText(data, size));
  fuzz::expectCleanRefusal("labels", [&] { (void)readLabelSetInfo(fuzz::scratch() / "labels"); });
  return 0;
}
