#include "dataset_args.h"

#include <algorithm>
#include <cstdio>

#include "resources.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/pipeline/input_modalities.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::app {

std::vector<OptionSpec> datasetOptions(const std::string& help, std::vector<OptionSpec> more,
                                       bool odometry_option, bool labels_option) {
  std::vector<OptionSpec> options = {
      {"dataset", Value::kText, "SPEC", "", help, kRequired},
      {"rig", Value::kText, "FILE", "", "rig file of a folder: dataset (docs/rig-format.md)"},
      {"odometry", Value::kText, "FILE|lidar", "",
       "odometry poses of the base, TUM or KITTI format, or lidar: LiDAR odometry on the scans "
       "(replaces the dataset's)"},
      {"ground-truth", Value::kText, "FILE", "",
       "ground-truth poses of the base, TUM or KITTI format (replaces the dataset's)"},
      {"kitti-calib", Value::kText, "FILE", "",
       "KITTI calib.txt whose Tr turns KITTI camera-0 poses into LiDAR poses"},
      {"labels", Value::kText, "DIR", "",
       "label set whose images replace the dataset's (written by semsegmap label or another "
       "tool, docs/class-maps.md)"},
  };
  options.erase(std::remove_if(options.begin(), options.end(),
                               [&](const OptionSpec& o) {
                                 return (o.name == "odometry" && !odometry_option) ||
                                        (o.name == "labels" && !labels_option);
                               }),
                options.end());
  options.insert(options.end(), more.begin(), more.end());
  return options;
}

namespace {

DatasetOptions datasetOptionsOf(const CliArgs& a, const std::filesystem::path& config) {
  DatasetOptions options;
  if (a.has("rig")) options.rig = a.get("rig");
  const auto& declared = a.command().options;
  auto declares = [&](const char* name) {
    return std::any_of(declared.begin(), declared.end(),
                       [&](const OptionSpec& o) { return o.name == name; });
  };
  if (declares("odometry") && a.has("odometry")) options.odometry = a.get("odometry");
  std::filesystem::path sections = config;
  if (sections.empty() && declares("config") && a.has("config")) sections = a.get("config");
  // LiDAR odometry takes its settings from the odometry section of the command's config.
  if (options.odometry == "lidar" && !sections.empty())
    options.lidar_odometry = loadOdometryConfig(sections);
  // The segmentation network of the config's semantics: section labels pictures without labels.
  if (declares("labels") && !sections.empty()) options.semantics = loadSemanticsConfig(sections);
  if (!options.semantics.model.empty() && a.command().name != "label")
    checkReplayable(options.semantics, sections.string());
  // A label set holds every picture's own labels; a budget is for the pipelines that read it.
  if (a.command().name == "label" && !labelsEveryPicture(options.semantics)) {
    note(sections.string() +
         ": semantics: rate_hz, budget_cores and latency_s are for a pipeline; "
         "label labels every picture");
    options.semantics.rate_hz = options.semantics.budget_cores = options.semantics.latency_s = 0;
  }
  if (declares("labels") && a.has("labels")) options.labels = a.get("labels");
  if (!options.semantics.model.empty() || !options.labels.empty())
    options.class_maps_dir = shippedFile("config/class_maps");
  if (a.has("ground-truth")) options.ground_truth = a.get("ground-truth");
  if (a.has("kitti-calib")) options.kitti_calib = a.get("kitti-calib");
  // Only the frames the run reads are checked up front: --max-frames 1 on a long recording.
  if (declares("max-frames")) options.frames_to_check = a.frameLimit();
  return options;
}

}  // namespace

std::unique_ptr<FrameSource> openDatasetArg(const CliArgs& a, const std::filesystem::path& config) {
  return openDataset(a.get("dataset"), datasetOptionsOf(a, config));
}

DatasetWithStages openDatasetForPipelineArg(const CliArgs& a) {
  return openDatasetForPipeline(a.get("dataset"), datasetOptionsOf(a, {}));
}

void printLabelling(const LabelingStats& s) {
  std::printf(
      "network: %zu pictures labelled (%.1f ms each, %.2f of a core); pictures with "
      "their own labels %zu, an earlier picture's %zu, none within tolerance_s %zu\n",
      s.network_runs, s.network_runs ? s.network_ms / s.network_runs : 0.0, s.share(), s.own,
      s.reused, s.unlabelled);
}

std::shared_ptr<Describer> describerFor(const DescriptorConfig& descriptor,
                                        const FrameSource& source) {
  return describerFor(descriptor, source.info());
}

std::shared_ptr<Describer> describerFor(const DescriptorConfig& descriptor,
                                        const DatasetInfo& info) {
  const DescriptorChoice choice = chooseDescriptor(descriptor, inputModalitiesOf(info));
  if (!choice.note.empty()) note(choice.note);
  return makeDescriber(choice.descriptor);
}

}  // namespace semsegmap::app
