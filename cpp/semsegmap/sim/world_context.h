// Internal to world generation: the state shared by the street, lot and traffic generators.
#pragma once

#include <string>
#include <vector>

#include "semsegmap/core/random.h"
#include "semsegmap/sim/mesh_builder.h"
#include "semsegmap/sim/world.h"

namespace semsegmap::sim::detail {

struct Circle {
  Eigen::Vector2d c;
  double r;
};

class WorldContext {
 public:
  WorldContext(World& world, uint64_t seed, uint16_t first_instance)
      : world(world), mesh(world.mesh, world.surfaces), rng(seed), next_instance_(first_instance) {}

  // A fresh instance id, recorded as an object for pictures and ground truth.
  uint16_t newObject(ClassId cls, const std::string& kind, const Eigen::Vector2d& c, double r);
  uint32_t surface(ClassId cls, uint16_t instance, const Eigen::Vector3f& albedo, float texture);
  // Albedo with a small per-surface variation, so that no two walls are exactly alike.
  Eigen::Vector3f vary(const Eigen::Vector3f& albedo, double sigma = 0.05);

  // Free space test: not on a street or its sidewalks (with `street_margin` beyond the curb) and
  // not overlapping anything already placed.
  bool isFree(const Circle& c, double street_margin) const;
  void occupy(const Circle& c) { occupied_.push_back(c); }
  double distanceToStreets(const Eigen::Vector2d& p) const;

  World& world;
  MeshBuilder mesh;
  SeededRng rng;

 private:
  uint16_t next_instance_;
  std::vector<Circle> occupied_;
};

// A street (an edge of the road network) as a frame: from node a to node b, its direction and
// the direction to its left.
struct EdgeFrame {
  Eigen::Vector2d a, b, dir, left;
  double length;
};
EdgeFrame edgeFrame(const RoadNetwork& roads, const std::pair<int, int>& e);

// Stage generators, called in this order by generateWorld.
void buildStreets(WorldContext& ctx);          // ground, roads, sidewalks
void buildLots(WorldContext& ctx);             // houses, yards, lot vegetation, fences
void buildStreetFurniture(WorldContext& ctx);  // lights, signs, street trees
void buildTraffic(WorldContext& ctx);          // parked cars and moving agents (traffic seed)

// Closed polyline following block (i, j)'s streets in the right-hand lane, counter-clockwise
// when `ccw`; lane_offset_m from the centreline.
std::vector<Eigen::Vector2d> blockLoop(const RoadNetwork& roads, int i, int j, bool ccw,
                                       double lane_offset_m);

}  // namespace semsegmap::sim::detail
