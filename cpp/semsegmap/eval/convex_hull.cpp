#include "semsegmap/eval/convex_hull.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <stdexcept>
#include <utility>

#include <Eigen/Geometry>
#include <Eigen/SVD>

// Last: qhull's headers define short macros (True, False, FORALLfacets, ...).
#include <libqhull_r/qhull_ra.h>

namespace semsegmap {
namespace {

// Where qhull writes its messages. qhull prints warnings and long error reports (flat input is an
// error) to the error file, stderr if none is given; the experiment meets degenerate segments by
// the thousand, so they go nowhere. One stream for all threads: stdio locks it per write.
FILE* qhullSink() {
  static FILE* const sink = [] {
    // Exits if the header and the shared library disagree on the layout of qhull's structs.
    QHULL_LIB_CHECK
    FILE* file = std::fopen("/dev/null", "w");
    if (!file) throw std::runtime_error("convexHull: cannot open /dev/null for qhull's messages");
    return file;
  }();
  return sink;
}

// The facet's vertices in counter-clockwise order seen from outside (along `normal`). qhull
// stores a facet's vertices as an unordered set; ordering them by angle about their centroid needs
// no further qhull calls, which would run outside qhull's error handler.
void orderAroundNormal(const std::vector<Eigen::Vector3d>& vertices, const Eigen::Vector3d& normal,
                       std::vector<int>& polygon) {
  if (polygon.size() <= 3) {
    if (polygon.size() == 3) {
      const Eigen::Vector3d& p0 = vertices[polygon[0]];
      const Eigen::Vector3d side = (vertices[polygon[1]] - p0).cross(vertices[polygon[2]] - p0);
      if (side.dot(normal) < 0.0) std::swap(polygon[1], polygon[2]);
    }
    return;
  }
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i : polygon) centroid += vertices[i];
  centroid /= static_cast<double>(polygon.size());
  Eigen::Vector3d u = vertices[polygon[0]] - centroid;
  u -= normal * normal.dot(u);
  const Eigen::Vector3d w = normal.cross(u);  // (u, w, normal) is right-handed
  std::vector<std::pair<double, int>> by_angle;
  by_angle.reserve(polygon.size());
  for (int i : polygon) {
    const Eigen::Vector3d r = vertices[i] - centroid;
    by_angle.emplace_back(std::atan2(r.dot(w), r.dot(u)), i);
  }
  std::sort(by_angle.begin(), by_angle.end());
  for (size_t k = 0; k < polygon.size(); ++k) polygon[k] = by_angle[k].second;
}

// Copies qhull's finished hull into `hull`: vertices, planes, the facets fanned into triangles,
// box and volume. Returns the surface area.
double extractHull(qhT* qh, ConvexHull& hull) {
  std::vector<int> index(qh->vertex_id, -1);  // qhull vertex id -> index into hull.vertices
  std::vector<int> polygon;
  facetT* facet;
  vertexT *vertex, **vertexp;
  FORALLfacets {
    const Eigen::Vector3d normal(facet->normal[0], facet->normal[1], facet->normal[2]);
    hull.planes.emplace_back(normal.x(), normal.y(), normal.z(), facet->offset);
    polygon.clear();
    FOREACHvertex_(facet->vertices) {
      int& id = index[vertex->id];
      if (id < 0) {
        id = static_cast<int>(hull.vertices.size());
        hull.vertices.emplace_back(vertex->point[0], vertex->point[1], vertex->point[2]);
      }
      polygon.push_back(id);
    }
    orderAroundNormal(hull.vertices, normal, polygon);
    for (size_t k = 1; k + 1 < polygon.size(); ++k)
      hull.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
  }
  if (hull.vertices.empty()) return 0.0;

  hull.lower = hull.upper = hull.vertices.front();
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& v : hull.vertices) {
    hull.lower = hull.lower.cwiseMin(v);
    hull.upper = hull.upper.cwiseMax(v);
    centroid += v;
  }
  centroid /= static_cast<double>(hull.vertices.size());
  // Sum of the tetrahedra from the centroid to each outward triangle; the centroid as apex keeps
  // the terms small for hulls far from the origin.
  double six_volume = 0.0, twice_area = 0.0;
  for (const auto& t : hull.triangles) {
    const Eigen::Vector3d p0 = hull.vertices[t[0]] - centroid;
    const Eigen::Vector3d p1 = hull.vertices[t[1]] - centroid;
    const Eigen::Vector3d p2 = hull.vertices[t[2]] - centroid;
    six_volume += p0.dot(p1.cross(p2));
    twice_area += (p1 - p0).cross(p2 - p0).norm();
  }
  hull.volume = six_volume / 6.0;
  return twice_area / 2.0;
}

