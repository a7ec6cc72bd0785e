// The descriptor-retrieval experiment (paper section IV-C) as one call: segment a simulated run,
// describe every observation with each descriptor, and rank each partial observation's segment
// among the final observations of all segments (eval/descriptor_eval.h).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/json.h"
#include "semsegmap/eval/descriptor_eval.h"
#include "semsegmap/eval/experiment.h"

namespace semsegmap {

struct DescriptorExperimentConfig {
  uint64_t world_seed = 1;
  std::string preset = "full";
  std::string run = "S0";
  size_t max_frames = 0;
  NamedConfig segmentation;  // how the run is cut into segments
  std::filesystem::path models = "models";
  std::vector<std::string> descriptors = {"semsegmap-net", "segmap-cnn", "fpfh", "eigen"};
  int threads = 0;
  int max_k = 50;
  // The run-time completeness estimate's window (segment/completeness.h), frames; the agreement
  // of the others of `completeness_windows` is reported beside it.
  size_t completeness_window = 10;
  std::vector<size_t> completeness_windows = {3, 5, 10, 20, 40};
  // One-scan wake-ups: every wake_up_every-th frame of `wake_up_run` (the same world) segmented
  // on its own by a pipeline started empty, its segments looking for their landmark among the
  // final observations of `run`. 0: none.
  std::string wake_up_run = "S2";
  size_t wake_up_every = 5;
  // Checked before each frame and each descriptor (Ctrl-C in the CLI): the segments of the
  // frames done are ranked by the descriptors done.
  StopToken stop;
};

struct DescriptorExperiment {
  DescriptorExperimentConfig config;
  std::string dataset;
  size_t segments = 0, queries = 0;
  std::vector<CompletenessBand> bands;
  std::vector<DescriptorRetrieval> results;
  CompletenessAgreement agreement;             // of the configured window
  std::vector<CompletenessAgreement> windows;  // of each of completeness_windows
  std::string wake_up_dataset;
  size_t wake_ups = 0, wake_up_queries = 0;
  std::vector<DescriptorRetrieval> wake_up_results;  // per descriptor, bands of true completeness
  bool interrupted = false;                          // the stop request ended it early
};

// Segments the run and ranks the observations with every descriptor; writes nothing.
DescriptorExperiment evaluateDescriptors(const DescriptorExperimentConfig& config,
                                         const ExperimentProgress& progress = {});

// descriptors.json: every number, the retrieval curves per band included.
nlohmann::ordered_json toJson(const DescriptorExperiment& e);

// Writes descriptors.json and descriptors.png (one panel per completeness band) into `out`.
void writeDescriptorFiles(const DescriptorExperiment& e, const std::filesystem::path& out);

// evaluateDescriptors, then writeDescriptorFiles.
DescriptorExperiment runDescriptorExperiment(const DescriptorExperimentConfig& config,
                                             const std::filesystem::path& out,
                                             const ExperimentProgress& progress = {});

std::string descriptorTable(const DescriptorExperiment& e);  // Markdown: top-1, top-16 per band
// Markdown: the estimate's agreement per window, then top-16 per estimated band and on the
// one-scan wake-ups, per descriptor.
std::string completenessTable(const DescriptorExperiment& e);

}  // namespace semsegmap
