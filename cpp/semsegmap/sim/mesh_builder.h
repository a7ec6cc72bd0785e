// Appends primitive shapes to a Mesh. Every primitive is closed and its triangles face outward,
// so shading can trust the geometric normal.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "semsegmap/sim/world.h"

namespace semsegmap::sim {

class MeshBuilder {
 public:
  MeshBuilder(Mesh& mesh, std::vector<Surface>& surfaces) : mesh_(mesh), surfaces_(surfaces) {}

  uint32_t addSurface(const Surface& s);

  // Box of size (length along the yawed x, width, height) standing on z = base_z.
  void addBox(const Eigen::Vector2d& center_xy, double base_z, const Eigen::Vector3d& size,
              double yaw, uint32_t surface);
  // Gable roof over a box footprint: ridge along the yawed x axis.
  void addGableRoof(const Eigen::Vector2d& center_xy, double base_z, double length, double width,
                    double ridge_height, double yaw, uint32_t surface);
  // Vertical cylinder (n-gon prism) standing on base_z.
  void addCylinder(const Eigen::Vector2d& center_xy, double base_z, double radius, double height,
                   int segments, uint32_t surface);
  // Ellipsoid centred at `center` with radii, as a subdivided octahedron.
  void addEllipsoid(const Eigen::Vector3d& center, const Eigen::Vector3d& radii, int subdivisions,
                    uint32_t surface);
  // Cone standing on base_z.
  void addCone(const Eigen::Vector2d& center_xy, double base_z, double radius, double height,
               int segments, uint32_t surface);
  // Flat convex polygon at height z facing up (ground patches).
  void addGroundPolygon(const std::vector<Eigen::Vector2d>& polygon, double z, uint32_t surface);
  // Thin vertical panel in front of a wall: the panel's outward normal is `normal_xy`.
  void addPanel(const Eigen::Vector2d& center_xy, const Eigen::Vector2d& normal_xy, double base_z,
                double width, double height, double thickness, uint32_t surface);

 private:
  void addTriangle(int a, int b, int c, uint32_t surface);
  int addVertex(const Eigen::Vector3d& v);

  Mesh& mesh_;
  std::vector<Surface>& surfaces_;
};

}  // namespace semsegmap::sim
