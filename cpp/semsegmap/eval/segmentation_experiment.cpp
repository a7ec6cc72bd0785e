#include "semsegmap/eval/segmentation_experiment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/eval/convex_hull.h"
#include "semsegmap/eval/localization_metrics.h"
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

// What the run leaves: each configuration's finished segments, and the ground-truth trajectory.
struct SegmentedRun {
  std::vector<std::vector<FinishedSegment>> finished;  // per configuration
  std::vector<Pose> trajectory;                        // one pose per frame
  bool interrupted = false;                            // the frames done, not all of them
};

SegmentedRun segmentRun(const SegmentationExperimentConfig& cfg,
                        const ExperimentProgress& progress) {
  auto source = openDataset(simulatedRunSpec(cfg.world_seed, cfg.run, cfg.preset, cfg.max_frames));
  std::vector<std::unique_ptr<Pipeline>> pipelines;
  for (const NamedConfig& c : cfg.configs)
    pipelines.push_back(
        std::make_unique<Pipeline>(c.config, source->info(), PoseSource::kGroundTruth));
  SegmentedRun run;
  run.finished.resize(cfg.configs.size());
  run.interrupted =
      !forEachFrame(*source, "segment " + cfg.run, progress, cfg.stop, [&](const Frame& frame) {
        for (size_t c = 0; c < pipelines.size(); ++c)
          for (const Segment& s : pipelines[c]->process(frame).segmentation.finished)
            run.finished[c].push_back(finishedSegment(s));
        run.trajectory.push_back(*frame.T_world_base);
      });
  for (size_t c = 0; c < pipelines.size(); ++c)
    for (const Segment& s : pipelines[c]->finish()) run.finished[c].push_back(finishedSegment(s));
  return run;
}

SegmentationResult resultOf(const std::string& config, const std::vector<FinishedSegment>& finished,
                            const std::vector<Pose>& trajectory,
                            const std::vector<double>& travelled,
                            const SegmentationExperimentConfig& cfg) {
  SegmentationResult r;
  r.config = config;
  r.segments = finished.size();
  r.ious = revisitIous(finished, trajectory, travelled, cfg);
  r.revisit_segments = r.ious.size();
  r.histogram = iouHistogram(r.ious, cfg.bins);
  for (double v : r.ious) (v >= cfg.consistent_iou ? r.consistent : r.inconsistent)++;
  return r;
}

// The first configuration against the second.
void compareFirstTwo(SegmentationExperiment& e) {
  if (e.results.size() < 2) return;
  const SegmentationResult &a = e.results[0], &b = e.results[1];
  for (int k = 0; k < e.config.bins; ++k)
    e.bin_change_pct.push_back(relativeChangePct(static_cast<double>(a.histogram[k]),
                                                 static_cast<double>(b.histogram[k])));
  e.consistent_change_pct =
      relativeChangePct(static_cast<double>(a.consistent), static_cast<double>(b.consistent));
  e.inconsistent_change_pct =
      relativeChangePct(static_cast<double>(a.inconsistent), static_cast<double>(b.inconsistent));
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

// The paper's figure: the histograms side by side, then the change per bin.
std::vector<viz::Panel> segmentationPanels(const SegmentationExperiment& e) {
  std::vector<viz::Panel> panels;
  viz::Panel hist = barPanel("segments per IoU bin at revisits", "segments");
  hist.auto_y = false;  // counts start at 0
  hist.y_max = 1.0;
  for (const SegmentationResult& r : e.results)
    for (size_t v : r.histogram) hist.y_max = std::max(hist.y_max, 1.15 * static_cast<double>(v));
  for (const SegmentationResult& r : e.results) {
    viz::Series s;
    s.name = r.config;
    s.x = binCentres(e.config.bins);
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
    s.x = binCentres(e.config.bins);
    s.y = e.bin_change_pct;
    for (size_t v : e.results[0].histogram) s.labels.push_back(std::to_string(v));
    change.series.push_back(std::move(s));
    panels.push_back(std::move(change));
  }
  return panels;
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

SegmentationExperiment evaluateSegmentation(const SegmentationExperimentConfig& cfg,
                                            const ExperimentProgress& progress) {
  if (cfg.configs.empty())
    throw std::invalid_argument("the segmentation experiment needs at least one configuration");
  SegmentationExperiment e;
  e.config = cfg;
  const SegmentedRun run = segmentRun(cfg, progress);
  e.frames = run.trajectory.size();
  e.interrupted = run.interrupted;
  const std::vector<double> travelled = travelledDistances(run.trajectory);
  for (size_t c = 0; c < cfg.configs.size(); ++c) {
    e.results.push_back(
        resultOf(cfg.configs[c].name, run.finished[c], run.trajectory, travelled, cfg));
    if (progress) progress("convex hulls", c + 1, cfg.configs.size());
  }
  compareFirstTwo(e);
  return e;
}

nlohmann::ordered_json toJson(const SegmentationExperiment& e) {
  nlohmann::ordered_json j;
  j["world_seed"] = e.config.world_seed;
  j["preset"] = e.config.preset;
  j["run"] = e.config.run;
  j["frames"] = e.frames;
  j["interrupted"] = e.interrupted;  // `frames` are those done before Ctrl-C
  j["consistent_iou"] = e.config.consistent_iou;
  j["bins"] = e.config.bins;
  j["results"] = nlohmann::ordered_json::array();
  for (const SegmentationResult& r : e.results)
    j["results"].push_back({{"config", r.config},
                            {"segments", r.segments},
                            {"revisit_segments", r.revisit_segments},
                            {"consistent", r.consistent},
                            {"inconsistent", r.inconsistent},
                            {"histogram", r.histogram}});
  j["bin_change_pct"] = e.bin_change_pct;
  j["consistent_change_pct"] = e.consistent_change_pct;
  j["inconsistent_change_pct"] = e.inconsistent_change_pct;
  j["paper"] = {{"consistent_change_pct", 30.97}, {"inconsistent_change_pct", -24.24}};
  return j;
}

void writeSegmentationFiles(const SegmentationExperiment& e, const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  writeJsonAtomically(out / "segmentation.json", toJson(e));
  viz::plotPanels(out / "segmentation.png",
                  "Segmentation consistency on " + e.config.run + " (world " +
                      std::to_string(e.config.world_seed) + ", " + e.config.preset + ")",
                  segmentationPanels(e));
}

SegmentationExperiment runSegmentationExperiment(const SegmentationExperimentConfig& cfg,
                                                 const std::filesystem::path& out,
                                                 const ExperimentProgress& progress) {
  SegmentationExperiment e = evaluateSegmentation(cfg, progress);
  writeSegmentationFiles(e, out);
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
  if (e.interrupted) t << partialNote();
  return t.str();
}

}  // namespace semsegmap
