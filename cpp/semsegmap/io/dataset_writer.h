// Writes frames into a dataset directory in the project's format.
#pragma once

#include <filesystem>
#include <optional>
#include <utility>
#include <vector>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

class DatasetWriter {
 public:
  // Creates the directory (and its subfolders) and writes meta.yaml. A dataset already in `dir`
  // (one with a meta.yaml) is replaced; the format's folders without a meta.yaml are refused
  // rather than mixed with. Throws std::invalid_argument when the rig fails validate().
  DatasetWriter(const std::filesystem::path& dir, const DatasetInfo& info);
  // Writes the frame's files (each atomically), then appends its row to frames.csv and
  // flushes, so an interrupted conversion leaves a readable dataset of the frames written so far.
  void write(const Frame& frame);
  size_t framesWritten() const { return frames_written_; }

 private:
  // The checks of write(), all before the first file is written.
  void checkFrame(const Frame& frame) const;
  // Which cameras have an rgb and a label image, checked against the first frame's.
  std::pair<std::vector<bool>, std::vector<bool>> checkCameras(const Frame& frame) const;
  void writeFiles(const Frame& frame, const std::vector<bool>& has_rgb,
                  const std::vector<bool>& has_label);

  std::filesystem::path dir_;
  DatasetInfo info_;
  size_t frames_written_ = 0;
  // Indices must increase so that file names never collide and frames.csv stays sorted.
  std::optional<size_t> last_index_;
  // Which image streams exist is fixed by the first frame, so that every frame has the same
  // files and the reader can tell a missing file from a stream the dataset does not have.
  std::vector<bool> camera_has_rgb_;
  std::vector<bool> camera_has_label_;
  bool has_point_times_ = false;  // likewise lidar_times/
};

}  // namespace semsegmap
