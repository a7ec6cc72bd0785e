// Where a dataset's label images come from when it has none (or the user brings others): a label
// set made once (`--labels DIR`, io/label_set.h) or the segmentation network run on the fly
// (the config's `semantics:` section, semantics/frame_labeler.h). Both go through a class map,
// so a foreign id is never read as one of the project's.
#pragma once

#include <filesystem>
#include <memory>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/semantics/frame_labeler.h"

namespace semsegmap {

// Frames of `source` whose pictures take the label set's images (they replace the dataset's).
// Checks up front that the set was made from a dataset of this many frames and cameras, that it
// labels the frames the run reads (the first max_frames; 0: all) and that its class map reads; a
// picture without its label image, or of another size, is an error naming the file.
// `class_maps_dir` holds the shipped class maps.
std::unique_ptr<FrameSource> withLabelSet(std::unique_ptr<FrameSource> source,
                                          const std::filesystem::path& dir,
                                          const std::filesystem::path& class_maps_dir,
                                          size_t max_frames = 0);

// The network of `config` (model, class map) loaded and checked against every camera of the rig
// before any frame is read.
std::shared_ptr<SegmentationNetwork> loadSegmentationNetwork(
    const SemanticsConfig& config, const DatasetInfo& info,
    const std::filesystem::path& class_maps_dir);

// Frames of `source` whose pictures without labels get them from the network. `stats()` of the
// returned source's labeler tells how often it ran (labelerOf).
std::unique_ptr<FrameSource> withSegmentationNetwork(std::unique_ptr<FrameSource> source,
                                                     std::shared_ptr<SegmentationNetwork> network);

// The labeler inside a source made by withSegmentationNetwork, or nullptr.
const FrameLabeler* labelerOf(const FrameSource& source);

}  // namespace semsegmap
