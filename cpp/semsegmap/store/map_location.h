// A map by where it lives, for every command that takes one: a file path (map_file.h) or a
// postgresql:// URI naming a map in a store (map_store_uri.h, pg_map_store.h).
#pragma once

#include <cstdint>
#include <string>

#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/store/pg_map_store.h"  // MapSnapshot; its functions only WITH_POSTGRES

namespace semsegmap {

// The whole map, or for a URI with region=X,Y,R the entries within R of X, Y. Throws
// std::runtime_error "<where>: <what is wrong>". `snapshot`, for a store map loaded whole: what it
// was, for a session aligned against it (PgMapStore::addSession); a file leaves it untouched.
TargetMap loadMapAt(const std::string& where, MapSnapshot* snapshot = nullptr);

// A new map at `where`: a file, replaced whole (written to a temporary name and renamed), or a
// map in a store, refused when the store holds one of that name already. A map without sessions
// becomes one session named `session_name` in a store. Returns the bytes of a file, 0 for a
// store.
uint64_t saveMapAt(const std::string& where, const TargetMap& map, const MapWriteOptions& options,
                   const std::string& session_name);

// For messages: a file's path as given, or a store's URI without its password.
std::string shownLocation(const std::string& where);

// For pictures and messages: a file's name, or a store map's name.
std::string mapDisplayName(const std::string& where);

// Throws std::runtime_error naming `where` when this build has no PostgreSQL map store and
// `where` is a store URI; nothing for a file.
void requireMapStoreBuilt(const std::string& where);

}  // namespace semsegmap
