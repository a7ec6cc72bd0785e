// Where a map lives: a file (map_file.h) or a map in a PostgreSQL + PostGIS store
// (pg_map_store.h), named by a libpq connection URI with the project's own parameters added:
//   postgresql://[user[:password]@][host][:port]/database?map=NAME[&region=X,Y,RADIUS][&...]
// `map` names the map within the store, `region` the part `localize` loads (a disc around X, Y
// in the map frame, metres); every other parameter is libpq's (host=/a/socket/dir, sslmode...).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace semsegmap {

struct MapRegion {
  double x = 0.0, y = 0.0;  // map frame, metres
  double radius_m = 0.0;
};

struct MapStoreUri {
  std::string conninfo;  // the URI without `map` and `region`: what libpq connects with
  std::string map;       // empty when the URI names the store alone (`maps list`)
  std::optional<MapRegion> region;
  std::string shown;  // for messages: the URI with any password replaced by "***"
};

// A postgresql:// or postgres:// URI (libpq's two schemes), else a file path.
bool isMapStoreUri(std::string_view where);

// Throws std::invalid_argument "<uri>: <what is wrong>" for a malformed `map` or `region`, or a
// missing map name when `need_map`.
MapStoreUri parseMapStoreUri(const std::string& uri, bool need_map = true);

// A map name: 1..63 letters, digits, '.', '_' or '-' (it is shown in lists and file names).
bool isMapName(std::string_view name);

}  // namespace semsegmap
