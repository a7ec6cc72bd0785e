// Lots along the streets: houses from a few repeated footprints in many colours (the case where
// colour helps to tell segments apart), with their yards, hedges, fences and trees.
#include <cmath>

#include "semsegmap/sim/polyline.h"
#include "semsegmap/sim/world_context.h"

namespace semsegmap::sim::detail {

namespace {

// A house footprint as boxes in the house frame (x along the street, y away from it, origin at
// the centre of the front wall).
struct Part {
  double x, y, length, depth;
};
struct Footprint {
  std::vector<Part> parts;
  double width, depth;  // bounding size
};

const std::vector<Footprint>& footprints() {
  static const std::vector<Footprint> f = {
      {{{0, 4.5, 12, 9}}, 12, 9},
      {{{0, 4.0, 10, 8}}, 10, 8},
      {{{0, 4.0, 12, 8}, {3.5, 10.0, 5, 6}}, 12, 13},
      {{{0, 5.0, 14, 10}}, 14, 10},
      {{{0, 5.5, 13, 7}, {0, 1.5, 5, 3.2}}, 13, 9},
      {{{0, 5.5, 9, 11}}, 9, 11},
  };
  return f;
}

const Eigen::Vector3f kWallPalette[] = {
    {0.72f, 0.6f, 0.4f},   {0.82f, 0.74f, 0.3f},  {0.35f, 0.5f, 0.75f},  {0.45f, 0.62f, 0.38f},
    {0.58f, 0.25f, 0.17f}, {0.82f, 0.82f, 0.78f}, {0.45f, 0.45f, 0.48f}, {0.85f, 0.45f, 0.35f},
    {0.55f, 0.45f, 0.72f}, {0.22f, 0.55f, 0.55f}, {0.55f, 0.55f, 0.25f}, {0.42f, 0.28f, 0.18f}};
const Eigen::Vector3f kRoofPalette[] = {{0.35f, 0.1f, 0.07f}, {0.2f, 0.18f, 0.17f},
                                        {0.3f, 0.3f, 0.32f},  {0.18f, 0.25f, 0.2f},
                                        {0.2f, 0.22f, 0.35f}, {0.4f, 0.25f, 0.12f}};
const Eigen::Vector3f kDoorPalette[] = {{0.3f, 0.17f, 0.08f},
                                        {0.6f, 0.08f, 0.06f},
                                        {0.85f, 0.85f, 0.82f},
                                        {0.1f, 0.2f, 0.45f},
                                        {0.1f, 0.3f, 0.15f}};
const Eigen::Vector3f kGlass{0.05f, 0.08f, 0.12f};

struct LotFrame {
  Eigen::Vector2d origin;  // centre of the house's front wall
  Eigen::Vector2d along;   // x of the house frame
  Eigen::Vector2d back;    // y of the house frame: away from the street
  Eigen::Vector2d at(double x, double y) const { return origin + along * x + back * y; }
  double yaw() const { return std::atan2(along.y(), along.x()); }
};

// Windows on the four walls of one box, one per ~3.2 m of wall on every floor, leaving room for
// the doors on the front.
void addWindows(WorldContext& ctx, const LotFrame& lot, const Part& p, int floors, double floor_h,
                bool front_has_doors, uint32_t glass) {
  struct Wall {
    Eigen::Vector2d center, normal, tangent;
    double length;
    bool front;
  };
  const Wall walls[] = {{lot.at(p.x, p.y - 0.5 * p.depth), -lot.back, lot.along, p.length, true},
                        {lot.at(p.x, p.y + 0.5 * p.depth), lot.back, lot.along, p.length, false},
                        {lot.at(p.x - 0.5 * p.length, p.y), -lot.along, lot.back, p.depth, false},
                        {lot.at(p.x + 0.5 * p.length, p.y), lot.along, lot.back, p.depth, false}};
  for (const auto& wall : walls) {
    const int n = static_cast<int>(wall.length / 3.2);
    for (int f = 0; f < floors; ++f)
      for (int k = 0; k < n; ++k) {
        const double s = (k + 0.5) * wall.length / n - 0.5 * wall.length;
        if (wall.front && front_has_doors && f == 0 && s > -3.5) continue;
        ctx.mesh.addPanel(wall.center + wall.tangent * s, wall.normal, f * floor_h + 0.9, 1.2, 1.3,
                          0.06, glass);
      }
  }
}

void addHouse(WorldContext& ctx, const LotFrame& lot, const Footprint& fp, uint16_t id) {
  const int floors = ctx.rng.chance(0.45) ? 2 : 1;
  const double floor_h = 2.9;
  const double wall_h = floors * floor_h + 0.3;
  const Eigen::Vector3f wall_color = ctx.vary(kWallPalette[ctx.rng.integer(0, 11)]);
  const uint32_t wall = ctx.surface(cls::kBuilding, id, wall_color, 0.08f);
  const uint32_t roof =
      ctx.surface(cls::kRoof, id, ctx.vary(kRoofPalette[ctx.rng.integer(0, 5)]), 0.15f);
  const uint32_t glass = ctx.surface(cls::kBuilding, id, kGlass, 0.0f);
  const bool pitched = ctx.rng.chance(0.65);
  for (size_t k = 0; k < fp.parts.size(); ++k) {
    const Part& p = fp.parts[k];
    const Eigen::Vector2d c = lot.at(p.x, p.y);
    const double h = k == 0 ? wall_h : floor_h + 0.3;
    ctx.mesh.addBox(c, 0.0, {p.length, p.depth, h}, lot.yaw(), wall);
    if (pitched) {
      // Ridge along the longer side, as on most houses.
      const bool along_x = p.length >= p.depth;
      ctx.mesh.addGableRoof(
          c, h, along_x ? p.length + 0.6 : p.depth + 0.6, along_x ? p.depth + 0.6 : p.length + 0.6,
          0.35 * std::min(p.length, p.depth), along_x ? lot.yaw() : lot.yaw() + M_PI / 2, roof);
    } else {
      ctx.mesh.addBox(c, h, {p.length + 0.2, p.depth + 0.2, 0.35}, lot.yaw(), roof);
    }
    addWindows(ctx, lot, p, k == 0 ? floors : 1, floor_h, k == 0, glass);
  }
  // Front door and garage door on the main part's front wall.
  const Part& main = fp.parts[0];
  const Eigen::Vector2d front = lot.at(main.x, main.y - 0.5 * main.depth);
  ctx.mesh.addPanel(
      front - lot.along * 1.5, -lot.back, 0.0, 1.0, 2.1, 0.08,
      ctx.surface(cls::kBuilding, id, ctx.vary(kDoorPalette[ctx.rng.integer(0, 4)]), 0.0f));
  const Eigen::Vector3f garage_color = ctx.rng.chance(0.5)
                                           ? Eigen::Vector3f(0.85f, 0.85f, 0.83f)
                                           : ctx.vary(kDoorPalette[ctx.rng.integer(0, 4)]);
  ctx.mesh.addPanel(front + lot.along * (0.5 * main.length - 2.0), -lot.back, 0.0, 2.7, 2.2, 0.08,
                    ctx.surface(cls::kBuilding, id, garage_color, 0.05f));
}

void addTree(WorldContext& ctx, const Eigen::Vector2d& c) {
  const uint16_t id = ctx.newObject(cls::kVegetation, "tree", c, 3.0);
  const double trunk_h = ctx.rng.uniform(1.5, 3.5);
  ctx.mesh.addCylinder(c, 0.0, ctx.rng.uniform(0.12, 0.3), trunk_h + 0.5, 7,
                       ctx.surface(cls::kTrunk, id, ctx.vary({0.23f, 0.15f, 0.08f}), 0.2f));
  // Foliage from yellow-green to blue-green, with a few autumn reds.
  const Eigen::Vector3f foliage[] = {{0.15f, 0.32f, 0.06f},
                                     {0.08f, 0.25f, 0.1f},
                                     {0.22f, 0.35f, 0.05f},
                                     {0.05f, 0.2f, 0.12f},
                                     {0.45f, 0.18f, 0.05f}};
  const uint32_t leaves =
      ctx.surface(cls::kVegetation, id, ctx.vary(foliage[ctx.rng.integer(0, 4)], 0.1), 0.45f);
  const double r = ctx.rng.uniform(1.5, 3.2);
  switch (ctx.rng.integer(0, 2)) {
    case 0:
      ctx.mesh.addEllipsoid({c.x(), c.y(), trunk_h + 0.8 * r}, {r, r, 0.9 * r}, 2, leaves);
      break;
    case 1:  // conifer
      ctx.mesh.addCone(c, trunk_h * 0.5, 0.7 * r, 3.0 * r, 10, leaves);
      break;
    default:  // tall and narrow
      ctx.mesh.addEllipsoid({c.x(), c.y(), trunk_h + 1.4 * r}, {0.7 * r, 0.7 * r, 1.6 * r}, 2,
                            leaves);
  }
  ctx.occupy({c, std::min(r, 2.5)});
}

void addLotExtras(WorldContext& ctx, const LotFrame& lot, double frontage, double setback,
                  const Footprint& fp) {
  // Driveway from the sidewalk to the garage door.
  const double dx = 0.5 * fp.parts[0].length - 2.0;
  const Eigen::Vector2d d0 = lot.at(dx, -setback), d1 = lot.at(dx, 0.0);
  const uint16_t drive = ctx.newObject(cls::kRoad, "driveway", 0.5 * (d0 + d1), 0.5 * setback);
  const uint32_t concrete = ctx.surface(cls::kRoad, drive, ctx.vary({0.4f, 0.39f, 0.36f}), 0.1f);
  ctx.mesh.addGroundPolygon(
      {d0 - lot.along * 1.6, d0 + lot.along * 1.6, d1 + lot.along * 1.6, d1 - lot.along * 1.6},
      0.03, concrete);

  // Hedge along the front of the lot, left of the driveway.
  if (ctx.rng.chance(0.4)) {
    const double len = 0.5 * frontage + dx - 3.0;
    if (len > 2.0) {
      const Eigen::Vector2d c = lot.at(-0.5 * frontage + 0.5 * len + 0.5, -setback + 0.8);
      const uint16_t id = ctx.newObject(cls::kVegetation, "hedge", c, 0.5 * len);
      ctx.mesh.addBox(
          c, 0.0, {len, ctx.rng.uniform(0.6, 1.0), ctx.rng.uniform(0.9, 1.7)}, lot.yaw(),
          ctx.surface(cls::kVegetation, id, ctx.vary({0.07f, 0.22f, 0.05f}, 0.1), 0.4f));
    }
  }
  // Fences on the lot's sides, from the front yard to the back.
  if (ctx.rng.chance(0.5)) {
    const Eigen::Vector3f colors[] = {
        {0.85f, 0.85f, 0.82f}, {0.35f, 0.22f, 0.12f}, {0.4f, 0.4f, 0.4f}};
    const Eigen::Vector3f color = ctx.vary(colors[ctx.rng.integer(0, 2)]);
    const double h = ctx.rng.uniform(1.1, 1.8);
    const double depth = fp.depth + 6.0;
    for (double side : {-0.5, 0.5}) {
      const Eigen::Vector2d c = lot.at(side * frontage, 0.5 * depth - 2.0);
      const uint16_t id = ctx.newObject(cls::kFence, "fence", c, 0.5 * depth);
      ctx.mesh.addBox(c, 0.0, {0.06, depth, h}, lot.yaw(),
                      ctx.surface(cls::kFence, id, color, 0.05f));
    }
  }
  // Mailbox and bins by the driveway.
  {
    const Eigen::Vector2d c = lot.at(dx - 2.4, -setback + 0.4);
    const uint16_t id = ctx.newObject(cls::kOther, "mailbox", c, 0.3);
    ctx.mesh.addCylinder(c, 0.0, 0.05, 1.0, 6,
                         ctx.surface(cls::kOther, id, {0.3f, 0.3f, 0.3f}, 0.0f));
    ctx.mesh.addBox(
        c, 1.0, {0.45, 0.25, 0.3}, lot.yaw(),
        ctx.surface(cls::kOther, id, ctx.vary(kDoorPalette[ctx.rng.integer(0, 4)]), 0.0f));
  }
  const int bins = ctx.rng.integer(0, 2);
  for (int b = 0; b < bins; ++b) {
    const Eigen::Vector2d c = lot.at(dx + 2.3 + 0.75 * b, -1.5);
    const uint16_t id = ctx.newObject(cls::kOther, "bin", c, 0.4);
    const Eigen::Vector3f colors[] = {
        {0.1f, 0.35f, 0.12f}, {0.1f, 0.2f, 0.5f}, {0.08f, 0.08f, 0.08f}, {0.4f, 0.25f, 0.1f}};
    ctx.mesh.addBox(c, 0.0, {0.6, 0.7, 1.05}, lot.yaw(),
                    ctx.surface(cls::kOther, id, colors[ctx.rng.integer(0, 3)], 0.02f));
  }
  // Trees and bushes in the yards.
  const int trees = ctx.rng.integer(0, 2);
  for (int t = 0; t < trees; ++t) {
    const Eigen::Vector2d c = lot.at(ctx.rng.uniform(-0.45, 0.45) * frontage,
                                     ctx.rng.chance(0.4) ? -ctx.rng.uniform(2.5, setback - 2.5)
                                                         : fp.depth + ctx.rng.uniform(3.0, 8.0));
    if (ctx.isFree({c, 1.5}, 1.0)) addTree(ctx, c);
  }
  const int bushes = ctx.rng.integer(0, 3);
  for (int k = 0; k < bushes; ++k) {
    const Eigen::Vector2d c =
        lot.at(ctx.rng.uniform(-0.45, 0.45) * frontage, -ctx.rng.uniform(0.8, 2.0));
    if (!ctx.isFree({c, 0.9}, 0.5)) continue;
    const uint16_t id = ctx.newObject(cls::kVegetation, "bush", c, 0.9);
    const double r = ctx.rng.uniform(0.5, 0.9);
    ctx.mesh.addEllipsoid(
        {c.x(), c.y(), 0.7 * r}, {r, r, 0.8 * r}, 1,
        ctx.surface(cls::kVegetation, id, ctx.vary({0.1f, 0.28f, 0.06f}, 0.12), 0.4f));
    ctx.occupy({c, r});
  }
}

}  // namespace

void buildLots(WorldContext& ctx) {
  const RoadNetwork& roads = ctx.world.roads;
  const double curb = 0.5 * roads.road_width_m + roads.sidewalk_width_m;
  for (const auto& e : roads.edges) {
    const auto [a, b, dir, left, length] = edgeFrame(roads, e);
    for (int side : {-1, 1}) {
      double s = curb + 10.0 + ctx.rng.uniform(0.0, 4.0);
      while (true) {
        const double frontage = ctx.rng.uniform(19.0, 26.0);
        if (s + frontage > length - curb - 8.0) break;
        const Footprint& fp =
            footprints()[ctx.rng.integer(0, static_cast<int>(footprints().size()) - 1)];
        const double setback = ctx.rng.uniform(6.0, 10.0);
        LotFrame lot;
        lot.back = left * side;
        // The house frame is right-handed seen from above whichever side of the street it is on.
        lot.along = side > 0 ? dir : Eigen::Vector2d(-dir);
        lot.origin = a + dir * (s + 0.5 * frontage) + lot.back * (curb + setback);
        const Eigen::Vector2d center = lot.at(0.0, 0.5 * fp.depth);
        const double radius = 0.5 * std::hypot(fp.width, fp.depth);
        s += frontage;
        if (!ctx.isFree({center, radius}, setback + 0.5 * fp.depth - radius - 0.5)) continue;
        const uint16_t id = ctx.newObject(cls::kBuilding, "house", center, radius);
        ctx.occupy({center, radius});
        addHouse(ctx, lot, fp, id);
        addLotExtras(ctx, lot, frontage, setback, fp);
      }
    }
  }
}

}  // namespace semsegmap::sim::detail