// One run of qhull on `coords` (x y z per point); fills `hull` on success and returns qhull's exit
// code. `joggle` adds option QJ: qhull perturbs the input by a few 1e-11 of the coordinates'
// magnitude, so that no precision problem can arise.
int runQhull(std::vector<double>& coords, bool joggle, ConvexHull& hull, double& area) {
  FILE* sink = qhullSink();
  // qhT is ~9 KB: on the heap, to be kind to the stacks of worker threads.
  auto state = std::make_unique<qhT>();
  qhT* qh = state.get();
  qh_zero(qh, sink);
  char plain[] = "qhull";
  char joggled[] = "qhull QJ";
  // No output file: qhull then prints nothing and only prepares the facet list.
  const int exitcode = qh_new_qhull(qh, 3, static_cast<int>(coords.size() / 3), coords.data(),
                                    False, joggle ? joggled : plain, nullptr, sink);
  if (exitcode == qh_ERRnone) area = extractHull(qh, hull);
  qh_freeqhull(qh, !qh_ALL);
  int curlong = 0, totlong = 0;
  qh_memfreeshort(qh, &curlong, &totlong);
  return exitcode;
}

// Whether the points lie on a plane or line up to the rounding of their coordinates. qhull does
// not reliably say so: it takes some such sets for a hull of ~1e-30 volume, and repeated points
// fail with a precision error whose joggled retry makes a ball of rounding size. The smallest
// singular value of the centred points is their spread across the flattest direction (it is the
// root of n times the smallest variance), computed to ~1e-16 of the largest, which the variance
// itself is not; rounding the coordinates makes it ~1e-16 of their magnitude times root n.
bool flat(const std::vector<double>& coords) {
  const Eigen::Index n = static_cast<Eigen::Index>(coords.size() / 3);
  const Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>> points(
      coords.data(), n, 3);
  const Eigen::RowVector3d mean = points.colwise().mean();
  const double magnitude = points.cwiseAbs().maxCoeff();
  const Eigen::Matrix<double, Eigen::Dynamic, 3> centred = points.rowwise() - mean;
  const Eigen::Vector3d spread = centred.jacobiSvd().singularValues();  // descending
  return spread[2] <= 1e-12 * magnitude * std::sqrt(static_cast<double>(n));
}

// Convex hull of packed coordinates (modified by nothing; non-const only for qhull's signature).
ConvexHull hullOfCoords(std::vector<double>& coords) {
  if (coords.size() < 12 || flat(coords)) return {};
  ConvexHull hull;
  double area = 0.0;
  int exitcode = runQhull(coords, false, hull, area);
  // Flat input that got past flat() fails with qh_ERRsingular: the hull is empty. Precision
  // trouble on a proper volume (nearly coincident or coplanar points) is retried with joggled
  // input.
  if (exitcode == qh_ERRprec || exitcode == qh_ERRtopology || exitcode == qh_ERRwide ||
      exitcode == qh_ERRqhull) {
    hull = ConvexHull();
    exitcode = runQhull(coords, true, hull, area);
  }
  if (exitcode != qh_ERRnone || !(hull.volume > 0.0)) return {};
  // Insurance for what flat() lets through: a hull whose thickness, 3 volume / area (1.5 times
  // that of a slab), is at the level of rounding is flat, so empty.
  const double magnitude =
      std::max(hull.lower.cwiseAbs().maxCoeff(), hull.upper.cwiseAbs().maxCoeff());
  if (3.0 * hull.volume <= 1e-12 * magnitude * area) return {};
  return hull;
}

