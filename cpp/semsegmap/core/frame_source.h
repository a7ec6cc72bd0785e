// Where frames come from: the simulator streams them, io/ reads them from disk. The pipeline
// only sees this interface.
#pragma once

#include <stdexcept>
#include <string>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/frame.h"
#include "semsegmap/core/sensor_rig.h"

namespace semsegmap {

struct DatasetInfo {
  std::string name;
  SensorRig rig;
  ClassTable classes = ClassTable::Default();
  bool has_ground_truth_poses = false;
  // Whether Frame::T_odom_base comes from the data (wheel or visual odometry, a pose file, the
  // simulator's drifting odometry). Without it T_odom_base is meaningless, and running on it
  // is refused instead of reading identity poses.
  bool has_odometry = false;
  bool has_point_labels = false;
  // Whether those labels carry classes; false: instance ids only (the simulator's `classes=0`,
  // ground truth for training a descriptor for a LiDAR without a camera), so the scans carry
  // no semantics.
  bool point_labels_have_classes = true;
  // Point instance ids from here on are traffic (parked and moving cars): no landmarks, and
  // another run of the same place has other ones. 0: the dataset has no such range.
  uint16_t first_transient_instance = 0;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  virtual const DatasetInfo& info() const = 0;
  virtual size_t size() const = 0;
  // Random access; throws with a message naming the file when a frame cannot be produced.
  virtual Frame frame(size_t index) = 0;
  // The time of a frame; sources that know it without reading the frame say so faster.
  virtual double frameTime(size_t index) { return frame(index).timestamp_s; }
};

// What every FrameSource throws for an index past its end.
[[noreturn]] inline void throwFrameOutOfRange(const std::string& dataset, size_t index,
                                              size_t frames) {
  throw std::out_of_range(dataset + ": frame " + std::to_string(index) + " out of range (" +
                          std::to_string(frames) + " frames)");
}

// How many frames a run reads of `source`: the first max_frames, or all when it is 0.
inline size_t framesToRead(const FrameSource& source, size_t max_frames) {
  return max_frames > 0 && max_frames < source.size() ? max_frames : source.size();
}

}  // namespace semsegmap
