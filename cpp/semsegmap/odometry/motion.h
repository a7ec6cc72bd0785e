// Constant-velocity motion: a frame-to-frame motion scaled in time, and the deskewing of a sweep
// whose points were measured at different times while the sensor moved.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/pose.h"

namespace semsegmap {

// The motion a fraction s of `delta`: rotation angle and translation scaled by s (a constant
// twist; s may be negative or above 1).
Pose scaleMotion(const Pose& delta, double s);

// The pose with its rotation made exactly orthonormal again. Isometry3d::inverse() takes the
// transpose for the inverse, so a rounding error in a rotation triples through every
// inverse-and-compose of the constant-velocity prediction and blows up within a few dozen frames.
Pose orthonormalized(const Pose& T);

// Points measured at times[i] seconds after the reference time, each in the sensor frame of its
// own time, re-expressed in the sensor frame at the reference time, for a sensor that moves by
// `motion` (sensor frame at the reference time -> at the reference time + `duration_s`) per
// `duration_s`. times must have one entry per point.
std::vector<Eigen::Vector3d> deskew(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<double>& times, const Pose& motion,
                                    double duration_s);

}  // namespace semsegmap
