// semsegmap enrich: one frame's LiDAR points coloured and labelled from the cameras, drawn over
// a camera image (and optionally saved as a PLY cloud) to check that the projection lines up.
#include <chrono>
#include <iostream>
#include <stdexcept>

#include "cli_args.h"
#include "dataset_args.h"
#include "semsegmap/enrich/enricher.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/ply_writer.h"
#include "semsegmap/viz/enrich_overlay.h"

namespace semsegmap::app {

namespace {

int runEnrich(const CliArgs& a) {
  const std::string spec = a.get("dataset");
  const std::string out = a.get("out");
  auto source = openDatasetArg(a);
  const DatasetInfo& info = source->info();

  const size_t frame_index = a.getCount("frame");
  if (frame_index >= source->size())
    throw UsageError("--frame " + std::to_string(frame_index) + " is outside " + spec + " (" +
                     std::to_string(source->size()) + " frames)");
  const size_t n_cams = info.rig.cameras.size();
  if (n_cams == 0) throw std::invalid_argument("dataset '" + spec + "' has no cameras to draw on");
  // The simulator's three cameras are left, front, right: the front one shows the most.
  const size_t camera = a.has("camera") ? a.getCount("camera") : (n_cams == 3 ? 1 : 0);
  if (camera >= n_cams)
    throw UsageError("--camera " + std::to_string(camera) + " is outside 0.." +
                     std::to_string(n_cams - 1));

  const Frame frame = source->frame(frame_index);
  if (frame.cameras.size() != n_cams || frame.cameras[camera].rgb.empty())
    throw std::invalid_argument("dataset '" + spec + "' frame " + std::to_string(frame_index) +
                                ": camera '" + info.rig.cameras[camera].name + "' has no image");

  const auto t0 = std::chrono::steady_clock::now();
  const EnrichedCloud cloud = enrichFrame(frame, info.rig, EnrichmentConfig{});
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  size_t coloured = 0;
  for (const EnrichedPoint& p : cloud) coloured += p.has_color;

  bool has_labels = !frame.point_labels.empty();
  for (const CameraFrame& cf : frame.cameras) has_labels |= !cf.label.empty();
  viz::EnrichOverlayStyle style;
  style.colour = has_labels ? viz::DotColour::kClass : viz::DotColour::kDepth;
  // Small images (the simulator's 640 x 480) see neighbouring LiDAR rings 2-3 pixels apart:
  // bigger dots would hide the picture they are meant to be compared with.
  style.dot_radius_px = frame.cameras[camera].rgb.width >= 1000 ? 1 : 0;
  style.max_width = static_cast<int>(a.getCount("width"));
  const std::string legend = info.name + "\nframe " + std::to_string(frame_index) + ": " +
                             std::to_string(coloured) + " / " + std::to_string(cloud.size()) +
                             " points coloured" +
                             (has_labels ? ", dots: class" : ", dots: depth (near red, far blue)");
  writePng(out, viz::drawEnrichOverlay(frame.cameras[camera].rgb, info.rig.cameras[camera], cloud,
                                       info.classes, legend, style));
  std::cout << "enriched " << cloud.size() << " points (" << coloured << " coloured) in " << ms
            << " ms\nwrote " << out << "\n";
  if (a.has("ply")) {
    writeEnrichedPly(a.get("ply"), cloud);
    std::cout << "wrote " << a.get("ply") << "\n";
  }
  return 0;
}

}  // namespace

const CommandSpec& enrichCommand() {
  static const CommandSpec command{
      "enrich", "one frame's LiDAR points coloured from the cameras, drawn over a camera image",
      datasetOptions(
          "the dataset",
          {
              {"frame", Value::kCount, "I", "0", "the frame to enrich"},
              {"out", Value::kText, "FILE.png", "", "the camera image with the points", kRequired},
              {"width", Value::kCount, "W", "0",
               "shrink the picture to this width, 0: as the camera"},
              {"ply", Value::kText, "FILE.ply", "", "also write the enriched cloud"},
              {"camera", Value::kCount, "K", "",
               "the camera to draw on (default: 1, the front one, with three cameras, else 0)"},
              {"config", Value::kText, "FILE", "",
               "a config whose semantics: section labels pictures that have no labels"},
          }),
      kDatasetNotes, runEnrich};
  return command;
}

}  // namespace semsegmap::app
