#include "semsegmap/eval/segmentation_experiment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "semsegmap/eval/convex_hull.h"
#include "semsegmap/eval/localization_metrics.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/json.h"
#include "semsegmap/io/open_dataset.h"
#include "semsegmap/pipeline/pipeline.h"
#include "semsegmap/viz/plot.h"

namespace semsegmap {

namespace {

struct FinishedSegment {
  Eigen::Vector3d centroid;
  size_t first_frame = 0, last_frame = 0;
  ConvexHull hull;
};

FinishedSegment finishedSegment(const Segment& s) {
  FinishedSegment f;
  const SegmentObservation& o = s.last();
  f.centroid = o.centroid;
  f.first_frame = s.first_frame;
  f.last_frame = s.last_frame;
  std::vector<Eigen::Vector3f> points;
  points.reserve(o.points.size());
  for (const EnrichedPoint& p : o.points) points.emplace_back(p.x, p.y, p.z);
  f.hull = convexHull(points);  // map frame = world: the run is segmented on ground truth
  return f;
}

// The IoU of every segment seen at a revisit with its best match among the segments finished on
// the earlier visit.
std::vector<double> revisitIous(const std::vector<FinishedSegment>& segments,
                                const std::vector<Pose>& trajectory,
                                const std::vector<double>& travelled,
                                const SegmentationExperimentConfig& cfg) {
  std::vector<double> ious;
  for (const FinishedSegment& b : segments) {
    const double before = travelled.at(b.first_frame) - cfg.exclude_recent_m;
    if (before <= 0.0) continue;
    bool revisit = false;
    for (size_t i = 0; i < trajectory.size() && travelled[i] < before && !revisit; ++i)
      revisit = (trajectory[i].translation() - b.centroid).head<2>().norm() < cfg.revisit_radius_m;
    if (!revisit) continue;
    double best = 0.0;
    for (const FinishedSegment& a : segments) {
      if (travelled.at(a.last_frame) >= before) continue;
      if ((a.centroid - b.centroid).norm() > cfg.candidate_radius_m) continue;
      best = std::max(best, convexHullIoU(a.hull, b.hull));
    }
    ious.push_back(best);
  }
  return ious;
}

viz::Panel barPanel(const std::string& title, const std::string& ylabel) {
  viz::Panel p;
  p.title = title;
  p.xlabel = "convex hull IoU";
  p.ylabel = ylabel;
  p.style = viz::PlotStyle::kBars;
  p.auto_y = true;
  return p;
}

std::vector<double> binCentres(int bins) {
  std::vector<double> x;
  for (int b = 0; b < bins; ++b) x.push_back((b + 0.5) / bins);
  return x;
}

}  // namespace

std::vector<size_t> iouHistogram(const std::vector<double>& ious, int bins) {
  if (bins <= 0) throw std::invalid_argument("iouHistogram: bins must be positive");
  std::vector<size_t> h(static_cast<size_t>(bins), 0);
  for (double v : ious) {
    const int b = std::clamp(static_cast<int>(std::floor(v * bins)), 0, bins - 1);
    ++h[static_cast<size_t>(b)];
  }
  return h;
}

double relativeChangePct(double a, double b) {
  return b > 0.0 ? 100.0 * (a - b) / b : 0.0;
}

SegmentationExperiment runSegmentationExperiment(const SegmentationExperimentConfig& cfg,
                                                 const std::filesystem::path& out,
                                                 const ExperimentProgress& progress) {
  if (cfg.configs.empty())
    throw std::invalid_argument("the segmentation experiment needs at least one configuration");
  SegmentationExperiment e;
  e.config = cfg;
  auto source = openDataset(simulatedRunSpec(cfg.world_seed, cfg.run, cfg.preset, cfg.max_frames));
  std::vector<std::unique_ptr<Pipeline>> pipelines;
  for (const NamedConfig& c : cfg.configs)
    pipelines.push_back(
        std::make_unique<Pipeline>(c.config, source->info(), PoseSource::kGroundTruth));
  std::vector<std::vector<FinishedSegment>> finished(cfg.configs.size());
  std::vector<Pose> trajectory;  // ground truth, one pose per frame
  forEachFrame(*source, "segment " + cfg.run, progress, [&](const Frame& frame) {
    for (size_t c = 0; c < pipelines.size(); ++c)
      for (const Segment& s : pipelines[c]->process(frame).segmentation.finished)
        finished[c].push_back(finishedSegment(s));
    trajectory.push_back(*frame.T_world_base_gt);
  });
  const std::vector<double> travelled = travelledDistances(trajectory);

  for (size_t c = 0; c < pipelines.size(); ++c) {
    for (const Segment& s : pipelines[c]->finish()) finished[c].push_back(finishedSegment(s));
    SegmentationResult r;
    r.config = cfg.configs[c].name;
    r.segments = finished[c].size();
    r.ious = revisitIous(finished[c], trajectory, travelled, cfg);
    r.revisit_segments = r.ious.size();
    r.histogram = iouHistogram(r.ious, cfg.bins);
    for (double v : r.ious) (v >= cfg.consistent_iou ? r.consistent : r.inconsistent)++;
    e.results.push_back(std::move(r));
    if (progress) progress("convex hulls", c + 1, pipelines.size());
  }
  if (e.results.size() >= 2) {
    const SegmentationResult &a = e.results[0], &b = e.results[1];
    for (int k = 0; k < cfg.bins; ++k)
      e.bin_change_pct.push_back(relativeChangePct(static_cast<double>(a.histogram[k]),
                                                   static_cast<double>(b.histogram[k])));
    e.consistent_change_pct =
        relativeChangePct(static_cast<double>(a.consistent), static_cast<double>(b.consistent));
    e.inconsistent_change_pct =
        relativeChangePct(static_cast<double>(a.inconsistent), static_cast<double>(b.inconsistent));
  }

  // JSON with every number, then the paper's figure: the histograms and the change per bin.
  std::ostringstream j;
  j << "{\n  \"world_seed\": " << cfg.world_seed << ",\n  \"preset\": " << jsonQuoted(cfg.preset)
    << ",\n  \"run\": " << jsonQuoted(cfg.run) << ",\n  \"frames\": " << trajectory.size()
    << ",\n  \"consistent_iou\": " << cfg.consistent_iou << ",\n  \"bins\": " << cfg.bins
    << ",\n  \"results\": [\n";
  for (size_t c = 0; c < e.results.size(); ++c) {
    const SegmentationResult& r = e.results[c];
    j << "    {\"config\": " << jsonQuoted(r.config) << ", \"segments\": " << r.segments
      << ", \"revisit_segments\": " << r.revisit_segments << ", \"consistent\": " << r.consistent
      << ", \"inconsistent\": " << r.inconsistent << ", \"histogram\": [";
    for (size_t k = 0; k < r.histogram.size(); ++k) j << (k ? ", " : "") << r.histogram[k];
    j << "]}" << (c + 1 < e.results.size() ? "," : "") << "\n";
  }
  j << "  ],\n  \"bin_change_pct\": [";
  for (size_t k = 0; k < e.bin_change_pct.size(); ++k) j << (k ? ", " : "") << e.bin_change_pct[k];
  j << "],\n  \"consistent_change_pct\": " << e.consistent_change_pct
    << ",\n  \"inconsistent_change_pct\": " << e.inconsistent_change_pct
    << ",\n  \"paper\": {\"consistent_change_pct\": 30.97, \"inconsistent_change_pct\": "
       "-24.24}\n}\n";
  std::filesystem::create_directories(out);
  writeBytesAtomically(out / "segmentation.json", j.str());

  std::vector<viz::Panel> panels;
  viz::Panel hist = barPanel("segments per IoU bin at revisits", "segments");
  hist.auto_y = false;  // counts start at 0
  hist.y_max = 1.0;
  for (const SegmentationResult& r : e.results)
    for (size_t v : r.histogram) hist.y_max = std::max(hist.y_max, 1.15 * static_cast<double>(v));
  for (const SegmentationResult& r : e.results) {
    viz::Series s;
    s.name = r.config;
    s.x = binCentres(cfg.bins);
    for (size_t v : r.histogram) s.y.push_back(static_cast<double>(v));
    hist.series.push_back(std::move(s));
  }
  panels.push_back(std::move(hist));
  if (e.results.size() >= 2) {
    viz::Panel change = barPanel(e.results[0].config + " against " + e.results[1].config +
                                     " (numbers: " + e.results[0].config + "'s segments)",
                                 "change in segments per bin (%)");
    viz::Series s;
    s.name = "change";
    s.x = binCentres(cfg.bins);
    s.y = e.bin_change_pct;
    for (size_t v : e.results[0].histogram) s.labels.push_back(std::to_string(v));
    change.series.push_back(std::move(s));
    panels.push_back(std::move(change));
  }
  viz::plotPanels(out / "segmentation.png",
                  "Segmentation consistency on " + cfg.run + " (world " +
                      std::to_string(cfg.world_seed) + ", " + cfg.preset + ")",
                  panels);
  return e;
}

std::string segmentationTable(const SegmentationExperiment& e) {
  std::ostringstream t;
  char line[256];
  t << "| config | segments | at revisits | IoU >= " << e.config.consistent_iou << " | IoU < "
    << e.config.consistent_iou << " |\n| --- | ---: | ---: | ---: | ---: |\n";
  for (const SegmentationResult& r : e.results) {
    std::snprintf(line, sizeof(line), "| %s | %zu | %zu | %zu | %zu |\n", r.config.c_str(),
                  r.segments, r.revisit_segments, r.consistent, r.inconsistent);
    t << line;
  }
  if (e.results.size() >= 2) {
    std::snprintf(line, sizeof(line),
                  "| change (%s vs %s) | | | %+.2f %% (paper +30.97 %%) | %+.2f %% (paper -24.24 "
                  "%%) |\n",
                  e.results[0].config.c_str(), e.results[1].config.c_str(), e.consistent_change_pct,
                  e.inconsistent_change_pct);
    t << line;
  }
  return t.str();
}

}  // namespace semsegmap
