#include "semsegmap/odometry/motion.h"

#include <Eigen/Geometry>

namespace semsegmap {

Pose scaleMotion(const Pose& delta, double s) {
  const Eigen::AngleAxisd rotation(delta.linear());
  Pose scaled = Pose::Identity();
  scaled.linear() = Eigen::AngleAxisd(rotation.angle() * s, rotation.axis()).toRotationMatrix();
  scaled.translation() = delta.translation() * s;
  return scaled;
}

Pose orthonormalized(const Pose& T) {
  Pose out = T;
  out.linear() = Eigen::Quaterniond(T.linear()).normalized().toRotationMatrix();
  return out;
}

std::vector<Eigen::Vector3d> deskew(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<double>& times, const Pose& motion,
                                    double duration_s) {
  std::vector<Eigen::Vector3d> out(points.size());
  if (!(duration_s > 0)) return points;
  // A spinning LiDAR measures a whole column at one time, so consecutive points mostly share
  // it: the pose is recomputed only when the time changes.
  double last_time = 0.0;
  Pose T_ref_point = Pose::Identity();
  for (size_t i = 0; i < points.size(); ++i) {
    if (i == 0 || times[i] != last_time) {
      last_time = times[i];
      T_ref_point = scaleMotion(motion, last_time / duration_s);
    }
    out[i] = T_ref_point * points[i];
  }
  return out;
}

}  // namespace semsegmap
