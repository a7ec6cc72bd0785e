#include "semsegmap/odometry/lidar_odometry.h"

#include <algorithm>
#include <cmath>

#include "semsegmap/odometry/motion.h"

namespace semsegmap {

namespace {

FilteredScan filterScan(const std::vector<LidarPoint>& points, const std::vector<float>& times,
                        const OdometryConfig& config) {
  FilteredScan out;
  const bool timed = times.size() == points.size();
  const double min_sq = config.min_range_m * config.min_range_m;
  const double max_sq = config.max_range_m * config.max_range_m;
  out.points.reserve(points.size());
  if (timed) out.times.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p(points[i].x, points[i].y, points[i].z);
    if (!p.allFinite() || (timed && !std::isfinite(times[i]))) {
      ++out.nonfinite;
      continue;
    }
    const double r_sq = p.squaredNorm();
    if (r_sq < min_sq || r_sq > max_sq) continue;
    out.points.push_back(p);
    if (timed) out.times.push_back(times[i]);
  }
  return out;
}

std::vector<Eigen::Vector3d> transformed(const Pose& T,
                                         const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> out(points.size());
  for (size_t i = 0; i < points.size(); ++i) out[i] = T * points[i];
  return out;
}

double rmsRange(const std::vector<Eigen::Vector3d>& points) {
  double sum = 0.0;
  for (const Eigen::Vector3d& p : points) sum += p.squaredNorm();
  return points.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(points.size()));
}

}  // namespace

const char* fallbackName(OdometryFallback fallback) {
  switch (fallback) {
    case OdometryFallback::kNone:
      return "none";
    case OdometryFallback::kFirstFrame:
      return "first frame";
    case OdometryFallback::kTooFewPoints:
      return "too few points";
    case OdometryFallback::kTooFewMatches:
      return "too few correspondences";
    case OdometryFallback::kNotFinite:
      return "solution not finite";
  }
  return "?";
}

LidarOdometry::LidarOdometry(const OdometryConfig& config)
    : config_(config),
      map_(config.voxel_size_m, config.max_points_per_voxel),
      threshold_(config.initial_threshold_m, config.min_motion_m, config.max_range_m) {}

Pose LidarOdometry::predictedDelta(double timestamp_s) const {
  const size_t n = poses_.size();
  if (n < 2) return Pose::Identity();
  const Pose last = poses_[n - 2].inverse() * poses_[n - 1];
  const double dt_last = timestamps_[n - 1] - timestamps_[n - 2];
  const double dt = timestamp_s - timestamps_[n - 1];
  // Frames at a steady rate (or without times) repeat the last motion; a gap scales it.
  if (!(dt_last > 0) || !(dt > 0) || std::abs(dt - dt_last) < 1e-6) return last;
  return scaleMotion(last, std::min(dt / dt_last, 10.0));
}

LidarOdometry::Prepared LidarOdometry::prepare(const FilteredScan& scan, const Pose* motion,
                                               double dt) const {
  Prepared out;
  out.points = motion ? deskew(scan.points, scan.times, *motion, dt) : scan.points;
  out.frame = voxelDownsample(out.points, 0.5 * config_.voxel_size_m);
  out.source = voxelDownsample(out.frame, 1.5 * config_.voxel_size_m);
  return out;
}

