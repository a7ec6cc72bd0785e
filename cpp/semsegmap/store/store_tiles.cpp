#include "semsegmap/store/store_tiles.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "semsegmap/store/pg_map_store.h"

namespace semsegmap {

StoreTiles::StoreTiles(const MapStoreUri& uri, const Eigen::Vector2d& centre, double radius_m,
                       double tile_m)
    : store_(std::make_unique<PgMapStore>(uri)),
      map_(uri.map),
      radius_m_(radius_m),
      tile_m_(tile_m),
      centre_(centre) {
  if (!(radius_m > 0) || !(tile_m > 0))
    throw std::invalid_argument(uri.shown + ": tiles need a positive radius and tile size");
}

StoreTiles::~StoreTiles() = default;

TargetMap StoreTiles::around(double x, double y) {
  centre_ = Eigen::Vector2d(x, y);
  std::vector<MapBox> boxes;
  const auto first = [&](double v) {
    return static_cast<long long>(std::floor((v - radius_m_) / tile_m_));
  };
  const auto last = [&](double v) {
    return static_cast<long long>(std::floor((v + radius_m_) / tile_m_));
  };
  for (long long i = first(x); i <= last(x); ++i)
    for (long long j = first(y); j <= last(y); ++j) {
      const MapBox b{static_cast<double>(i) * tile_m_, static_cast<double>(j) * tile_m_,
                     static_cast<double>(i + 1) * tile_m_, static_cast<double>(j + 1) * tile_m_};
      // The tile touches the disc: its nearest point to the centre lies within the radius.
      const double dx = std::max({b.x0 - x, 0.0, x - b.x1}),
                   dy = std::max({b.y0 - y, 0.0, y - b.y1});
      if (dx * dx + dy * dy > radius_m_ * radius_m_ || !loaded_.insert({i, j}).second) continue;
      boxes.push_back(b);
    }
  return store_->loadBoxes(map_, boxes);
}

}  // namespace semsegmap