template <typename Scalar>
ConvexHull convexHullOf(const std::vector<Eigen::Matrix<Scalar, 3, 1>>& points) {
  std::vector<double> coords;
  coords.reserve(3 * points.size());
  for (const auto& p : points) {
    if (!p.allFinite()) continue;
    coords.push_back(static_cast<double>(p.x()));
    coords.push_back(static_cast<double>(p.y()));
    coords.push_back(static_cast<double>(p.z()));
  }
  return hullOfCoords(coords);
}

// Signed distances of `vertices` to `planes`: row f, column i is plane f at vertex i. Column-major,
// so the distances of one vertex to all planes are contiguous.
Eigen::MatrixXd planeDistances(const std::vector<Eigen::Vector4d>& planes,
                               const std::vector<Eigen::Vector3d>& vertices) {
  const Eigen::Map<const Eigen::Matrix<double, 4, Eigen::Dynamic>> p(
      planes.front().data(), 4, static_cast<Eigen::Index>(planes.size()));
  const Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic>> x(
      vertices.front().data(), 3, static_cast<Eigen::Index>(vertices.size()));
  Eigen::MatrixXd d = p.topRows<3>().transpose() * x;
  d.colwise() += p.row(3).transpose();
  return d;
}

// Six times the signed volume swept from `centre` by the part of the surface of `s` that lies
// inside `other` (the volume of the cones from `centre` over those pieces). `d` holds the signed
// distances of s's vertices to other's planes, planeDistances(other.planes, s.vertices), and
// `outside` its column-wise maxima. Each triangle of s is kept whole, dropped, or clipped by
// those of other's planes that cut it.
//
// Where the surfaces of s and other lie on one plane (vertices within `tolerance` of it), the
// piece must be counted once: with `keep_shared` s's triangles there are not clipped by that
// plane, without it they are dropped. (The planes face the same way: facing opposite ways, the
// hulls would be apart, which the caller has ruled out.)
double sixVolumeInside(const ConvexHull& s, const ConvexHull& other, const Eigen::MatrixXd& d,
                       const Eigen::VectorXd& outside, bool keep_shared, double tolerance,
                       const Eigen::Vector3d& centre) {
  const Eigen::Index planes = d.rows();
  double six_volume = 0.0;
  std::vector<Eigen::Index> cuts;
  std::vector<Eigen::Vector3d> polygon, clipped;
  for (const auto& t : s.triangles) {
    // Well inside: kept whole, and too deep to share a plane with other's surface.
    const bool inside = std::max({outside[t[0]], outside[t[1]], outside[t[2]]}) < -tolerance;
    if (!inside) {
      const double* d0 = d.col(t[0]).data();
      const double* d1 = d.col(t[1]).data();
      const double* d2 = d.col(t[2]).data();
      bool dropped = false;
      cuts.clear();
      for (Eigen::Index f = 0; f < planes && !dropped; ++f) {
        const double a = d0[f], b = d1[f], c = d2[f];
        if (std::abs(a) <= tolerance && std::abs(b) <= tolerance && std::abs(c) <= tolerance)
          dropped = !keep_shared;  // on the plane: shared surface
        else if (a > 0.0 && b > 0.0 && c > 0.0)
          dropped = true;  // outside the plane
        else if (a > 0.0 || b > 0.0 || c > 0.0)
          cuts.push_back(f);  // partly outside
      }
      if (dropped) continue;
    }
    polygon.assign(
        {s.vertices[t[0]] - centre, s.vertices[t[1]] - centre, s.vertices[t[2]] - centre});
    if (!inside) {
      for (Eigen::Index f : cuts) {
        // Clip to n·x + d <= 0, in coordinates relative to the centre.
        const Eigen::Vector4d& plane = other.planes[static_cast<size_t>(f)];
        const Eigen::Vector3d n = plane.head<3>();
        const double offset = plane[3] + n.dot(centre);
        clipped.clear();
        for (size_t k = 0; k < polygon.size(); ++k) {
          const Eigen::Vector3d& p = polygon[k];
          const Eigen::Vector3d& q = polygon[(k + 1) % polygon.size()];
          const double sp = n.dot(p) + offset, sq = n.dot(q) + offset;
          if (sp <= 0.0) clipped.push_back(p);
          if ((sp <= 0.0) != (sq <= 0.0)) clipped.push_back(p + (sp / (sp - sq)) * (q - p));
        }
        polygon.swap(clipped);
        if (polygon.size() < 3) break;
      }
    }
    for (size_t k = 1; k + 1 < polygon.size(); ++k)
      six_volume += polygon[0].dot(polygon[k].cross(polygon[k + 1]));
  }
  return six_volume;
}

}  // namespace

