// semsegmap convert: any dataset the CLI reads (KITTI raw, SemanticKITTI, NCLT, the simulator)
// written in the project's own format (with the label images of --labels or of a --config's
// segmentation network).
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/io/dataset_writer.h"

namespace semsegmap::app {

namespace {

int runConvert(const CliArgs& a) {
  auto source = openDatasetArg(a);
  const size_t n = a.frameLimit(source->size());
  DatasetWriter writer(a.get("out"), source->info());
  Progress progress("convert", n);
  // Each frame's files and frames.csv row are whole when the next starts: a stopped
  // conversion is a readable dataset of the frames written.
  for (size_t i = 0; i < n && !stopRequested(); ++i) {
    writer.write(source->frame(i));
    progress.update(i + 1);
  }
  std::cout << "wrote " << writer.framesWritten() << " frames of " << source->info().name << " to "
            << a.get("out") << "\n";
  if (writer.framesWritten() < n)
    return interruptedRun("convert", writer.framesWritten(), n, a.get("out"));
  return 0;
}

}  // namespace

const CommandSpec& convertCommand() {
  static const CommandSpec command{
      "convert",
      "writes any dataset the command line reads in the project's own format",
      datasetOptions("the dataset to convert",
                     {
                         {"out", Value::kText, "DIR", "", "dataset directory to write", kRequired},
                         maxFramesOption(),
                         {"config", Value::kText, "FILE", "",
                          "a config whose semantics: section labels the pictures that have no "
                          "labels, so that the written dataset carries them"},
                     }),
      kDatasetNotes,
      runConvert,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
