#include "semsegmap/sim/polyline.h"

#include <algorithm>
#include <cmath>

namespace semsegmap::sim {

namespace {
Eigen::Vector2d leftNormal(const Eigen::Vector2d& d) {
  return {-d.y(), d.x()};
}
}  // namespace

Polyline offsetPolyline(const Polyline& p, double offset, bool closed) {
  const size_t n = p.size();
  Polyline out;
  if (n < 2) return p;
  auto dir = [&](size_t k) { return (p[(k + 1) % n] - p[k]).normalized().eval(); };
  for (size_t k = 0; k < n; ++k) {
    const bool has_prev = closed || k > 0;
    const bool has_next = closed || k + 1 < n;
    if (!has_prev) {
      out.push_back(p[k] + leftNormal(dir(k)) * offset);
    } else if (!has_next) {
      out.push_back(p[k] + leftNormal(dir(k - 1)) * offset);
    } else {
      const Eigen::Vector2d d0 = dir((k + n - 1) % n), d1 = dir(k);
      const Eigen::Vector2d n0 = leftNormal(d0), n1 = leftNormal(d1);
      // Mitre point: along the bisector of the two normals, scaled so both offsets hold.
      const Eigen::Vector2d m = (n0 + n1).normalized();
      const double cos_half = std::max(0.2, m.dot(n0));
      out.push_back(p[k] + m * (offset / cos_half));
    }
  }
  return out;
}

Polyline roundCorners(const Polyline& p, double cut_m, double step_m) {
  if (p.size() < 3) return p;
  Polyline out{p.front()};
  for (size_t k = 1; k + 1 < p.size(); ++k) {
    const Eigen::Vector2d a = p[k - 1], c = p[k], b = p[k + 1];
    const double cut = std::min({cut_m, (c - a).norm() / 3.0, (b - c).norm() / 3.0});
    const Eigen::Vector2d p0 = c + (a - c).normalized() * cut;
    const Eigen::Vector2d p2 = c + (b - c).normalized() * cut;
    const int steps = std::max(2, static_cast<int>(std::ceil(2.0 * cut / step_m)));
    for (int s = 0; s <= steps; ++s) {
      const double t = static_cast<double>(s) / steps;
      out.push_back((1 - t) * (1 - t) * p0 + 2 * (1 - t) * t * c + t * t * p2);
    }
  }
  out.push_back(p.back());
  return out;
}

double polylineLength(const Polyline& p, bool closed) {
  double len = 0.0;
  for (size_t k = 0; k + 1 < p.size(); ++k) len += (p[k + 1] - p[k]).norm();
  if (closed && p.size() > 1) len += (p.front() - p.back()).norm();
  return len;
}

PolylinePoint pointAt(const Polyline& p, double s, bool closed) {
  const double total = polylineLength(p, closed);
  if (closed) {
    s = std::fmod(s, total);
    if (s < 0) s += total;
  } else {
    s = std::clamp(s, 0.0, total);
  }
  const size_t segments = closed ? p.size() : p.size() - 1;
  for (size_t k = 0; k < segments; ++k) {
    const Eigen::Vector2d a = p[k], b = p[(k + 1) % p.size()];
    const double len = (b - a).norm();
    if (s <= len || k + 1 == segments) {
      const Eigen::Vector2d d = len > 0 ? ((b - a) / len).eval() : Eigen::Vector2d(1, 0);
      return {a + d * std::min(s, len), std::atan2(d.y(), d.x())};
    }
    s -= len;
  }
  return {p.front(), 0.0};
}

double distanceToSegment(const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0 ? std::clamp((q - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - q).norm();
}

}  // namespace semsegmap::sim