ConvexHull convexHull(const std::vector<Eigen::Vector3d>& points) {
  return convexHullOf(points);
}

ConvexHull convexHull(const std::vector<Eigen::Vector3f>& points) {
  return convexHullOf(points);
}

double intersectionVolume(const ConvexHull& a, const ConvexHull& b) {
  if (a.empty() || b.empty()) return 0.0;
  // Boxes apart or touching: no volume in common. This rejects most pairs of a map's segments.
  if ((a.upper.array() <= b.lower.array()).any() || (b.upper.array() <= a.lower.array()).any())
    return 0.0;

  // Points within `tolerance` of a plane count as on it, where it matters: whether the hulls only
  // touch, and whether pieces of their surfaces lie on one plane. Rounding errors of the plane
  // distances scale with the magnitude of the coordinates (~1e-16 of it).
  const double magnitude = std::max({a.lower.cwiseAbs().maxCoeff(), a.upper.cwiseAbs().maxCoeff(),
                                     b.lower.cwiseAbs().maxCoeff(), b.upper.cwiseAbs().maxCoeff()});
  const double tolerance = 1e-11 * magnitude;

  const Eigen::MatrixXd a_to_b = planeDistances(b.planes, a.vertices);  // b's planes x a's vertices
  const Eigen::MatrixXd b_to_a = planeDistances(a.planes, b.vertices);
  // A facet with the whole other hull on its outer side separates the two (or they touch).
  if ((a_to_b.rowwise().minCoeff().array() >= -tolerance).any() ||
      (b_to_a.rowwise().minCoeff().array() >= -tolerance).any())
    return 0.0;
  // One hull inside the other: the intersection is the inner one, exactly.
  const Eigen::VectorXd a_outside = a_to_b.colwise().maxCoeff();  // > 0: outside b
  const Eigen::VectorXd b_outside = b_to_a.colwise().maxCoeff();
  if ((a_outside.array() <= tolerance).all()) return a.volume;
  if ((b_outside.array() <= tolerance).all()) return b.volume;

  // The surface of a ∩ b is the part of a's surface inside b and the part of b's inside a. By the
  // divergence theorem its volume is the sum of the cones from any point over the surface's pieces,
  // taken near the intersection to keep the terms small.
  const Eigen::Vector3d centre = (a.lower.cwiseMax(b.lower) + a.upper.cwiseMin(b.upper)) / 2.0;
  const double six_volume = sixVolumeInside(a, b, a_to_b, a_outside, true, tolerance, centre) +
                            sixVolumeInside(b, a, b_to_a, b_outside, false, tolerance, centre);
  return std::clamp(six_volume / 6.0, 0.0, std::min(a.volume, b.volume));
}

double convexHullIoU(const ConvexHull& a, const ConvexHull& b) {
  if (a.empty() || b.empty()) return 0.0;
  const double common = intersectionVolume(a, b);
  const double either = a.volume + b.volume - common;
  return either > 0.0 ? common / either : 0.0;
}

}  // namespace semsegmap
