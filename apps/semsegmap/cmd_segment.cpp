// semsegmap segment: enrichment + local map + incremental segmentation over a dataset; writes
// segments.csv, the final observation of each segment as points, and a bird's-eye picture.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "dataset_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/artefacts/segments_io.h"
#include "semsegmap/pipeline/pipeline.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/viz/segments_png.h"

namespace semsegmap::app {

namespace {

// Segment counts, sizes and (with ground truth) purity, then the time per stage.
void printSummary(const std::vector<Segment>& segments, size_t n, size_t merges, bool has_gt,
                  const StageTimes& total) {
  double purity = 0.0;
  size_t points = 0;
  for (const auto& s : segments) {
    purity += s.last().gt_purity * static_cast<double>(s.last().n_points);
    points += s.last().n_points;
  }
  std::printf("frames %zu  segments %zu  merges %zu  mean points %.0f", n, segments.size(), merges,
              segments.empty() ? 0.0 : static_cast<double>(points) / segments.size());
  if (has_gt && !segments.empty()) {
    double mean_purity = 0.0;
    for (const auto& s : segments) mean_purity += s.last().gt_purity;
    std::printf("  mean purity %.3f  (point-weighted %.3f)", mean_purity / segments.size(),
                purity / points);
  }
  std::printf("\nms/frame: enrich %.1f  local map %.1f  segmentation %.1f\n", total.enrich_ms / n,
              total.local_map_ms / n, total.segment_ms / n);
}

int runSegment(const CliArgs& a) {
  const PipelineConfig config = loadPipelineConfig(a.get("config"));
  const std::filesystem::path out = a.get("out");
  auto source = openDatasetArg(a);
  const PoseSource poses = parsePoseSource(a.has("poses")                          ? a.get("poses")
                                           : source->info().has_ground_truth_poses ? "gt"
                                                                                   : "odom");
  const size_t n = a.frameLimit(source->size());
  std::filesystem::create_directories(out);

  Pipeline pipeline(config, source->info(), poses);
  std::vector<Segment> segments;
  std::vector<Pose> trajectory;
  StageTimes total;
  size_t merges = 0;
  Progress progress("segment", n);
  std::vector<std::optional<size_t>> numbers;  // the dataset's own, by frame index
  size_t done = 0;
  for (; done < n && !stopRequested(); ++done) {
    const Frame frame = source->frame(done);
    if (numbers.size() <= frame.index) numbers.resize(frame.index + 1);
    numbers[frame.index] = frame.number;
    FrameResult r = pipeline.process(frame);
    trajectory.push_back(r.T_local_base);
    merges += r.segmentation.merges.size();
    for (auto& s : r.segmentation.finished) segments.push_back(std::move(s));
    total.enrich_ms += r.times.enrich_ms;
    total.local_map_ms += r.times.local_map_ms;
    total.segment_ms += r.times.segment_ms;
    progress.update(done + 1);
  }
  if (done == 0) return interruptedRun("segment", 0, n, "");
  for (auto& s : pipeline.finish()) segments.push_back(std::move(s));
  std::sort(segments.begin(), segments.end(),
            [](const Segment& x, const Segment& y) { return x.id < y.id; });

  const bool has_gt = source->info().has_point_labels;
  writeSegmentsCsv(out / "segments.csv", segments, source->info().classes, has_gt, numbers);
  writeSegmentPointsPly(out / "segments.ply", segments);
  viz::writeSegmentsPng(
      out / "segments.png", segments, trajectory,
      source->info().name + " - " + std::filesystem::path(a.get("config")).stem().string());

  printSummary(segments, done, merges, has_gt, total);
  std::cout << "wrote " << (out / "segments.csv").string() << ", segments.ply, segments.png\n";
  if (done < n) return interruptedRun("segment", done, n, out.string());
  return 0;
}

}  // namespace

const CommandSpec& segmentCommand() {
  static const CommandSpec command{
      "segment",
      "enrichment + local map + incremental segmentation -> segments.csv, .ply, .png",
      datasetOptions(
          "the dataset",
          {
              {"config", Value::kText, "FILE", "", "pipeline configuration, config/*.yaml",
               kRequired},
              {"out", Value::kText, "DIR", "", "output folder", kRequired},
              {"poses", Value::kText, "gt|odom", "",
               "poses the local map is built with (default: gt when the data has them, else odom)"},
              maxFramesOption(),
          }),
      kDatasetNotes,
      runSegment,
      /*stops_between_frames=*/true};
  return command;
}

}  // namespace semsegmap::app
