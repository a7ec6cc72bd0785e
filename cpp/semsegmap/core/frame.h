// One synchronised capture of the rig: the value type that flows from datasets and the
// simulator into the pipeline.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/core/image.h"
#include "semsegmap/core/pose.h"

namespace semsegmap {

// A LiDAR return in the LiDAR frame (KITTI's float32 layout).
struct LidarPoint {
  float x = 0, y = 0, z = 0, intensity = 0;
};

// Ground truth for one LiDAR point (simulation, or SemanticKITTI labels).
struct PointLabel {
  ClassId class_id = cls::kUnknown;
  uint16_t instance_id = 0;  // 0: no instance
  bool operator==(const PointLabel& o) const {
    return class_id == o.class_id && instance_id == o.instance_id;
  }
};

struct CameraFrame {
  Image rgb;    // 3 channels; empty when the dataset has no color
  Image label;  // 1 channel of class ids; empty when no semantics
  // Labels of an earlier picture of this camera (a segmentation network on a budget labels fewer
  // pictures than the LiDAR scans): the LiDAR's frame when that picture was taken, seen from this
  // scan's (T_then_now, from odometry). Points are moved by it before their class is read, so that
  // a static world keeps its classes while the robot drives. nullopt: the labels are this
  // picture's.
  std::optional<Pose> T_label_lidar;
};

struct Frame {
  size_t index = 0;  // in the source it came from (a subset numbers its frames from 0)
  // The dataset's own number of the frame, from its scan's name (KITTI's 000042.bin is 42; see
  // FrameSource::frameNumber); kept through subsets, so that outputs name the frame as the data
  // does. Nothing when the dataset does not name its scans by number.
  std::optional<size_t> number;
  double timestamp_s = 0.0;  // made up from the rate when !DatasetInfo::has_frame_times
  std::vector<LidarPoint> points;
  std::vector<PointLabel> point_labels;  // empty, or one per point
  // When each point was measured, in seconds after timestamp_s (a spinning LiDAR sweeps while
  // the robot moves); empty when the input has no per-point times.
  std::vector<float> point_times;
  std::vector<CameraFrame> cameras;  // in the order of SensorRig::cameras
  // Classes come from the cameras' labels in this run, also in a scan where no camera has any
  // yet (a network on a budget): point labels are then ground truth for evaluation, never an
  // input, and the scan's points are coloured without classes.
  bool camera_semantics = false;
  // Poses are named T_to_from, so that subscripts cancel: T_world_lidar = T_world_base *
  // rig.T_base_lidar. The odometry frame is where the robot's own odometry started; the world
  // frame is the dataset's ground truth, when it has one.
  Pose T_odom_base = Pose::Identity();
  std::optional<Pose> T_world_base;  // ground truth
};

}  // namespace semsegmap
