// A synthetic town of box-shaped buildings for relocalization (tests and bench/): each building
// is a map segment with points on its walls and a random descriptor, and a robot's local segments
// are the buildings near it, sampled afresh, seen from its own frame, their descriptors the map's
// with noise.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "semsegmap/core/pose.h"
#include "semsegmap/core/random.h"
#include "semsegmap/localize/target_map.h"

namespace semsegmap {

using Points = std::vector<Eigen::Vector3f>;

struct Building {
  Eigen::Vector3f centre;
  Eigen::Vector3f size;  // x, y, height
};

// Points on the four walls of a building, about one every `spacing_m` at random.
inline Points wallsOf(const Building& b, SeededRng& rng, double spacing_m) {
  Points out;
  const float perimeter = 2 * (b.size.x() + b.size.y());
  const int n = static_cast<int>(perimeter * b.size.z() / (spacing_m * spacing_m));
  for (int i = 0; i < n; ++i) {
    float along = static_cast<float>(rng.uniform(0, perimeter));
    const float z = static_cast<float>(rng.uniform(0, b.size.z()));
    Eigen::Vector3f p = b.centre - 0.5f * Eigen::Vector3f(b.size.x(), b.size.y(), 0);
    const float sx = b.size.x(), sy = b.size.y();
    if (along < sx) {
      p += Eigen::Vector3f(along, 0, z);
    } else if ((along -= sx) < sy) {
      p += Eigen::Vector3f(sx, along, z);
    } else if ((along -= sy) < sx) {
      p += Eigen::Vector3f(sx - along, sy, z);
    } else {
      p += Eigen::Vector3f(0, sy - (along - sx), z);
    }
    out.push_back(p);
  }
  return out;
}

// A town of `n` buildings of random size and place on a side_m square, and its map.
struct Town {
  std::vector<Building> buildings;
  TargetMap map;
};

inline Town makeTown(int n, double side_m, uint64_t seed, int dimension = 16,
                     size_t max_points_per_segment = 0) {
  SeededRng rng(seed);
  Town town;
  town.map.descriptor = "eigen";
  town.map.descriptors.resize(n, dimension);
  for (int i = 0; i < n; ++i) {
    Building b{Eigen::Vector3f(static_cast<float>(rng.uniform(0, side_m)),
                               static_cast<float>(rng.uniform(0, side_m)), 0),
               Eigen::Vector3f(static_cast<float>(rng.uniform(3, 15)),
                               static_cast<float>(rng.uniform(3, 15)),
                               static_cast<float>(rng.uniform(3, 10)))};
    town.buildings.push_back(b);
    MapSegment s;
    s.points = wallsOf(b, rng, 0.5);
    if (max_points_per_segment > 0) s.points = subsamplePoints(s.points, max_points_per_segment);
    s.centroid = b.centre + Eigen::Vector3f(0, 0, b.size.z() / 2);
    s.n_points = static_cast<uint32_t>(s.points.size());
    town.map.segments.push_back(s);
    for (int d = 0; d < dimension; ++d)
      town.map.descriptors(i, d) = static_cast<float>(rng.gaussian(1));
  }
  return town;
}

// The local segments of a robot at `robot` (map frame) whose local frame is T_map_local^-1 of
// the map's: the buildings within radius_m, their points sampled again, their descriptors the
// map's plus noise of `noise` sigma.
struct Query {
  std::vector<Eigen::Vector3f> centroids;
  Eigen::MatrixXf descriptors;
  std::vector<Points> points;
  Eigen::Vector3d robot_local;
};

inline Query queryAt(const Town& town, const Eigen::Vector3d& robot, const Pose& T_map_local,
                     double radius_m, double noise, uint64_t seed, double spacing_m = 0.7) {
  SeededRng rng(seed);
  const Pose T_local_map = T_map_local.inverse();
  Query q;
  std::vector<Eigen::VectorXf> rows;
  for (size_t i = 0; i < town.buildings.size(); ++i) {
    const Building& b = town.buildings[i];
    if ((b.centre.head<2>().cast<double>() - robot.head<2>()).norm() > radius_m) continue;
    Points points;
    for (const Eigen::Vector3f& p : wallsOf(b, rng, spacing_m))
      points.push_back((T_local_map * p.cast<double>()).cast<float>());
    q.points.push_back(points);
    q.centroids.push_back(
        (T_local_map * town.map.segments[i].centroid.cast<double>()).cast<float>());
    Eigen::VectorXf d = town.map.descriptors.row(static_cast<Eigen::Index>(i)).transpose();
    for (int k = 0; k < d.size(); ++k) d[k] += static_cast<float>(rng.gaussian(noise));
    rows.push_back(d);
  }
  q.descriptors.resize(static_cast<Eigen::Index>(rows.size()), town.map.dimension());
  for (size_t i = 0; i < rows.size(); ++i)
    q.descriptors.row(static_cast<Eigen::Index>(i)) = rows[i];
  q.robot_local = T_local_map * robot;
  return q;
}

inline Pose someLocalFrame() {
  return Eigen::Translation3d(-420.0, 135.0, 2.0) *
         Eigen::AngleAxisd(2.1, Eigen::Vector3d::UnitZ());
}

}  // namespace semsegmap
