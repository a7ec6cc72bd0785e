#include "semsegmap/store/map_location.h"

#include <filesystem>
#include <stdexcept>

#include "semsegmap/store/map_store_uri.h"

namespace semsegmap {

void requireMapStoreBuilt(const std::string& where) {
  if (!isMapStoreUri(where) || SEMSEGMAP_WITH_POSTGRES) return;
  throw std::runtime_error(parseMapStoreUri(where, false).shown +
                           ": this build has no PostgreSQL map store (reconfigure with "
                           "-DSEMSEGMAP_WITH_POSTGRES=ON, libpq-dev)");
}

std::string shownLocation(const std::string& where) {
  return isMapStoreUri(where) ? parseMapStoreUri(where, false).shown : where;
}

std::string mapDisplayName(const std::string& where) {
  if (!isMapStoreUri(where)) return std::filesystem::path(where).filename().string();
  const MapStoreUri uri = parseMapStoreUri(where, false);
  return uri.map.empty() ? uri.shown : uri.map;
}

TargetMap loadMapAt(const std::string& where, MapSnapshot* snapshot) {
  if (!isMapStoreUri(where)) return loadTargetMap(where);
  requireMapStoreBuilt(where);
#if SEMSEGMAP_WITH_POSTGRES
  const MapStoreUri uri = parseMapStoreUri(where);
  PgMapStore store(uri);
  return store.load(uri.map, uri.region, snapshot);
#else
  (void)snapshot;
  throw std::logic_error("requireMapStoreBuilt let a store URI through");
#endif
}

uint64_t saveMapAt(const std::string& where, const TargetMap& map, const MapWriteOptions& options,
                   const std::string& session_name) {
  if (!isMapStoreUri(where)) return saveTargetMap(where, map, options);
  requireMapStoreBuilt(where);
#if SEMSEGMAP_WITH_POSTGRES
  const MapStoreUri uri = parseMapStoreUri(where);
  if (uri.region)
    throw std::invalid_argument(uri.shown + ": region= selects what to load, not where to write");
  PgMapStore store(uri);
  store.create(uri.map, map, session_name);
  return 0;
#else
  (void)options, (void)session_name, (void)map;
  throw std::logic_error("requireMapStoreBuilt let a store URI through");
#endif
}

}  // namespace semsegmap
