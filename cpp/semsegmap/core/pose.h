// Poses are Eigen::Isometry3d named T_target_source, so T_world_base * T_base_lidar reads right.
#pragma once

#include <Eigen/Geometry>
#include <array>

namespace semsegmap {

using Pose = Eigen::Isometry3d;

// x y z qx qy qz qw, the TUM trajectory order.
std::array<double, 7> toXyzQuat(const Pose& T);
Pose fromXyzQuat(const std::array<double, 7>& v);

// A pose on the ground plane: position (x, y, z) and heading yaw about +z.
Pose planarPose(double x, double y, double z, double yaw_rad);
double yawOf(const Pose& T);

// The pose a fraction w in [0, 1] of the way from a to b: linear in position, slerp in rotation.
Pose interpolatePose(const Pose& a, const Pose& b, double w);

// Translation distance in metres and rotation angle in degrees between two poses.
double translationError(const Pose& a, const Pose& b);
double rotationErrorDeg(const Pose& a, const Pose& b);

}  // namespace semsegmap
