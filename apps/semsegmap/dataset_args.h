// The --dataset SPEC of every command that reads data, with the options that complete a robot's
// own recording: its rig file and the poses it lacks.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli_args.h"
#include "semsegmap/core/frame_source.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/describe/descriptor.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap::app {

// --dataset (required, described by `help`), --rig, --odometry (unless the command makes the
// odometry itself), --ground-truth, --kitti-calib, --labels (unless the command reads no
// labels), followed by `more`.
std::vector<OptionSpec> datasetOptions(const std::string& help, std::vector<OptionSpec> more,
                                       bool odometry_option = true, bool labels_option = true);

// openDataset() with those options. A command that takes --labels also gets the segmentation
// network of its --config's semantics: section, when it names one.
// `config` names the configuration whose odometry: and semantics: sections apply, for commands
// that take several (eval revisits); by default the command's --config.
std::unique_ptr<FrameSource> openDatasetArg(const CliArgs& a,
                                            const std::filesystem::path& config = {});
// The same for a command that runs one Pipeline (map, localize, slam): the network and LiDAR
// odometry come as stages for the pipeline to own (pipeline/front_end_stages.h), as they do for
// code that embeds it.
DatasetWithStages openDatasetForPipelineArg(const CliArgs& a);

// One line: how many pictures the segmentation network labelled, at what share of the cores,
// and how many scans took an earlier picture's labels or none (semantics/frame_labeler.h).
void printLabelling(const LabelingStats& s);

// The describer for the data `source` gives: descriptor.model, or descriptor.model_lidar_only
// for a LiDAR without a camera (chooseDescriptor); what was chosen or assumed is printed.
std::shared_ptr<Describer> describerFor(const DescriptorConfig& descriptor,
                                        const FrameSource& source);
std::shared_ptr<Describer> describerFor(const DescriptorConfig& descriptor,
                                        const DatasetInfo& info);

}  // namespace semsegmap::app
