// Localization at the revisits of any recorded sequence with ground truth: map from some of its
// frames, localize others against that map, every configuration on the very same frames. It is
// how a user checks the system on their own recording (`semsegmap eval revisits`), and how the
// real KITTI revisits are measured.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/core/json.h"
#include "semsegmap/eval/experiment.h"
#include "semsegmap/eval/scan_context_localizer.h"
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
  // Wake-ups (the kidnapped robot), off at 0: a robot wakes up at every wake_up_every-th query
  // frame of each range (0: every wake_up_frames-th, back to back) with an empty local map and
  // localizes from that frame and the wake_up_frames - 1 after it (within the range).
  size_t wake_up_frames = 0, wake_up_every = 0;
  // Registers every query scan to the mapped scans from its ground-truth pose
  // (eval/ground_truth_check.h): how far the ground truth disagrees with the map's own geometry,
  // and each localization's error against the registered pose besides the recorded one.
  bool check_ground_truth = false;
  // Scan Context (eval/scan_context_localizer.h), the whole-scan baseline, on the same frames:
  // the mapped scans at their ground-truth poses, each query frame on its own (it needs no local
  // map). Its result follows the configurations', named kScanContextName; nothing: left out.
  std::optional<ScanContextLocalizerConfig> scan_context = ScanContextLocalizerConfig{};
  // Checked before each frame (Ctrl-C in the CLI): the maps and query sessions end with the
  // frames done, and no further query session starts.
  StopToken stop;
};

// "N[/EVERY]" of --wake-up; throws std::invalid_argument naming `what` and the text.
void parseWakeUp(const std::string& text, const std::string& what, RevisitExperimentConfig& c);

// The query frames as the sessions that localize them: one over every range, or with wake-ups
// one a wake-up.
std::vector<std::vector<FrameRange>> querySessions(const RevisitExperimentConfig& c);

struct WakeUp {              // one wake-up of one configuration
  FrameRange frames;         // the dataset's frames it localized from
  bool revisit = false;      // its first frame is at a revisit
  size_t localized = 0;      // 1 + frames after waking up until the first localization within
                             // correct_m (of the registered ground truth where the scan
                             // registered, check_ground_truth); 0: none
  bool wrong_first = false;  // a localization more than wrong_m off came before any correct one
};

struct RevisitFrame {             // one query frame
  size_t frame = 0;               // the dataset's frame number
  double nearest_mapped_m = 0.0;  // ground-truth distance to the nearest mapped frame
  bool revisit = false;           // nearest_mapped_m <= place_radius_m
  // check_ground_truth: the base pose registered to the mapped scans, when registration worked.
  std::optional<Pose> T_world_base_registered;
  double ground_truth_correction_m = 0.0;  // how far registration moved the ground truth
};

struct RevisitLocalization {
  size_t frame = 0;  // the dataset's frame number
  int inliers = 0;
  double translation_error_m = 0.0, rotation_error_deg = 0.0;
  double registered_error_m = -1.0;  // against the registered ground truth; < 0: none
  double registered_rotation_error_deg = -1.0;
};

// The name of Scan Context's result, and its descriptor's; a configuration may not take it.
inline constexpr const char* kScanContextName = "scan-context";

struct RevisitResult {  // one configuration, or Scan Context
  std::string config, descriptor;
  std::string method = "segments";  // what localized: "segments", or kScanContextName
  std::string model;  // the model file the input's modalities chose (chooseDescriptor); or empty
  std::string model_note;   // why that model, when the configuration names more than one
  size_t map_segments = 0;  // Scan Context: 0
  // The saved map's file; Scan Context: what it keeps in memory, the scan contexts and the mapped
  // scans' points it registers to.
  uint64_t map_bytes = 0;
  size_t mapped_scans = 0;  // Scan Context: the scans in its database
  std::vector<RevisitLocalization> localizations;
  // Mean time a query frame took, ms: with segments the front end and the localization (the
  // pipeline's stage times), with Scan Context the scan context, the retrieval and the
  // registration. None: no query frame.
  std::optional<double> ms_per_query;
  size_t below_0_5m = 0, below_1m = 0, below_5m = 0, wrong = 0;
  std::optional<double> mean_translation_error_m, mean_rotation_error_deg;  // none: unknown
  size_t revisits_localized = 0;  // revisit frames localized within correct_m
  size_t ambiguous = 0;           // relocalizations that fit another place too: no pose
  // The covariances against the errors (LocalizationSummary): none without a localization.
  std::optional<double> share_mahalanobis_within_3, mean_nees, median_sigma_m;
  std::vector<WakeUp> wake_ups;  // with wake-ups only
  // check_ground_truth: localizations with a registered ground truth, and their errors to it.
  size_t registered_compared = 0;
  size_t registered_below_0_3m = 0;  // and 1 degree: the real-data target
  double mean_registered_error_m = 0.0, mean_registered_rotation_error_deg = 0.0;
  std::filesystem::path dir;  // its files, relative to the output directory
};

struct RevisitExperiment {
  RevisitExperimentConfig config;
  std::string dataset;
  bool odometry_is_ground_truth = false;  // the query frames' odometry is the ground truth
  std::vector<RevisitFrame> queries;
  size_t revisits = 0;    // query frames at a revisit
  size_t registered = 0;  // check_ground_truth: query frames whose registration worked
  double mean_correction_m = 0.0, max_correction_m = 0.0;
  std::vector<RevisitResult> results;
  std::vector<double> thresholds;  // of the cumulative curves, m
  bool interrupted = false;        // the stop request ended it early: `queries` are those done
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
