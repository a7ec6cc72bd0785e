// Traffic, drawn from the traffic seed: parked cars at the curbs (so that two runs through the
// same streets see different cars) and agents that move: cars around blocks, people on sidewalks.
#include <cmath>

#include "semsegmap/sim/polyline.h"
#include "semsegmap/sim/world_context.h"

namespace semsegmap::sim::detail {

namespace {

const Eigen::Vector3f kCarPaint[] = {
    {0.85f, 0.85f, 0.85f}, {0.04f, 0.04f, 0.05f}, {0.5f, 0.52f, 0.55f}, {0.6f, 0.05f, 0.04f},
    {0.05f, 0.15f, 0.5f},  {0.08f, 0.3f, 0.12f},  {0.8f, 0.65f, 0.05f}, {0.3f, 0.3f, 0.32f}};

// A car in its own frame (x forward, origin on the ground at its centre).
void addCarBody(MeshBuilder& mb, const Eigen::Vector2d& c, double yaw, uint32_t paint,
                uint32_t glass, uint32_t tyre) {
  const Eigen::Vector2d fwd(std::cos(yaw), std::sin(yaw));
  const Eigen::Vector2d left(-fwd.y(), fwd.x());
  mb.addBox(c, 0.3, {4.4, 1.8, 0.75}, yaw, paint);
  mb.addBox(c - fwd * 0.3, 1.05, {2.4, 1.6, 0.55}, yaw, glass);
  for (double fx : {-1.4, 1.4})
    for (double sy : {-0.8, 0.8})
      mb.addBox(c + fwd * fx + left * sy, 0.0, {0.65, 0.25, 0.62}, yaw, tyre);
}

void addPersonBody(MeshBuilder& mb, uint32_t clothes, uint32_t trousers, uint32_t skin) {
  mb.addBox({0, 0}, 0.0, {0.3, 0.38, 0.85}, 0.0, trousers);
  mb.addBox({0, 0}, 0.85, {0.28, 0.46, 0.65}, 0.0, clothes);
  mb.addEllipsoid({0, 0, 1.65}, {0.11, 0.1, 0.13}, 1, skin);
}

}  // namespace

void buildTraffic(WorldContext& ctx) {
  World& w = ctx.world;
  const RoadNetwork& roads = w.roads;
  const double half_road = 0.5 * roads.road_width_m;

  // Parked cars: slots along both curbs, away from the intersections.
  for (const auto& e : roads.edges) {
    const auto [a, b, dir, left, length] = edgeFrame(roads, e);
    for (int side : {-1, 1}) {
      for (double s = 14.0; s < length - 14.0; s += 7.0) {
        if (!ctx.rng.chance(w.config.parked_car_probability)) continue;
        const Eigen::Vector2d c = a + dir * s + left * (side * (half_road - 1.15));
        const double yaw = std::atan2(dir.y(), dir.x()) + (side > 0 ? M_PI : 0.0);
        const uint16_t id = ctx.newObject(cls::kCar, "parked-car", c, 2.4);
        addCarBody(ctx.mesh, c, yaw,
                   ctx.surface(cls::kCar, id, ctx.vary(kCarPaint[ctx.rng.integer(0, 7)]), 0.02f),
                   ctx.surface(cls::kCar, id, {0.04f, 0.05f, 0.07f}, 0.0f),
                   ctx.surface(cls::kCar, id, {0.03f, 0.03f, 0.03f}, 0.0f));
      }
    }
  }

  // Moving cars loop around random blocks in the right-hand lane.
  const int blocks = roads.grid_nodes - 1;
  for (int k = 0; k < w.config.moving_cars; ++k) {
    Agent agent;
    agent.class_id = cls::kCar;
    agent.instance_id = ctx.newObject(cls::kCar, "moving-car", Eigen::Vector2d::Zero(), 2.4);
    agent.path = blockLoop(roads, ctx.rng.integer(0, blocks - 1), ctx.rng.integer(0, blocks - 1),
                           ctx.rng.chance(0.5), 0.25 * roads.road_width_m);
    agent.speed_mps = ctx.rng.uniform(4.0, 8.0);
    agent.start_m = ctx.rng.uniform(0.0, polylineLength(agent.path, true));
    MeshBuilder mb(agent.mesh, agent.surfaces);
    const uint32_t paint = mb.addSurface(
        {cls::kCar, agent.instance_id, ctx.vary(kCarPaint[ctx.rng.integer(0, 7)]), 0.02f});
    const uint32_t glass =
        mb.addSurface({cls::kCar, agent.instance_id, {0.04f, 0.05f, 0.07f}, 0.0f});
    const uint32_t tyre =
        mb.addSurface({cls::kCar, agent.instance_id, {0.03f, 0.03f, 0.03f}, 0.0f});
    addCarBody(mb, {0, 0}, 0.0, paint, glass, tyre);
    w.agents.push_back(std::move(agent));
  }

  // People walk up and down a sidewalk.
  for (int k = 0; k < w.config.pedestrians; ++k) {
    const auto& e = roads.edges[ctx.rng.integer(0, static_cast<int>(roads.edges.size()) - 1)];
    const Eigen::Vector2d a = roads.nodes[e.first], b = roads.nodes[e.second];
    const Eigen::Vector2d dir = (b - a).normalized();
    const Eigen::Vector2d left(-dir.y(), dir.x());
    const double side = ctx.rng.chance(0.5) ? 1.0 : -1.0;
    const Eigen::Vector2d off = left * (side * (half_road + 0.5 * roads.sidewalk_width_m));
    Agent agent;
    agent.class_id = cls::kPerson;
    agent.instance_id = ctx.newObject(cls::kPerson, "person", Eigen::Vector2d::Zero(), 0.4);
    agent.path = {a + dir * 10.0 + off, b - dir * 10.0 + off};
    agent.speed_mps = ctx.rng.uniform(1.0, 1.6);
    agent.start_m = ctx.rng.uniform(0.0, polylineLength(agent.path, true));
    MeshBuilder mb(agent.mesh, agent.surfaces);
    const Eigen::Vector3f clothes[] = {{0.6f, 0.1f, 0.1f},
                                       {0.1f, 0.2f, 0.6f},
                                       {0.8f, 0.8f, 0.75f},
                                       {0.1f, 0.45f, 0.2f},
                                       {0.7f, 0.55f, 0.1f}};
    addPersonBody(
        mb, mb.addSurface({cls::kPerson, agent.instance_id, clothes[ctx.rng.integer(0, 4)], 0.0f}),
        mb.addSurface({cls::kPerson, agent.instance_id, {0.1f, 0.1f, 0.15f}, 0.0f}),
        mb.addSurface({cls::kPerson, agent.instance_id, {0.75f, 0.55f, 0.42f}, 0.0f}));
    w.agents.push_back(std::move(agent));
  }
}

}  // namespace semsegmap::sim::detail
