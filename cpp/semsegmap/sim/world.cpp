#include "semsegmap/sim/world.h"

#include <cmath>
#include <stdexcept>

#include "semsegmap/sim/polyline.h"
#include "semsegmap/sim/world_context.h"

namespace semsegmap::sim {

WorldConfig worldPreset(const std::string& name, uint64_t seed) {
  WorldConfig c;
  c.seed = seed;
  if (name == "full") return c;
  if (name == "small") {
    c.grid_nodes = 3;  // 2 x 2 blocks: the demo's neighbourhood
    c.moving_cars = 3;
    c.pedestrians = 5;
    return c;
  }
  if (name == "tiny") {
    c.grid_nodes = 3;
    c.block_spacing_m = 50.0;
    c.moving_cars = 1;
    c.pedestrians = 2;
    return c;
  }
  throw std::invalid_argument("unknown world preset '" + name + "' (expected full, small or tiny)");
}

Eigen::Vector3d Agent::poseAt(double t) const {
  const PolylinePoint p = pointAt(path, start_m + speed_mps * t, true);
  return {p.position.x(), p.position.y(), p.heading};
}

namespace detail {

uint16_t WorldContext::newObject(ClassId cls, const std::string& kind, const Eigen::Vector2d& c,
                                 double r) {
  if (next_instance_ == 0xffff) throw std::runtime_error("world generation: out of instance ids");
  const uint16_t id = next_instance_++;
  world.objects.push_back({id, cls, kind, c, r});
  return id;
}

uint32_t WorldContext::surface(ClassId cls, uint16_t instance, const Eigen::Vector3f& albedo,
                               float texture) {
  return mesh.addSurface({cls, instance, albedo, texture});
}

Eigen::Vector3f WorldContext::vary(const Eigen::Vector3f& albedo, double sigma) {
  const float s = static_cast<float>(1.0 + rng.gaussian(sigma));
  return (albedo * s).cwiseMax(0.01f).cwiseMin(1.0f);
}

double WorldContext::distanceToStreets(const Eigen::Vector2d& p) const {
  double best = 1e18;
  for (const auto& [a, b] : world.roads.edges)
    best = std::min(best, distanceToSegment(p, world.roads.nodes[a], world.roads.nodes[b]));
  return best;
}

bool WorldContext::isFree(const Circle& c, double street_margin) const {
  const double curb = 0.5 * world.roads.road_width_m + world.roads.sidewalk_width_m;
  if (distanceToStreets(c.c) < curb + street_margin + c.r) return false;
  for (const auto& o : occupied_)
    if ((o.c - c.c).norm() < o.r + c.r) return false;
  return true;
}

std::vector<Eigen::Vector2d> blockLoop(const RoadNetwork& roads, int i, int j, bool ccw,
                                       double lane_offset_m) {
  Polyline corners = {roads.nodes[roads.node(i, j)], roads.nodes[roads.node(i + 1, j)],
                      roads.nodes[roads.node(i + 1, j + 1)], roads.nodes[roads.node(i, j + 1)]};
  if (!ccw) std::reverse(corners.begin(), corners.end());
  // Right-hand traffic: the lane is to the right of the direction of travel.
  return offsetPolyline(corners, -lane_offset_m, true);
}

}  // namespace detail

World generateWorld(const WorldConfig& config, uint64_t traffic_seed) {
  if (config.grid_nodes < 3) throw std::invalid_argument("world: grid_nodes must be at least 3");
  if (!(config.block_spacing_m >= 40.0))
    throw std::invalid_argument("world: block_spacing_m must be at least 40");
  World world;
  world.config = config;
  world.traffic_seed = traffic_seed;

  // Intersections on a jittered grid, centred on the origin.
  SeededRng node_rng(hashKeys(config.seed, 0x5eed0001));
  RoadNetwork& roads = world.roads;
  roads.grid_nodes = config.grid_nodes;
  roads.road_width_m = config.road_width_m;
  roads.sidewalk_width_m = config.sidewalk_width_m;
  const double half_extent = 0.5 * (config.grid_nodes - 1) * config.block_spacing_m;
  for (int j = 0; j < config.grid_nodes; ++j)
    for (int i = 0; i < config.grid_nodes; ++i)
      roads.nodes.emplace_back(
          i * config.block_spacing_m - half_extent + node_rng.gaussian(config.node_jitter_m),
          j * config.block_spacing_m - half_extent + node_rng.gaussian(config.node_jitter_m));
  for (int j = 0; j < config.grid_nodes; ++j)
    for (int i = 0; i < config.grid_nodes; ++i) {
      if (i + 1 < config.grid_nodes)
        roads.edges.emplace_back(roads.node(i, j), roads.node(i + 1, j));
      if (j + 1 < config.grid_nodes)
        roads.edges.emplace_back(roads.node(i, j), roads.node(i, j + 1));
    }
  const double margin = 70.0;  // lots behind the outer streets
  world.min_xy = Eigen::Vector2d::Constant(-half_extent - margin);
  world.max_xy = Eigen::Vector2d::Constant(half_extent + margin);

  {
    detail::WorldContext ctx(world, hashKeys(config.seed, 0x5eed0002), 1);
    detail::buildStreets(ctx);
    detail::buildStreetFurniture(ctx);
    detail::buildLots(ctx);
  }
  {
    detail::WorldContext ctx(world, hashKeys(traffic_seed, 0x7aff1c), kTrafficInstanceBase);
    detail::buildTraffic(ctx);
  }
  return world;
}

}  // namespace semsegmap::sim
