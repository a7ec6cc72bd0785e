// Sums run in double so that the result does not depend on the order of the points beyond the
// last float bit: the descriptors must not change when a segment's points come shuffled.
#include "semsegmap/describe/net_input.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include <Eigen/Core>

#include "semsegmap/core/random.h"

namespace semsegmap {

namespace {

constexpr double kPi = 3.14159265358979323846;

uint64_t floatBits(float f) {
  uint32_t u = 0;
  std::memcpy(&u, &f, sizeof u);
  return u;
}

uint64_t pointHash(const EnrichedPoint& p, uint64_t salt) {
  return hashKeys(salt ^ (static_cast<uint64_t>(p.class_id) << 1 | (p.has_color ? 1u : 0u)),
                  floatBits(p.x) | floatBits(p.y) << 32, floatBits(p.z) | floatBits(p.h) << 32,
                  floatBits(p.s) | floatBits(p.v) << 32);
}

// Full order on points, for the (astronomically rare) hash ties between different points.
bool pointLess(const EnrichedPoint& a, const EnrichedPoint& b) {
  return std::tie(a.x, a.y, a.z, a.h, a.s, a.v, a.class_id, a.has_color) <
         std::tie(b.x, b.y, b.z, b.h, b.s, b.v, b.class_id, b.has_color);
}

Eigen::Vector3d centroidOf(const EnrichedCloud& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const EnrichedPoint& p : points) sum += Eigen::Vector3d(p.x, p.y, p.z);
  return sum / static_cast<double>(points.size());
}

void requireNonEmpty(const EnrichedCloud& points, const char* who) {
  if (points.empty()) throw std::invalid_argument(std::string(who) + ": segment has no points");
}

// Clamped before the conversion to int, which would be undefined for a NaN or a huge value.
int cellOf(double value, double lo, double size, int cells) {
  const double cell = std::floor((value - lo) / size * cells);
  if (!(cell > 0.0)) return 0;
  return cell >= cells - 1 ? cells - 1 : static_cast<int>(cell);
}

double principalYawAbout(const EnrichedCloud& points, const Eigen::Vector3d& c) {
  double cxx = 0, cyy = 0, cxy = 0;
  for (const EnrichedPoint& p : points) {
    const double dx = p.x - c.x(), dy = p.y - c.y();
    cxx += dx * dx;
    cyy += dy * dy;
    cxy += dx * dy;
  }
  double yaw = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
  const double ux = std::cos(yaw), uy = std::sin(yaw);
  double skew = 0;
  for (const EnrichedPoint& p : points) {
    const double t = (p.x - c.x()) * ux + (p.y - c.y()) * uy;
    skew += t * t * t;
  }
  if (skew < 0) yaw += yaw > 0 ? -kPi : kPi;
  return yaw;
}

}  // namespace

std::array<float, 3> colorFeatures(const EnrichedPoint& p) {
  if (!p.has_color) return {0.0f, 0.0f, 0.0f};
  const double angle = 2.0 * kPi * p.h;
  return {static_cast<float>(p.s * std::cos(angle)), static_cast<float>(p.s * std::sin(angle)),
          2.0f * p.v - 1.0f};
}

std::vector<uint32_t> hashSubsample(const EnrichedCloud& points, int count, uint64_t salt) {
  requireNonEmpty(points, "hashSubsample");
  if (count <= 0) throw std::invalid_argument("hashSubsample: count must be positive");
  std::vector<std::pair<uint64_t, uint32_t>> keyed(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    keyed[i] = {pointHash(points[i], salt), static_cast<uint32_t>(i)};
  }
  const auto less = [&](const std::pair<uint64_t, uint32_t>& a,
                        const std::pair<uint64_t, uint32_t>& b) {
    if (a.first != b.first) return a.first < b.first;
    return pointLess(points[a.second], points[b.second]);
  };
  const size_t keep = std::min(keyed.size(), static_cast<size_t>(count));
  if (keep < keyed.size()) {
    std::nth_element(keyed.begin(), keyed.begin() + static_cast<std::ptrdiff_t>(keep), keyed.end(),
                     less);
  }
  std::sort(keyed.begin(), keyed.begin() + static_cast<std::ptrdiff_t>(keep), less);
  std::vector<uint32_t> out(static_cast<size_t>(count));
  for (size_t i = 0; i < out.size(); ++i) out[i] = keyed[i % keep].second;
  return out;
}

