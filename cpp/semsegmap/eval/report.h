// report.md of `semsegmap eval paper` and `semsegmap demo`: every table and picture of the
// experiments that ran, the paper's numbers beside ours, and what produced them (commit,
// configurations, models, machine), so that a reader can judge and reproduce the results.
#pragma once

#include <string>
#include <vector>

#include "semsegmap/eval/descriptor_experiment.h"
#include "semsegmap/eval/localization_experiment.h"
#include "semsegmap/eval/segmentation_experiment.h"

namespace semsegmap {

struct ReportContext {
  std::string title = "SemSegMap evaluation";
  std::string command;  // how the report was made
  double seconds = 0.0;
  std::vector<std::string> pictures;  // extra pictures (relative paths) shown first
  std::string view;                   // a page of `semsegmap view` (relative path), linked first
  // Ctrl-C ended the experiments early: the report says its numbers are partial, and an
  // experiment that did not start is left out.
  bool interrupted = false;
};

// The commit of the working directory's repository ("unknown" outside one; "+changes" when it
// has uncommitted changes) and a one-line description of this machine.
std::string sourceCommit();
std::string machineDescription();

// Any experiment may be null (not run).
std::string paperReport(const ReportContext& context, const SegmentationExperiment* segmentation,
                        const DescriptorExperiment* descriptors,
                        const LocalizationExperiment* localization);

}  // namespace semsegmap
