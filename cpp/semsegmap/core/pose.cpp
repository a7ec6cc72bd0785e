#include "semsegmap/core/pose.h"

#include <cmath>

namespace semsegmap {

std::array<double, 7> toXyzQuat(const Pose& T) {
  const Eigen::Quaterniond q(T.linear());
  const Eigen::Vector3d t = T.translation();
  return {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
}

Pose fromXyzQuat(const std::array<double, 7>& v) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::Quaterniond(v[6], v[3], v[4], v[5]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
  return T;
}

Pose planarPose(double x, double y, double z, double yaw_rad) {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

double yawOf(const Pose& T) {
  return std::atan2(T.linear()(1, 0), T.linear()(0, 0));
}

double translationError(const Pose& a, const Pose& b) {
  return (a.translation() - b.translation()).norm();
}

double rotationErrorDeg(const Pose& a, const Pose& b) {
  const Eigen::AngleAxisd d(a.linear().transpose() * b.linear());
  return std::abs(d.angle()) * 180.0 / M_PI;
}

Pose interpolatePose(const Pose& a, const Pose& b, double w) {
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  Pose T = Pose::Identity();
  T.linear() = qa.slerp(w, qb).normalized().toRotationMatrix();
  T.translation() = (1.0 - w) * a.translation() + w * b.translation();
  return T;
}

}  // namespace semsegmap
