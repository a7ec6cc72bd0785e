// The segmentation-consistency experiment (paper section IV-B): on a run that revisits places
// (S1), is a segment cut the same way again when the robot comes back? For each segment seen at
// a revisit, the convex-hull IoU with the best-overlapping segment of the target map built on the
// earlier visit of that place; IoU >= 0.33 counts as consistent. Every configuration segments the
// very same frames.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/json.h"
#include "semsegmap/eval/experiment.h"

namespace semsegmap {

struct SegmentationExperimentConfig {
  uint64_t world_seed = 1;
  std::string preset = "full";
  std::string run = "S1";
  size_t max_frames = 0;
  std::vector<NamedConfig> configs;  // the first is compared against the second
  // A segment belongs to a revisit when an earlier pass of the robot, ending at least
  // exclude_recent_m of driving before the segment was first seen, came within revisit_radius_m
  // of it. Its target map holds the segments finished before that point.
  double exclude_recent_m = 60.0;
  double revisit_radius_m = 20.0;
  double candidate_radius_m = 5.0;  // target segments with a centroid this close are compared
  double consistent_iou = 0.33;
  int bins = 10;   // of width 1 / bins over [0, 1]
  StopToken stop;  // checked before each frame (Ctrl-C in the CLI): the frames done are compared
};

struct SegmentationResult {
  std::string config;
  size_t segments = 0;  // finished segments of the run
  size_t revisit_segments = 0;
  std::vector<double> ious;       // one per revisit segment
  std::vector<size_t> histogram;  // counts per bin; IoU 1 falls in the last bin
  size_t consistent = 0, inconsistent = 0;
};

struct SegmentationExperiment {
  SegmentationExperimentConfig config;
  size_t frames = 0;  // of the run
  std::vector<SegmentationResult> results;
  // First configuration against the second, in percent of the second's counts (0 when it has
  // none): per bin, consistent and inconsistent. The paper: +30.97 % and -24.24 %.
  std::vector<double> bin_change_pct;
  double consistent_change_pct = 0.0, inconsistent_change_pct = 0.0;
  bool interrupted = false;  // the stop request ended the run early: `frames` are those done
};

// Histogram of IoU values in `bins` equal bins over [0, 1].
std::vector<size_t> iouHistogram(const std::vector<double>& ious, int bins);
// (a - b) / b in percent; 0 when b is 0.
double relativeChangePct(double a, double b);

// Segments the run with every configuration and compares them; writes nothing.
SegmentationExperiment evaluateSegmentation(const SegmentationExperimentConfig& config,
                                            const ExperimentProgress& progress = {});

// segmentation.json: every number, and the paper's.
nlohmann::ordered_json toJson(const SegmentationExperiment& e);

// Writes segmentation.json and segmentation.png (histograms and the change per bin) into `out`.
void writeSegmentationFiles(const SegmentationExperiment& e, const std::filesystem::path& out);

// evaluateSegmentation, then writeSegmentationFiles.
SegmentationExperiment runSegmentationExperiment(const SegmentationExperimentConfig& config,
                                                 const std::filesystem::path& out,
                                                 const ExperimentProgress& progress = {});

std::string segmentationTable(const SegmentationExperiment& e);  // Markdown

}  // namespace semsegmap
