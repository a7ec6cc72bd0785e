// A store map served in tiles (pipeline/map_tiles.h): the square tiles of side `tile_m` that
// touch the disc of `radius_m` around the robot, each loaded once (PgMapStore::loadBoxes, an
// entry on a shared edge in one tile only), over one connection kept open for the drive.
#pragma once

#include <memory>
#include <set>
#include <string>
#include <utility>

#include "semsegmap/pipeline/map_tiles.h"
#include "semsegmap/store/map_store_uri.h"

namespace semsegmap {

class PgMapStore;

class StoreTiles : public MapTileSource {
 public:
  // Centred at `centre` (nothing loaded yet: around() loads). Throws as PgMapStore does when the
  // store cannot be reached.
  StoreTiles(const MapStoreUri& uri, const Eigen::Vector2d& centre, double radius_m,
             double tile_m = 100.0);
  ~StoreTiles() override;
  TargetMap around(double x, double y) override;
  Eigen::Vector2d centre() const override { return centre_; }
  // Half a tile: the disc's edge then stays at least radius_m - tile_m / 2 ahead of the robot.
  double reloadAfterM() const override { return tile_m_ / 2; }
  size_t tilesLoaded() const { return loaded_.size(); }

 private:
  std::unique_ptr<PgMapStore> store_;
  std::string map_;
  double radius_m_, tile_m_;
  Eigen::Vector2d centre_ = Eigen::Vector2d::Zero();
  std::set<std::pair<long long, long long>> loaded_;
};

}  // namespace semsegmap
