// What the eval commands share: comma lists and the configurations they compare.
#pragma once

#include <string>
#include <vector>

#include "cli_args.h"
#include "semsegmap/eval/experiment.h"
#include "semsegmap/eval/localization_experiment.h"

namespace semsegmap::app {

// The non-empty items of a list separated by `separator`.
std::vector<std::string> splitList(const std::string& s, char separator = ',');

// One label pass of `eval localization --labels` (the demo's network pass too):
// perfect | network[,rate=R][,budget=C][,every][,ground=classes|geometry][,descriptor=own]
// [,config=FILE]. Throws
// UsageError for a spec it cannot read.
LabelPass labelPass(const std::string& spec);

// --configs: SemSegMap first, the SegMap baseline second. The default list names shipped
// configs; a list the user types names their own files.
std::vector<NamedConfig> comparedConfigs(const CliArgs& a);

// The experiments on the simulator (eval segmentation, descriptors, localization, paper): only
// in a build with it (cmd_eval.cpp). `eval revisits` runs on any recording (cmd_eval_revisits),
// `eval semantics` on any dataset with cameras and per-point ground truth (cmd_eval_semantics).
const std::vector<const CommandSpec*>& simulatedEvalCommands();
const CommandSpec& evalRevisitsCommand();
const CommandSpec& evalSemanticsCommand();
const CommandSpec& evalLabelsCommand();

}  // namespace semsegmap::app
