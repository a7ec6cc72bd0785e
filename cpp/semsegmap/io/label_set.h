// Label sets: label images made once and reused (`semsegmap label` writes them, `--labels DIR`
// reads them), or made by another tool. DIR/labels.yaml says what the ids mean and what the set
// labels; DIR/camK/NNNNNN.png is the 8-bit label image of camera K's picture in frame NNNNNN
// (docs/class-maps.md).
#pragma once

#include <filesystem>
#include <string>

namespace semsegmap {

struct LabelSetInfo {
  // What the ids mean: "semsegmap" (the project's own), a shipped class map's name or a class
  // map file relative to the set. Required: ids read in another class table are wrong silently.
  std::string class_map = "semsegmap";
  size_t frames = 0;  // the frames it labels: 0 to frames - 1 (`label --max-frames` labels fewer)
  // Frames of the dataset it was made from; 0: not said (sets written before the key, or by
  // another tool), and then `frames` may be more than the set labels.
  size_t dataset_frames = 0;
  size_t cameras = 0;   // cameras of its rig
  std::string dataset;  // what it was made from (for people; not checked)
  std::string model;
  // `semsegmap label` was stopped (Ctrl-C) before labelling the frames it was asked to: the
  // set is whole for its `frames`, and shorter than asked. Written only when true.
  bool interrupted = false;
};

// Writes DIR/labels.yaml atomically: written last, it says that the set is whole.
void writeLabelSetInfo(const std::filesystem::path& dir, const LabelSetInfo& info);
// Throws std::runtime_error naming DIR/labels.yaml and the field when it is missing or wrong.
LabelSetInfo readLabelSetInfo(const std::filesystem::path& dir);
std::filesystem::path labelSetImage(const std::filesystem::path& dir, size_t camera, size_t frame);

}  // namespace semsegmap
