// Ground, streets, sidewalks and street furniture.
#include <cmath>

#include "semsegmap/sim/polyline.h"
#include "semsegmap/sim/world_context.h"

namespace semsegmap::sim::detail {

EdgeFrame edgeFrame(const RoadNetwork& roads, const std::pair<int, int>& e) {
  EdgeFrame f;
  f.a = roads.nodes[e.first];
  f.b = roads.nodes[e.second];
  f.length = (f.b - f.a).norm();
  f.dir = (f.b - f.a) / f.length;
  f.left = {-f.dir.y(), f.dir.x()};
  return f;
}

void buildStreets(WorldContext& ctx) {
  World& w = ctx.world;
  const RoadNetwork& roads = w.roads;
  const double half_road = 0.5 * roads.road_width_m;

  const uint16_t terrain = ctx.newObject(cls::kTerrain, "terrain", Eigen::Vector2d::Zero(), 0.0);
  const uint32_t grass = ctx.surface(cls::kTerrain, terrain, {0.16f, 0.36f, 0.09f}, 0.35f);
  ctx.mesh.addGroundPolygon({{w.min_xy.x(), w.min_xy.y()},
                             {w.max_xy.x(), w.min_xy.y()},
                             {w.max_xy.x(), w.max_xy.y()},
                             {w.min_xy.x(), w.max_xy.y()}},
                            0.0, grass);

  for (const auto& e : roads.edges) {
    const EdgeFrame f = edgeFrame(roads, e);
    const Eigen::Vector2d mid = 0.5 * (f.a + f.b);
    const uint16_t road = ctx.newObject(cls::kRoad, "road", mid, 0.5 * f.length);
    const uint32_t asphalt = ctx.surface(cls::kRoad, road, ctx.vary({0.09f, 0.09f, 0.1f}), 0.15f);
    // Extended through the intersections so that crossing streets overlap without gaps.
    const Eigen::Vector2d a = f.a - f.dir * half_road, b = f.b + f.dir * half_road;
    ctx.mesh.addGroundPolygon({a - f.left * half_road, b - f.left * half_road,
                               b + f.left * half_road, a + f.left * half_road},
                              0.02, asphalt);
    // Sidewalks: raised 12 cm (the curb), stopping short of the crossing streets.
    for (int side : {-1, 1}) {
      const uint16_t walk = ctx.newObject(cls::kSidewalk, "sidewalk", mid, 0.5 * f.length);
      const uint32_t concrete =
          ctx.surface(cls::kSidewalk, walk, ctx.vary({0.42f, 0.41f, 0.38f}), 0.12f);
      const double trim = half_road;
      const double len = f.length - 2.0 * trim;
      const Eigen::Vector2d c = mid + f.left * (side * (half_road + 0.5 * roads.sidewalk_width_m));
      ctx.mesh.addBox(c, 0.0, {len, roads.sidewalk_width_m, 0.12}, std::atan2(f.dir.y(), f.dir.x()),
                      concrete);
    }
  }
}

void buildStreetFurniture(WorldContext& ctx) {
  World& w = ctx.world;
  const RoadNetwork& roads = w.roads;
  const double half_road = 0.5 * roads.road_width_m;
  const double curb = half_road + roads.sidewalk_width_m;

  for (const auto& e : roads.edges) {
    const EdgeFrame f = edgeFrame(roads, e);
    // Street lights alternate sides along the street, on the sidewalk next to the curb.
    int side = ctx.rng.chance(0.5) ? 1 : -1;
    for (double s = 16.0; s < f.length - 16.0; s += w.config.street_light_spacing_m) {
      const Eigen::Vector2d base = f.a + f.dir * s + f.left * (side * (half_road + 0.35));
      const uint16_t id = ctx.newObject(cls::kPole, "street-light", base, 0.3);
      const uint32_t metal = ctx.surface(cls::kPole, id, ctx.vary({0.25f, 0.26f, 0.27f}), 0.0f);
      const double h = ctx.rng.uniform(6.0, 8.0);
      ctx.mesh.addCylinder(base, 0.12, 0.09, h, 8, metal);
      const Eigen::Vector2d arm = base - f.left * (side * 0.8);
      ctx.mesh.addBox(arm, 0.12 + h - 0.15, {0.15, 1.6, 0.12}, std::atan2(f.dir.y(), f.dir.x()),
                      metal);
      ctx.occupy({base, 0.4});
      side = -side;
    }
    // Street trees in the front yards, a few metres behind the sidewalk.
    if (ctx.rng.chance(0.5)) {
      for (double s = 20.0; s < f.length - 20.0; s += ctx.rng.uniform(14.0, 24.0)) {
        const int ts = ctx.rng.chance(0.5) ? 1 : -1;
        const Eigen::Vector2d c = f.a + f.dir * s + f.left * (ts * (curb + 1.6));
        if (!ctx.isFree({c, 1.2}, 0.0)) continue;
        const uint16_t id = ctx.newObject(cls::kVegetation, "tree", c, 2.5);
        const double trunk_h = ctx.rng.uniform(2.0, 3.0);
        ctx.mesh.addCylinder(c, 0.0, ctx.rng.uniform(0.15, 0.25), trunk_h + 0.5, 7,
                             ctx.surface(cls::kTrunk, id, ctx.vary({0.23f, 0.15f, 0.08f}), 0.2f));
        const double r = ctx.rng.uniform(1.6, 2.6);
        ctx.mesh.addEllipsoid(
            {c.x(), c.y(), trunk_h + r * 0.8}, {r, r, r * 0.9}, 2,
            ctx.surface(cls::kVegetation, id, ctx.vary({0.12f, 0.3f, 0.07f}, 0.12), 0.4f));
        ctx.occupy({c, 2.0});
      }
    }
  }

  // Traffic signs on some corners of each intersection.
  const Eigen::Vector3f sign_colors[] = {
      {0.7f, 0.05f, 0.05f}, {0.05f, 0.2f, 0.65f}, {0.85f, 0.7f, 0.05f}, {0.85f, 0.85f, 0.85f}};
  for (int j = 0; j < roads.grid_nodes; ++j)
    for (int i = 0; i < roads.grid_nodes; ++i) {
      const Eigen::Vector2d n = roads.nodes[roads.node(i, j)];
      for (int q = 0; q < 4; ++q) {
        if (!ctx.rng.chance(0.45)) continue;
        const double a = M_PI / 4 + q * M_PI / 2;
        const Eigen::Vector2d c =
            n + Eigen::Vector2d(std::cos(a), std::sin(a)) * (half_road + 1.0) * std::sqrt(2.0);
        const uint16_t id = ctx.newObject(cls::kTrafficSign, "traffic-sign", c, 0.5);
        ctx.mesh.addCylinder(c, 0.12, 0.04, 2.3, 6,
                             ctx.surface(cls::kPole, id, {0.5f, 0.5f, 0.52f}, 0.0f));
        const Eigen::Vector3f color = sign_colors[ctx.rng.integer(0, 3)];
        const double facing = a + M_PI / 4 * (ctx.rng.chance(0.5) ? 1 : -1);
        ctx.mesh.addBox(c, 1.9, {0.04, 0.7, 0.7}, facing,
                        ctx.surface(cls::kTrafficSign, id, ctx.vary(color), 0.0f));
        ctx.occupy({c, 0.5});
      }
    }
}

}  // namespace semsegmap::sim::detail
