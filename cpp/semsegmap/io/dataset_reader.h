// Reads a dataset directory in the project's format as a FrameSource.
#pragma once

#include <filesystem>
#include <vector>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

class DatasetReader : public FrameSource {
 public:
  // Reads meta.yaml and frames.csv; throws std::runtime_error naming the file and the problem.
  explicit DatasetReader(const std::filesystem::path& dir);
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return rows_.size(); }
  // Loads the frame's files; a missing, truncated or mis-sized file throws naming that file.
  Frame frame(size_t index) override;
  // From frames.csv: pose files pair scans by time without reading them.
  double frameTime(size_t index) override { return rows_.at(index).timestamp_s; }

 private:
  struct Row {
    size_t index;
    double timestamp_s;
    Pose odom;
    std::optional<Pose> gt;
  };
  std::filesystem::path dir_;
  DatasetInfo info_;
  std::vector<Row> rows_;
};

}  // namespace semsegmap