OdometryResult LidarOdometry::registerFrame(const std::vector<LidarPoint>& points,
                                            const std::vector<float>& point_times,
                                            double timestamp_s) {
  OdometryResult result;
  result.input_points = points.size();
  const FilteredScan scan = filterScan(points, point_times, config_);
  result.skipped_nonfinite = scan.nonfinite;
  const Pose delta = predictedDelta(timestamp_s);
  const Pose prediction = pose() * delta;
  const double dt = timestamps_.empty() ? 0.0 : timestamp_s - timestamps_.back();
  const bool timed = config_.deskew && !scan.times.empty() && dt > 0;
  // Deskewing needs a velocity: at first the prediction's; without one (the second frame) none.
  Prepared prepared = prepare(scan, timed && poses_.size() >= 2 ? &delta : nullptr, dt);
  result.registration_points = prepared.source.size();
  const double sigma = threshold_.sigma();
  result.threshold_m = std::max(3.0 * sigma, config_.min_threshold_m);
  if (map_.empty()) {
    result.fallback = OdometryFallback::kFirstFrame;
    // The first sweep can only be deskewed once the second gives a velocity.
    if (config_.deskew && !scan.times.empty()) first_scan_ = scan;
    const Pose T = poses_.empty() ? Pose::Identity() : prediction;
    return finishFrame(result, T, timestamp_s, prepared.frame, prepared.points);
  }
  if (prepared.source.size() < static_cast<size_t>(std::max(1, config_.min_points))) {
    result.fallback = OdometryFallback::kTooFewPoints;
    return finishFrame(result, prediction, timestamp_s, {}, {});
  }
  IcpResult icp = align(prepared.source, prediction, sigma, result);
  if (timed && icp.enough_correspondences && icp.T.matrix().allFinite()) {
    // Once more with the sweep deskewed by the motion just found, which is better than the
    // prediction (and the only one there is at the second frame).
    const Pose motion = pose().inverse() * icp.T;
    prepared = prepare(scan, &motion, dt);
    if (poses_.size() == 1 && first_scan_) rebuildFirstFrame(motion, dt);
    icp = align(prepared.source, icp.T, sigma, result);
    result.deskewed = true;
  }
  if (!icp.enough_correspondences) {
    result.fallback = OdometryFallback::kTooFewMatches;
    return finishFrame(result, prediction, timestamp_s, {}, {});
  }
  if (!icp.T.matrix().allFinite()) {
    result.fallback = OdometryFallback::kNotFinite;
    return finishFrame(result, prediction, timestamp_s, {}, {});
  }
  // Without two poses there was no velocity to predict with: that frame's deviation says
  // nothing about the constant-velocity model.
  if (poses_.size() >= 2)
    threshold_.addDeviation(prediction.inverse() * icp.T, rmsRange(prepared.source));
  return finishFrame(result, icp.T, timestamp_s, prepared.frame, prepared.points);
}

IcpResult LidarOdometry::align(const std::vector<Eigen::Vector3d>& source, const Pose& initial,
                               double sigma, OdometryResult& result) const {
  const IcpResult icp =
      alignToMap(source, map_, initial, result.threshold_m, sigma / 3.0, config_.icp);
  result.iterations += icp.iterations;
  result.correspondences = icp.correspondences;
  result.degenerate_directions = icp.degenerate_directions;
  return icp;
}

void LidarOdometry::rebuildFirstFrame(const Pose& motion, double dt) {
  // The first frame went into the map as measured; now that the motion is known, its sweep is
  // deskewed with it (at constant velocity the first sweep moved as the second) and replaces it.
  const Prepared first = prepare(*first_scan_, &motion, dt);
  map_ = VoxelMap(config_.voxel_size_m, config_.max_points_per_voxel);
  map_.add(transformed(poses_.front(), first.frame), transformed(poses_.front(), first.points));
  first_scan_.reset();
}

OdometryResult LidarOdometry::finishFrame(OdometryResult& result, const Pose& T, double timestamp_s,
                                          const std::vector<Eigen::Vector3d>& frame,
                                          const std::vector<Eigen::Vector3d>& all_points) {
  // A pose that is not finite can only come from a prediction built on one; the last good pose
  // is kept instead, so that no NaN ever leaves the odometry.
  const Pose safe = T.matrix().allFinite() ? orthonormalized(T) : pose();
  poses_.push_back(safe);
  timestamps_.push_back(timestamp_s);
  if (!frame.empty()) {
    map_.add(transformed(safe, frame), transformed(safe, all_points));
    map_.removeFarFrom(safe.translation(), config_.max_range_m);
  }
  result.T_odom_lidar = safe;
  result.map_voxels = map_.voxelCount();
  return result;
}

}  // namespace semsegmap
