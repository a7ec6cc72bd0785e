// A small TF buffer: the transforms of a bag's /tf_static and /tf as a tree of frames, and the
// transform between any two connected frames at a time, with dynamic transforms interpolated
// (linear in position, slerp in rotation). What tf2's buffer does for a recording, without ROS.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/stamped_pose.h"
#include "semsegmap/io/ros_messages.h"

namespace semsegmap::rosmsg {

// A frame name as TF compares it: ROS 1 allowed a leading '/', tf2 drops it.
std::string tfFrameName(const std::string& frame_id);

class TfBuffer {
 public:
  // Dynamic transforms further apart than max_gap_s are not interpolated across (a gap in the
  // recording); a time up to max_extrapolation_s before the first or after the last sample takes
  // that sample (a scan stamped a few milliseconds before the first /tf).
  explicit TfBuffer(double max_gap_s = 1.0, double max_extrapolation_s = 0.1)
      : max_gap_s_(max_gap_s), max_extrapolation_s_(max_extrapolation_s) {}

  // Adds the transform header.frame_id <- child_frame_id. A static one holds at every time; a
  // dynamic one is a sample at its stamp. A frame has one parent: a later parent replaces the
  // earlier one, as in tf2. Throws std::invalid_argument for a zero quaternion or a transform of
  // a frame to itself.
  void add(const TransformStamped& t, bool is_static);
  void add(const TfMessage& m, bool is_static) {
    for (const TransformStamped& t : m.transforms) add(t, is_static);
  }

  bool hasFrame(const std::string& frame) const;
  bool empty() const { return edges_.empty(); }

  // T_target_source at time t: maps points given in `source` into `target`. Nothing when the two
  // frames are not connected or a dynamic transform on the way has no sample near t; then `why`
  // (when given) says which, naming the frames.
  std::optional<Pose> lookup(const std::string& target, const std::string& source, double t,
                             std::string* why = nullptr) const;

  // Whether every transform between the two connected frames is static (then any time gives the
  // same); false when they are not connected.
  bool isStatic(const std::string& target, const std::string& source) const;

 private:
  struct Edge {
    std::string parent;
    bool is_static = false;
    Pose T_parent_child = Pose::Identity();  // when static
    std::vector<StampedPose> samples;        // when dynamic, sorted by time
  };
  // The two frames' chains up to their nearest common ancestor, which is up_source[source_steps]
  // and up_target[target_steps].
  struct Path {
    std::vector<std::string> up_source, up_target;
    size_t source_steps = 0, target_steps = 0;
  };
  std::optional<Path> path(const std::string& target, const std::string& source) const;
  // The frames from `frame` up to the root of its tree, `frame` first.
  std::vector<std::string> chainToRoot(const std::string& frame) const;
  std::optional<Pose> edgePose(const std::string& child, const Edge& e, double t,
                               std::string* why) const;
  // T_ancestor_frame along the chain, or nothing.
  std::optional<Pose> poseInAncestor(const std::vector<std::string>& chain, size_t ancestor,
                                     double t, std::string* why) const;

  double max_gap_s_, max_extrapolation_s_;
  std::map<std::string, Edge> edges_;  // by child frame
};

}  // namespace semsegmap::rosmsg
