// Lists of dataset specs and what is made of them: the world a spec's instance ids belong to,
// and the training set of the learned descriptors extracted from several datasets.
#pragma once

#include <string>
#include <vector>

#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/learn/training_data.h"

namespace semsegmap {

// "sim:world=N,preset=P" for a sim spec, whatever its run, condition, traffic or frames; the spec
// itself for anything else (a dataset directory is a world of its own).
std::string worldOf(const std::string& spec);

// openDataset() on each spec (with `options`: a segmentation network in options.semantics labels
// the pictures as a robot's would be), then appendObservations. Throws when a dataset has no
// ground-truth poses or no point instances (nothing to learn from).
TrainingSet extractTrainingSet(const std::vector<std::string>& specs,
                               const PipelineConfig& pipeline, const ExtractionConfig& config,
                               const ExtractionProgress& progress = {},
                               const DatasetOptions& options = {});

// A comma-separated list of dataset specs, where a sim spec has commas of its own: a token of
// the form key=value (no '/' or ':') continues the sim: spec before it, any other token starts a
// new spec; ';' always separates. "sim:world=1,run=S1,sim:world=1,run=S1,condition=sunrise"
// is two specs. Throws std::invalid_argument on an empty list or an empty spec.
std::vector<std::string> splitDatasetSpecs(const std::string& list);

}  // namespace semsegmap
