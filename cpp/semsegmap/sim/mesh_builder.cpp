#include "semsegmap/sim/mesh_builder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

namespace semsegmap::sim {

uint32_t MeshBuilder::addSurface(const Surface& s) {
  surfaces_.push_back(s);
  return static_cast<uint32_t>(surfaces_.size() - 1);
}

int MeshBuilder::addVertex(const Eigen::Vector3d& v) {
  mesh_.vertices.push_back(v.cast<float>());
  return static_cast<int>(mesh_.vertices.size() - 1);
}

void MeshBuilder::addTriangle(int a, int b, int c, uint32_t surface) {
  mesh_.triangles.emplace_back(a, b, c);
  mesh_.triangle_surface.push_back(surface);
}

void MeshBuilder::addBox(const Eigen::Vector2d& c, double base_z, const Eigen::Vector3d& size,
                         double yaw, uint32_t surface) {
  const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw));
  const Eigen::Vector2d ay(-ax.y(), ax.x());
  int v[8];
  for (int k = 0; k < 8; ++k) {
    const double sx = (k & 1) ? 0.5 : -0.5;
    const double sy = (k & 2) ? 0.5 : -0.5;
    const double z = (k & 4) ? base_z + size.z() : base_z;
    const Eigen::Vector2d p = c + ax * (sx * size.x()) + ay * (sy * size.y());
    v[k] = addVertex({p.x(), p.y(), z});
  }
  // Quads listed counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    addTriangle(v[q[0]], v[q[1]], v[q[2]], surface);
    addTriangle(v[q[0]], v[q[2]], v[q[3]], surface);
  }
}

void MeshBuilder::addGableRoof(const Eigen::Vector2d& c, double base_z, double length, double width,
                               double ridge_height, double yaw, uint32_t surface) {
  const Eigen::Vector2d ax(std::cos(yaw), std::sin(yaw));
  const Eigen::Vector2d ay(-ax.y(), ax.x());
  auto at = [&](double sx, double sy, double z) {
    const Eigen::Vector2d p = c + ax * (sx * length) + ay * (sy * width);
    return addVertex({p.x(), p.y(), z});
  };
  const int a = at(-0.5, -0.5, base_z), b = at(0.5, -0.5, base_z);
  const int cc = at(0.5, 0.5, base_z), d = at(-0.5, 0.5, base_z);
  const int r0 = at(-0.5, 0.0, base_z + ridge_height), r1 = at(0.5, 0.0, base_z + ridge_height);
  // Two slopes, two gable ends, and the bottom so the prism is closed.
  addTriangle(a, b, r1, surface);
  addTriangle(a, r1, r0, surface);
  addTriangle(cc, d, r0, surface);
  addTriangle(cc, r0, r1, surface);
  addTriangle(b, cc, r1, surface);
  addTriangle(d, a, r0, surface);
  addTriangle(a, d, cc, surface);
  addTriangle(a, cc, b, surface);
}

void MeshBuilder::addCylinder(const Eigen::Vector2d& c, double base_z, double radius, double height,
                              int segments, uint32_t surface) {
  std::vector<int> bottom, top;
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    const Eigen::Vector2d p = c + radius * Eigen::Vector2d(std::cos(a), std::sin(a));
    bottom.push_back(addVertex({p.x(), p.y(), base_z}));
    top.push_back(addVertex({p.x(), p.y(), base_z + height}));
  }
  const int cb = addVertex({c.x(), c.y(), base_z});
  const int ct = addVertex({c.x(), c.y(), base_z + height});
  for (int k = 0; k < segments; ++k) {
    const int n = (k + 1) % segments;
    addTriangle(bottom[k], bottom[n], top[n], surface);
    addTriangle(bottom[k], top[n], top[k], surface);
    addTriangle(ct, top[k], top[n], surface);
    addTriangle(cb, bottom[n], bottom[k], surface);
  }
}

void MeshBuilder::addCone(const Eigen::Vector2d& c, double base_z, double radius, double height,
                          int segments, uint32_t surface) {
  std::vector<int> ring;
  for (int k = 0; k < segments; ++k) {
    const double a = 2.0 * M_PI * k / segments;
    const Eigen::Vector2d p = c + radius * Eigen::Vector2d(std::cos(a), std::sin(a));
    ring.push_back(addVertex({p.x(), p.y(), base_z}));
  }
  const int apex = addVertex({c.x(), c.y(), base_z + height});
  const int cb = addVertex({c.x(), c.y(), base_z});
  for (int k = 0; k < segments; ++k) {
    const int n = (k + 1) % segments;
    addTriangle(ring[k], ring[n], apex, surface);
    addTriangle(cb, ring[n], ring[k], surface);
  }
}

void MeshBuilder::addEllipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& radii,
                               int subdivisions, uint32_t surface) {
  // Subdivide an octahedron on the unit sphere, then scale: a cheap, watertight blob.
  std::vector<Eigen::Vector3d> pts = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                      {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  std::vector<std::array<int, 3>> tris = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                          {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto midpoint = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      pts.push_back((pts[a] + pts[b]).normalized());
      const int id = static_cast<int>(pts.size() - 1);
      mid.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> next;
    for (const auto& t : tris) {
      const int ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({ab, t[1], bc});
      next.push_back({ca, bc, t[2]});
      next.push_back({ab, bc, ca});
    }
    tris.swap(next);
  }
  const int base = static_cast<int>(mesh_.vertices.size());
  for (const auto& p : pts) addVertex(center + p.cwiseProduct(radii));
  for (const auto& t : tris) addTriangle(base + t[0], base + t[1], base + t[2], surface);
}

void MeshBuilder::addGroundPolygon(const std::vector<Eigen::Vector2d>& polygon, double z,
                                   uint32_t surface) {
  // Fan triangulation; orientation fixed so that the normal points up.
  double area2 = 0.0;
  for (size_t k = 0; k < polygon.size(); ++k) {
    const auto& a = polygon[k];
    const auto& b = polygon[(k + 1) % polygon.size()];
    area2 += a.x() * b.y() - b.x() * a.y();
  }
  std::vector<int> v;
  for (const auto& p : polygon) v.push_back(addVertex({p.x(), p.y(), z}));
  if (area2 < 0) std::reverse(v.begin(), v.end());
  for (size_t k = 1; k + 1 < v.size(); ++k) addTriangle(v[0], v[k], v[k + 1], surface);
}

void MeshBuilder::addPanel(const Eigen::Vector2d& c, const Eigen::Vector2d& normal_xy,
                           double base_z, double width, double height, double thickness,
                           uint32_t surface) {
  const double yaw = std::atan2(normal_xy.y(), normal_xy.x());
  addBox(c + normal_xy * (0.5 * thickness), base_z, {thickness, width, height}, yaw, surface);
}

}  // namespace semsegmap::sim
