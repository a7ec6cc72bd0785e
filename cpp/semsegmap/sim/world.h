// The procedural residential neighbourhood that the simulator renders: a grid of streets with
// jittered intersections, houses in their lots, vegetation and street furniture, parked cars
// drawn from a separate traffic seed, and moving agents. Deterministic from the seeds.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/core/class_table.h"

namespace semsegmap::sim {

struct WorldConfig {
  uint64_t seed = 1;
  int grid_nodes = 5;             // intersections per side: (n-1)^2 blocks
  double block_spacing_m = 92.0;  // a loop around one block is about 380 m (the paper's S2)
  double node_jitter_m = 5.0;     // irregular blocks, so no two streets look the same
  double road_width_m = 7.0;
  double sidewalk_width_m = 2.0;
  double parked_car_probability = 0.35;  // per curb slot of 7 m
  int moving_cars = 6;
  int pedestrians = 10;
  double street_light_spacing_m = 32.0;
};

// Named presets: "full" (the paper-sized neighbourhood), "small" (the demo), "tiny" (tests).
WorldConfig worldPreset(const std::string& name, uint64_t seed);

// A triangle mesh whose triangles each carry the index of the surface they belong to.
struct Mesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<uint32_t> triangle_surface;
};

// What a ray that hits a triangle sees: class, object instance and material.
struct Surface {
  ClassId class_id = cls::kOther;
  uint16_t instance_id = 0;
  Eigen::Vector3f albedo{0.5f, 0.5f, 0.5f};  // linear RGB in [0, 1]
  float texture = 0.0f;                      // amplitude of procedural brightness noise
};

// A labelled object, for pictures and ground-truth bookkeeping.
struct WorldObject {
  uint16_t instance_id = 0;
  ClassId class_id = cls::kOther;
  std::string kind;  // "house", "tree", "hedge", "parked-car", ...
  Eigen::Vector2d center_xy{0, 0};
  double radius_m = 0.0;
};

struct RoadNetwork {
  int grid_nodes = 0;
  std::vector<Eigen::Vector2d> nodes;  // node (i, j) at index j * grid_nodes + i
  std::vector<std::pair<int, int>> edges;
  double road_width_m = 0.0;
  double sidewalk_width_m = 0.0;
  int node(int i, int j) const { return j * grid_nodes + i; }
};

// Something that moves: its mesh is given in its own frame (x forward, z up) and is placed at
// time t by walking `path` (a closed polyline) at `speed_mps` from arc length `start_m`.
struct Agent {
  Mesh mesh;
  std::vector<Surface> surfaces;
  std::vector<Eigen::Vector2d> path;
  double speed_mps = 0.0;
  double start_m = 0.0;
  uint16_t instance_id = 0;
  ClassId class_id = cls::kCar;
  // World pose of the agent at time t as (x, y, yaw).
  Eigen::Vector3d poseAt(double t) const;
};

struct World {
  WorldConfig config;
  uint64_t traffic_seed = 0;
  RoadNetwork roads;
  Mesh mesh;  // everything static, parked cars included
  std::vector<Surface> surfaces;
  std::vector<WorldObject> objects;
  std::vector<Agent> agents;
  Eigen::Vector2d min_xy{0, 0}, max_xy{0, 0};
};

// Instance ids of the world seed's objects are the same whatever the traffic seed, because
// traffic is generated after them with ids from kTrafficInstanceBase; that keeps ground-truth
// associations valid across runs that see different cars.
constexpr uint16_t kTrafficInstanceBase = 60000;

World generateWorld(const WorldConfig& config, uint64_t traffic_seed);

}  // namespace semsegmap::sim
