#include "semsegmap/localize/scan_context.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

namespace semsegmap {

namespace {

void checkConfig(const ScanContextConfig& c) {
  if (c.rings == 0 || c.sectors == 0 || !(c.max_radius_m > 0))
    throw std::invalid_argument(
        "scan context: need at least one ring and one sector, and a positive max radius");
}

std::string gridText(const Eigen::MatrixXf& bins) {
  return std::to_string(bins.rows()) + " x " + std::to_string(bins.cols());
}

// The sector shift as a yaw in (-pi, pi].
double yawOfShift(size_t shift, size_t sectors) {
  const double yaw = 2.0 * M_PI * static_cast<double>(shift) / static_cast<double>(sectors);
  return yaw > M_PI ? yaw - 2.0 * M_PI : yaw;
}

// 1 - mean cosine similarity of the column pairs where both columns hold a point, pairing the
// query's column j with the candidate's j + shift; 1 when no pair does.
double distanceAtShift(const ScanContext& query, const ScanContext& candidate,
                       const Eigen::VectorXf& query_norms, const Eigen::VectorXf& candidate_norms,
                       size_t shift) {
  const size_t sectors = static_cast<size_t>(query.bins.cols());
  double similarity = 0.0;
  size_t pairs = 0;
  for (size_t j = 0; j < sectors; ++j) {
    const size_t k = (j + shift) % sectors;
    if (query_norms(j) == 0 || candidate_norms(k) == 0) continue;
    similarity += query.bins.col(j).dot(candidate.bins.col(k)) /
                  (static_cast<double>(query_norms(j)) * candidate_norms(k));
    ++pairs;
  }
  return pairs > 0 ? 1.0 - similarity / static_cast<double>(pairs) : 1.0;
}

}  // namespace

ScanContext makeScanContext(const std::vector<LidarPoint>& points, const ScanContextConfig& config,
                            const Eigen::Matrix3d& R_level_sensor) {
  checkConfig(config);
  ScanContext sc;
  sc.bins = Eigen::MatrixXf::Zero(config.rings, config.sectors);
  const double ring_width = config.max_radius_m / static_cast<double>(config.rings);
  const double sector_width = 2.0 * M_PI / static_cast<double>(config.sectors);
  for (const LidarPoint& p : points) {
    const Eigen::Vector3d q = R_level_sensor * Eigen::Vector3d(p.x, p.y, p.z);
    if (!q.allFinite()) continue;
    const double range = std::hypot(q.x(), q.y());
    // A point straight above or below the sensor has no azimuth.
    if (range >= config.max_radius_m || range == 0.0) continue;
    double azimuth = std::atan2(q.y(), q.x());
    if (azimuth < 0) azimuth += 2.0 * M_PI;
    const size_t ring = std::min(config.rings - 1, static_cast<size_t>(range / ring_width));
    const size_t sector = std::min(config.sectors - 1, static_cast<size_t>(azimuth / sector_width));
    // A point below the offset (a ditch, a slope down) still occupies its bin: an empty bin is 0.
    const float height = std::max(1e-3f, static_cast<float>(q.z() + config.height_offset_m));
    float& bin = sc.bins(static_cast<Eigen::Index>(ring), static_cast<Eigen::Index>(sector));
    bin = std::max(bin, height);
  }
  return scanContextOfBins(std::move(sc.bins));
}

Pose scanContextFrame(const Pose& T_world_base, const Pose& T_base_lidar) {
  Pose T_base_scan = Pose::Identity();
  T_base_scan.translation() = T_base_lidar.translation();
  return T_world_base * T_base_scan;
}

ScanContext scanContextOfBins(Eigen::MatrixXf bins) {
  ScanContext sc;
  sc.bins = std::move(bins);
  sc.ring_key = Eigen::VectorXf::Zero(sc.bins.rows());
  for (Eigen::Index r = 0; r < sc.bins.rows(); ++r) {
    const auto occupied = static_cast<size_t>((sc.bins.row(r).array() > 0).count());
    sc.occupied += occupied;
    sc.ring_key(r) = static_cast<float>(occupied) / static_cast<float>(sc.bins.cols());
  }
  return sc;
}

ScanContextDistance scanContextDistance(const ScanContext& query, const ScanContext& candidate) {
  if (query.bins.rows() != candidate.bins.rows() || query.bins.cols() != candidate.bins.cols())
    throw std::invalid_argument("scan context: cannot compare a " + gridText(query.bins) +
                                " grid with a " + gridText(candidate.bins) + " one");
  ScanContextDistance best;
  if (query.empty() || candidate.empty()) return best;
  const Eigen::VectorXf query_norms = query.bins.colwise().norm().transpose();
  const Eigen::VectorXf candidate_norms = candidate.bins.colwise().norm().transpose();
  const size_t sectors = static_cast<size_t>(query.bins.cols());
  for (size_t shift = 0; shift < sectors; ++shift) {
    const double d = distanceAtShift(query, candidate, query_norms, candidate_norms, shift);
    if (d < best.distance) best = {d, shift, yawOfShift(shift, sectors)};
  }
  return best;
}

Pose ScanContextMatch::T_world_query() const {
  return T_world_candidate * Eigen::AngleAxisd(distance.yaw_rad, Eigen::Vector3d::UnitZ());
}

ScanContextDatabase::ScanContextDatabase(const ScanContextConfig& config) : config_(config) {
  checkConfig(config);
}

size_t ScanContextDatabase::add(ScanContext context, const Pose& T_world_scan) {
  if (static_cast<size_t>(context.bins.rows()) != config_.rings ||
      static_cast<size_t>(context.bins.cols()) != config_.sectors)
    throw std::invalid_argument("scan context database: a " + gridText(context.bins) +
                                " scan context in a database of " + std::to_string(config_.rings) +
                                " x " + std::to_string(config_.sectors));
  scans_.push_back({std::move(context), T_world_scan});
  return scans_.size() - 1;
}

uint64_t ScanContextDatabase::bytes() const {
  uint64_t bytes = 0;
  for (const MappedScan& scan : scans_)
    bytes += (scan.context.bins.size() + scan.context.ring_key.size()) * sizeof(float);
  return bytes;
}

std::vector<ScanContextMatch> ScanContextDatabase::nearest(const ScanContext& query,
                                                           size_t candidates, size_t n) const {
  if (query.empty()) return {};
  std::vector<std::pair<float, size_t>> by_key;
  for (size_t i = 0; i < scans_.size(); ++i)
    if (!scans_[i].context.empty())
      by_key.emplace_back((scans_[i].context.ring_key - query.ring_key).squaredNorm(), i);
  const size_t m = std::min(candidates, by_key.size());
  std::partial_sort(by_key.begin(), by_key.begin() + static_cast<std::ptrdiff_t>(m), by_key.end());
  std::vector<ScanContextMatch> found;
  for (size_t k = 0; k < m; ++k) {
    const MappedScan& scan = scans_[by_key[k].second];
    found.push_back(
        {by_key[k].second, scanContextDistance(query, scan.context), scan.T_world_scan});
  }
  std::stable_sort(found.begin(), found.end(), [](const auto& a, const auto& b) {
    return a.distance.distance < b.distance.distance;
  });
  if (found.size() > n) found.resize(n);
  return found;
}

std::optional<ScanContextMatch> ScanContextDatabase::best(const ScanContext& query) const {
  const std::vector<ScanContextMatch> found = nearest(query, config_.candidates, 1);
  if (found.empty()) return std::nullopt;
  return found[0];
}

std::optional<ScanContextMatch> ScanContextDatabase::query(const ScanContext& query) const {
  std::optional<ScanContextMatch> found = best(query);
  if (found && found->distance.distance >= config_.max_distance) return std::nullopt;
  return found;
}

}  // namespace semsegmap
