// semsegmap convert: any dataset the CLI reads (KITTI raw, SemanticKITTI, NCLT, the simulator)
// written in the project's own format.
#include <iostream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/io/dataset_writer.h"
#include "semsegmap/io/open_dataset.h"

namespace semsegmap::app {

int runConvert(const std::vector<std::string>& args) {
  const CliArgs a(args, {"dataset", "out", "max-frames"}, {});
  auto source = openDataset(a.require("dataset"));
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  const size_t n = max_frames > 0
                       ? std::min<size_t>(source->size(), static_cast<size_t>(max_frames))
                       : source->size();
  DatasetWriter writer(a.require("out"), source->info());
  Progress progress("convert", n);
  for (size_t i = 0; i < n; ++i) {
    writer.write(source->frame(i));
    progress.update(i + 1);
  }
  std::cout << "wrote " << writer.framesWritten() << " frames of " << source->info().name << " to "
            << a.require("out") << "\n";
  return 0;
}

}  // namespace semsegmap::app
