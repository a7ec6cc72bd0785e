// Localization at the revisits of any recorded sequence with ground truth: map from some of its
// frames, localize others against that map, every configuration on the very same frames. It is
// how a user checks the system on their own recording (`semsegmap eval revisits`), and how the
// real KITTI revisits are measured.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/core/json.h"
#include "semsegmap/eval/experiment.h"
#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

// Frames first..last (inclusive) in the order the dataset lists them, from 0.
struct FrameRange {
  size_t first = 0, last = 0;
};

// "A:B[,C:D...]" (a single "A" is A:A); throws std::invalid_argument naming `what` and the text.
std::vector<FrameRange> parseFrameRanges(const std::string& text, const std::string& what);

struct RevisitExperimentConfig {
  std::vector<FrameRange> map_frames, query_frames;
  std::vector<NamedConfig> configs;  // compared side by side
  // A query frame whose ground-truth position lies this close to a mapped frame's is at a
  // revisit: a place the map holds.
  double place_radius_m = 10.0;
  double correct_m = 1.0;  // a localization this close counts as localized at a revisit
  double wrong_m = 5.0;    // a localization farther off is wrong
  size_t picture_points_per_segment = 32;  // kept in memory for the pictures
};

struct RevisitFrame {             // one query frame
  size_t frame = 0;               // the dataset's frame number
  double nearest_mapped_m = 0.0;  // ground-truth distance to the nearest mapped frame
  bool revisit = false;           // nearest_mapped_m <= place_radius_m
};

struct RevisitLocalization {
  size_t frame = 0;  // the dataset's frame number
  int inliers = 0;
  double translation_error_m = 0.0, rotation_error_deg = 0.0;
};

struct RevisitResult {  // one configuration
  std::string config, descriptor;
  size_t map_segments = 0;
  uint64_t map_bytes = 0;
  std::vector<RevisitLocalization> localizations;
  size_t below_0_5m = 0, below_1m = 0, below_5m = 0, wrong = 0;
  double mean_translation_error_m = 0.0, mean_rotation_error_deg = 0.0;
  size_t revisits_localized = 0;  // revisit frames localized within correct_m
  std::filesystem::path dir;      // its files, relative to the output directory
};

struct RevisitExperiment {
  RevisitExperimentConfig config;
  std::string dataset;
  std::vector<RevisitFrame> queries;
  size_t revisits = 0;  // query frames at a revisit
  std::vector<RevisitResult> results;
  std::vector<double> thresholds;  // of the cumulative curves, m
};

// Checks the ranges against the dataset and each other, and that it has ground truth, before any
// frame is read; maps the map frames on ground-truth poses and localizes the query frames on the
// dataset's odometry, with every configuration. Writes as it goes into `out`:
// maps/<config>.map and <config>/ (localizations.csv, summary.json, localization.png).
RevisitExperiment evaluateRevisits(FrameSource& source, const RevisitExperimentConfig& config,
                                   const std::filesystem::path& out,
                                   const ExperimentProgress& progress = {});
nlohmann::ordered_json toJson(const RevisitExperiment& e);
// revisits.json and revisits.png (localizations within each error threshold, per configuration).
void writeRevisitFiles(const RevisitExperiment& e, const std::filesystem::path& out);
// The results as a Markdown table, one row per configuration.
std::string revisitTable(const RevisitExperiment& e);

}  // namespace semsegmap
