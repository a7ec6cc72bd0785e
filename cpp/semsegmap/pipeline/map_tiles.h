// A map that is not loaded whole: a robot holds the tiles of it around where it is and asks for
// more as it moves ([fleet], docs/map-store.md). The source is the caller's (a PostgreSQL store,
// store/store_tiles.h); LocalizationSession::followTiles adds what it returns to its localizer.
#pragma once

#include <Eigen/Core>

#include "semsegmap/localize/target_map.h"

namespace semsegmap {

class MapTileSource {
 public:
  virtual ~MapTileSource() = default;
  // The map's entries in the tiles around (x, y), map frame, that no earlier call returned; the
  // map's header (descriptor, fingerprint, settings) always.
  virtual TargetMap around(double x, double y) = 0;
  // Where the tiles were last asked for.
  virtual Eigen::Vector2d centre() const = 0;
  // How far the robot moves from centre() before it asks again.
  virtual double reloadAfterM() const = 0;
};

}  // namespace semsegmap
