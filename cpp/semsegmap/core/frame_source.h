// Where frames come from: the simulator streams them, io/ reads them from disk. The pipeline
// only sees this interface.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/frame.h"
#include "semsegmap/core/sensor_rig.h"

namespace semsegmap {

// Where a dataset's parts come from, in words, as `semsegmap info` shows them: the reader's
// choices (a topic, a file pattern, a pose file and the rule that matched its poses). Empty where
// the dataset has no such part.
struct DatasetOrigin {
  std::string kind;                  // how it was read: "rosbag", "folder", "kitti-raw", ...
  std::string lidar;                 // "topic /points (frame velodyne)", "velodyne/*.bin"
  std::vector<std::string> cameras;  // per rig camera, in its order: "topic /cam/image_raw"
  std::string odometry;              // "topic /odom", "TF odom -> base_link", "poses.txt: ..."
  std::string ground_truth;
  std::string label_images;  // the cameras' class images: "cam0_label/", "label set DIR"
  std::string point_labels;  // per-point classes: "labels/*.label"
};

struct DatasetInfo {
  std::string name;
  DatasetOrigin origin;
  SensorRig rig;
  ClassTable classes = ClassTable::Default();
  bool has_ground_truth_poses = false;
  // Whether Frame::T_odom_base comes from the data (wheel or visual odometry, a pose file, the
  // simulator's drifting odometry). Without it T_odom_base is meaningless, and running on it
  // is refused instead of reading identity poses.
  bool has_odometry = false;
  // Whether that odometry is the ground truth itself (a SemanticKITTI sequence's poses, KITTI
  // raw's oxts, NCLT's ground truth): errors measured against the ground truth then say how
  // well the run does with perfect odometry, and are marked so.
  bool odometry_is_ground_truth = false;
  // Whether the frame times come from the data (file names, a times file, the recording);
  // false: made up from the rate, so that poses cannot be matched to frames by time.
  bool has_frame_times = true;
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
  // The frame number in the name of the frame's scan (KITTI's 000042.bin is 42), to which a
  // KITTI pose file's line refers; nothing when the source does not name its scans by number.
  virtual std::optional<size_t> frameNumber(size_t /*index*/) { return std::nullopt; }
};

// How the dataset itself names a frame, for outputs that a user matches with the data: its
// number (Frame::number) and its time, each nothing when the data has none (a time made up from
// the rate is not the data's).
struct FrameStamp {
  std::optional<size_t> number;
  std::optional<double> time_s;
};
inline FrameStamp stampOf(const Frame& frame, bool has_frame_times) {
  return {frame.number, has_frame_times ? std::optional<double>(frame.timestamp_s) : std::nullopt};
}
inline FrameStamp stampOf(const Frame& frame, const DatasetInfo& info) {
  return stampOf(frame, info.has_frame_times);
}

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
