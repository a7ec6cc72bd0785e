// What a recording gives besides geometry, and the descriptor model that suits it: a model
// trained on coloured, labelled points sees out-of-distribution input on a LiDAR without a
// camera, so a configuration may name a LiDAR-only model (descriptor.model_lidar_only) that is
// taken instead whenever the input has neither colour nor classes.
#pragma once

#include <string>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/pipeline/pipeline_config.h"

namespace semsegmap {

struct InputModalities {
  bool color = false;    // cameras give the points colour
  bool classes = false;  // cameras (label images or a network) or point labels give classes
};

// From the dataset's rig and labels. A camera counts for both: its classes come from label
// images or from the configuration's semantics network.
InputModalities inputModalitiesOf(const DatasetInfo& info);

std::string modalitiesText(const InputModalities& m);  // "colour and classes", "geometry only", ...

struct DescriptorChoice {
  DescriptorConfig descriptor;  // the configuration's, with the model that suits the input
  std::string note;             // what was chosen or assumed and why; empty when nothing to say
};

// The configuration's model, or model_lidar_only for input with neither colour nor classes. A
// semsegmap-net model on geometry-only input without a LiDAR-only model configured is kept,
// with a note that says so (it was trained on colour and classes). Other kinds see geometry
// only and are never changed.
DescriptorChoice chooseDescriptor(const DescriptorConfig& descriptor, const InputModalities& input);

}  // namespace semsegmap
