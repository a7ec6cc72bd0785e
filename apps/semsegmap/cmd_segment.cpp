// semsegmap segment: enrichment + local map + incremental segmentation over a dataset; writes
// segments.csv, the final observation of each segment as points, and a bird's-eye picture.
#include <filesystem>
#include <iostream>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/io/config.h"
#include "semsegmap/io/open_dataset.h"
#include "semsegmap/io/segments_io.h"
#include "semsegmap/pipeline/pipeline.h"
#include "semsegmap/viz/segments_png.h"

namespace semsegmap::app {

int runSegment(const std::vector<std::string>& args) {
  const CliArgs a(args, {"dataset", "config", "out", "poses", "max-frames"}, {});
  const PipelineConfig config = loadPipelineConfig(a.require("config"));
  const std::filesystem::path out = a.require("out");
  auto source = openDataset(a.require("dataset"));
  const PoseSource poses =
      parsePoseSource(a.get("poses", source->info().has_ground_truth_poses ? "gt" : "odom"));
  const long long max_frames = a.getInt("max-frames", 0);
  if (max_frames < 0) throw std::invalid_argument("--max-frames must not be negative");
  const size_t n = max_frames > 0
                       ? std::min<size_t>(source->size(), static_cast<size_t>(max_frames))
                       : source->size();
  std::filesystem::create_directories(out);

  Pipeline pipeline(config, source->info(), poses);
  std::vector<Segment> segments;
  std::vector<Pose> trajectory;
  StageTimes total;
  size_t merges = 0;
  Progress progress("segment", n);
  for (size_t i = 0; i < n; ++i) {
    FrameResult r = pipeline.process(source->frame(i));
    trajectory.push_back(r.T_map_base);
    merges += r.segmentation.merges.size();
    for (auto& s : r.segmentation.finished) segments.push_back(std::move(s));
    total.enrich_ms += r.times.enrich_ms;
    total.local_map_ms += r.times.local_map_ms;
    total.segment_ms += r.times.segment_ms;
    progress.update(i + 1);
  }
  for (auto& s : pipeline.finish()) segments.push_back(std::move(s));
  std::sort(segments.begin(), segments.end(),
            [](const Segment& x, const Segment& y) { return x.id < y.id; });

  const bool has_gt = source->info().has_point_labels;
  writeSegmentsCsv(out / "segments.csv", segments, source->info().classes, has_gt);
  writeSegmentPointsPly(out / "segments.ply", segments);
  viz::writeSegmentsPng(
      out / "segments.png", segments, trajectory,
      source->info().name + " - " + std::filesystem::path(a.require("config")).stem().string());

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
  std::cout << "wrote " << (out / "segments.csv").string() << ", segments.ply, segments.png\n";
  return 0;
}

}  // namespace semsegmap::app