PointNetSample makePointNetSample(const EnrichedCloud& points, int num_points, int num_classes,
                                  int recon_grid, uint64_t salt, bool use_color, bool use_classes) {
  requireNonEmpty(points, "makePointNetSample");
  const Eigen::Vector3d c = centroidOf(points);
  double max_distance = 0;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const EnrichedPoint& p : points) {
    const Eigen::Vector3d q(p.x, p.y, p.z);
    max_distance = std::max(max_distance, (q - c).norm());
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  PointNetSample out;
  // A millimetre floor keeps a degenerate (single-location) segment finite.
  const double scale = std::max(max_distance, 1e-3);
  out.scale = static_cast<float>(scale);

  const std::vector<uint32_t> chosen = hashSubsample(points, num_points, salt);
  out.points.resize(static_cast<size_t>(num_points) * 6);
  for (size_t i = 0; i < chosen.size(); ++i) {
    const EnrichedPoint& p = points[chosen[i]];
    float* row = out.points.data() + 6 * i;
    row[0] = static_cast<float>((p.x - c.x()) / scale);
    row[1] = static_cast<float>((p.y - c.y()) / scale);
    row[2] = static_cast<float>((p.z - c.z()) / scale);
    const std::array<float, 3> color =
        use_color ? colorFeatures(p) : std::array<float, 3>{0.0f, 0.0f, 0.0f};
    std::copy(color.begin(), color.end(), row + 3);
  }

  // Class histograms over the bounding box; a flat axis puts everything in its middle cell. An
  // observation in which some points have a class leaves its unobserved points out (missing,
  // not a vote for unknown: a segment half in the picture gets the histogram of its seen half);
  // one without any class is a sensor without a network, every point in the unknown bin, as the
  // models were trained and measured on such input.
  const bool skip_unobserved =
      use_classes &&
      std::any_of(points.begin(), points.end(), [](const EnrichedPoint& p) { return p.has_class; });
  std::vector<double> counts(static_cast<size_t>(num_classes) * 27, 0.0);
  std::array<double, 27> totals{};
  for (const EnrichedPoint& p : points) {
    const Eigen::Vector3d q(p.x, p.y, p.z);
    int cell[3];
    for (int a = 0; a < 3; ++a) {
      const double size = hi[a] - lo[a];
      cell[a] = size > 0 ? cellOf(q[a], lo[a], size, 3) : 1;
    }
    const int flat = (cell[0] * 3 + cell[1]) * 3 + cell[2];
    if (skip_unobserved && !p.has_class) continue;
    // A point without a class is in the unknown bin whatever id it carries.
    const int cls =
        use_classes && p.has_class ? std::min<int>(p.class_id, num_classes - 1) : cls::kUnknown;
    counts[static_cast<size_t>(cls) * 27 + flat] += 1.0;
    totals[flat] += 1.0;
  }
  out.class_grid.resize(counts.size());
  for (size_t i = 0; i < counts.size(); ++i) {
    const double total = totals[i % 27];
    out.class_grid[i] = total > 0 ? static_cast<float>(counts[i] / total) : 0.0f;
  }

  const size_t r = static_cast<size_t>(recon_grid);
  out.occupancy.assign(r * r * r, 0.0f);
  for (const EnrichedPoint& p : points) {
    const Eigen::Vector3d q = (Eigen::Vector3d(p.x, p.y, p.z) - c) / scale;
    const size_t ix = static_cast<size_t>(cellOf(q.x(), -1.0, 2.0, recon_grid));
    const size_t iy = static_cast<size_t>(cellOf(q.y(), -1.0, 2.0, recon_grid));
    const size_t iz = static_cast<size_t>(cellOf(q.z(), -1.0, 2.0, recon_grid));
    out.occupancy[(ix * r + iy) * r + iz] = 1.0f;
  }
  return out;
}

double principalYaw(const EnrichedCloud& points) {
  requireNonEmpty(points, "principalYaw");
  return principalYawAbout(points, centroidOf(points));
}

OccupancyGridSample makeSegMapGrid(const EnrichedCloud& points, int grid_xy, int grid_z) {
  requireNonEmpty(points, "makeSegMapGrid");
  const Eigen::Vector3d c = centroidOf(points);
  const double yaw = principalYawAbout(points, c);
  const double cs = std::cos(yaw), sn = std::sin(yaw);
  std::vector<Eigen::Vector3d> aligned(points.size());
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (size_t i = 0; i < points.size(); ++i) {
    const double dx = points[i].x - c.x(), dy = points[i].y - c.y();
    aligned[i] = {cs * dx + sn * dy, -sn * dx + cs * dy, points[i].z - c.z()};
    lo = lo.cwiseMin(aligned[i]);
    hi = hi.cwiseMax(aligned[i]);
  }
  OccupancyGridSample out;
  const int cells[3] = {grid_xy, grid_xy, grid_z};
  Eigen::Vector3d origin;
  Eigen::Vector3d extent;
  for (int a = 0; a < 3; ++a) {
    extent[a] = std::max(hi[a] - lo[a], static_cast<double>(kSegMapMinExtentM[a]));
    origin[a] = 0.5 * (lo[a] + hi[a]) - 0.5 * extent[a];
    out.extent_m[a] = static_cast<float>(extent[a]);
  }
  const size_t gxy = static_cast<size_t>(grid_xy), gz = static_cast<size_t>(grid_z);
  out.occupancy.assign(gxy * gxy * gz, 0.0f);
  for (const Eigen::Vector3d& q : aligned) {
    size_t idx[3];
    for (int a = 0; a < 3; ++a) {
      idx[a] = static_cast<size_t>(cellOf(q[a], origin[a], extent[a], cells[a]));
    }
    out.occupancy[(idx[0] * gxy + idx[1]) * gz + idx[2]] = 1.0f;
  }
  return out;
}

}  // namespace semsegmap
