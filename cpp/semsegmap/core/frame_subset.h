// Some frames of a dataset, numbered from 0 in the order given, as the sessions and the frame
// loops expect: the map and query frames of a revisit check, or a recording's scans taken far
// apart. `datasetFrame` maps a number back.
#pragma once

#include <utility>
#include <vector>

#include "semsegmap/core/frame_source.h"

namespace semsegmap {

class FrameSubset : public FrameSource {
 public:
  FrameSubset(FrameSource& source, std::vector<size_t> frames)
      : source_(source), frames_(std::move(frames)) {}
  const DatasetInfo& info() const override { return source_.info(); }
  size_t size() const override { return frames_.size(); }
  Frame frame(size_t index) override {
    Frame f = source_.frame(frames_.at(index));
    f.index = index;
    return f;
  }
  double frameTime(size_t index) override { return source_.frameTime(frames_.at(index)); }
  std::optional<size_t> frameNumber(size_t index) override {
    return source_.frameNumber(frames_.at(index));
  }
  size_t datasetFrame(size_t index) const { return frames_.at(index); }

 private:
  FrameSource& source_;
  std::vector<size_t> frames_;
};

}  // namespace semsegmap
