// The localization experiment (paper section IV-D, Table I): map one simulated run, localize
// other runs of the same world against the map, every configuration on the very same frames
// (each frame is rendered once and fed to every configuration's pipeline).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/json.h"
#include "semsegmap/eval/experiment.h"
#include "semsegmap/odometry/lidar_odometry.h"
#include "semsegmap/pipeline/modes.h"
#include "semsegmap/semantics/frame_labeler.h"

namespace semsegmap {

// Where the camera labels of one pass over the runs come from.
struct LabelPass {
  std::string labels = "perfect";  // for the files and tables: "network", "network,rate=2"
  // This segmentation network's labels replace the simulator's in every run (map and queries),
  // within the budget of its settings (replayed on the data's clock); the same labels reach
  // every configuration. Empty model: the simulator's labels.
  SemanticsConfig network;
  // Every configuration of the pass removes the ground by geometry as well as by class
  // (local_map.geometric_ground_removal): what a network's labels need (its file says so).
  bool geometric_ground_removal = false;
  // The learned descriptor trained on this network's labels (the network file's
  // descriptor.model, of kind descriptor_kind): the pass's configurations of that kind describe
  // with it instead of their own model, as a robot with this network would. Empty: their own.
  std::string descriptor_kind, descriptor_model;
  std::filesystem::path dir;  // the pass's maps and runs, under the output folder ("": in it)
};

struct LocalizationExperimentConfig {
  uint64_t world_seed = 1;
  std::string preset = "full";  // sim::worldPreset
  std::string map_run = "S0";
  std::vector<std::string> query_runs = {"S2", "S3"};
  size_t max_frames = 0;  // per run; 0: all
  // Camera labels of every run as a segmentation network's (sim/label_noise.h): 0 perfect.
  int label_noise = 0;
  // Every pass runs every configuration on the very same rendered frames: a network's pass
  // labels its own copy of each frame, so the renderer (most of a frame's time) runs once.
  std::vector<LabelPass> label_passes = {LabelPass{}};
  std::filesystem::path class_maps_dir;  // the shipped class maps, for a network's class_map
  // Simulator keys appended to every run's spec: the rig, e.g. "lidar=hdl64,cameras=front".
  std::string rig;
  // The query runs' odometry from LiDAR odometry on their scans (odometry/), with these
  // settings, instead of the simulator's drifting odometry.
  bool lidar_odometry = false;
  OdometryConfig odometry;
  std::vector<NamedConfig> configs;  // compared side by side (semsegmap, segmap)
  double correct_m = 1.0;            // a localization this close counts for recall
  double wrong_m = 5.0;              // a localization farther off is wrong
  double recall_window_m = 20.0;
  size_t picture_points_per_segment = 32;  // kept in memory for the pictures, not saved
  // Checked before each frame (Ctrl-C in the CLI): the run in hand ends with its frames done
  // (a map of them, or that query run's results) and no further run starts.
  StopToken stop;
};

struct LocalizationResult {  // one configuration on one query run
  std::string config, descriptor, fingerprint, run, dataset;
  std::string labels;       // LabelPass::labels
  LabelingStats labelling;  // of the query run, when a network labelled it
  size_t frames = 0;
  double distance_m = 0.0;
  LocalizationSummary summary;
  size_t wrong = 0;         // error > wrong_m
  double wrong_rate = 0.0;  // wrong / localizations
  double recall = 0.0;      // along the trajectory, see eval/localization_metrics.h
  double hz = 0.0;          // the whole pipeline
  StageTimes per_frame;     // mean stage times
  size_t map_segments = 0;
  uint64_t map_bytes = 0;
  std::vector<double> errors;      // translation error of each localization, m
  std::vector<size_t> cumulative;  // localizations within each of the experiment's thresholds
  std::filesystem::path dir;       // its files, relative to the output directory
};

struct LocalizationExperiment {
  LocalizationExperimentConfig config;
  std::vector<LocalizationResult> results;  // query run major, then pass, then configuration
  std::vector<double> thresholds;           // of the cumulative curves, m
  // LocalizationExperimentConfig::stop ended it early: `results` hold the query runs done, the
  // last of them over its frames done (none when the stop came while mapping).
  bool interrupted = false;
};

// Maps the map run and localizes the query runs with every configuration. What each run leaves
// behind is written into `out` as the run finishes (a run's records are not kept):
// maps/<config>.map and <config>_<run>/ (localizations.csv, summary.json, localization.png).
LocalizationExperiment evaluateLocalization(const LocalizationExperimentConfig& config,
                                            const std::filesystem::path& out,
                                            const ExperimentProgress& progress = {});

// localization.json: the configuration and every number of every run.
nlohmann::ordered_json toJson(const LocalizationExperiment& e);

// Writes into `out` localization.json and localization_accuracy.png (the cumulative number of
// localizations against the error threshold, one panel per query run; none without a run done).
void writeLocalizationFiles(const LocalizationExperiment& e, const std::filesystem::path& out);

// evaluateLocalization, then writeLocalizationFiles.
LocalizationExperiment runLocalizationExperiment(const LocalizationExperimentConfig& config,
                                                 const std::filesystem::path& out,
                                                 const ExperimentProgress& progress = {});

// The results as a Markdown table (one row per run and configuration).
std::string localizationTable(const LocalizationExperiment& e);

// The paper's Table I localizations (SegMap, SemSegMap) for a run of the full-sized world;
// {-1, -1} for other runs and presets, beside which the paper's counts would mislead.
std::pair<int, int> paperLocalizations(const std::string& run, const std::string& preset);

}  // namespace semsegmap
