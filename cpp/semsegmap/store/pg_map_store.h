// A map store in PostgreSQL + PostGIS ([fleet], docs/map-store.md): the maps of a fleet in one
// database, each map the sessions (drives) merged into it, each segment observation a row with
// its centroid as a PostGIS point (spatial index), so that a robot loads the region it is in.
// Every write is one transaction: a session lands whole or not at all, whatever happens to the
// writer or the connection. Writers of one map are serialized by an advisory lock held to the
// end of their transaction; a session aligned against an older state of the map is joined, under
// the lock, to the sessions that landed meanwhile, so two robots mapping one place at once add
// one segment, not two.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "semsegmap/localize/target_map.h"
#include "semsegmap/store/map_store_uri.h"

typedef struct pg_conn PGconn;

namespace semsegmap {

// The store's schema version (semsegmap_schema); older stores are migrated in place on connect.
int mapStoreSchemaVersion();

// A box of the map frame, [x0, x1) x [y0, y1): a tile (store_tiles.h).
struct MapBox {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

struct StoredMap {
  std::string name, descriptor;
  int dimension = 0;
  int64_t created_unix_s = 0;
  size_t sessions = 0, entries = 0, segments = 0;     // entries: observations; segments: distinct
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;  // the centroids' extent, map frame
};

struct StoredSession {
  int64_t id = 0;  // the store's, stable (positions in TargetMap::sessions are not)
  std::string name;
  int64_t merged_unix_s = 0;
  size_t frames = 0, entries = 0;
};

// What a map was when it was loaded whole, for writing a session aligned against it.
struct MapSnapshot {
  int64_t last_session = 0;  // the newest session id it held
  uint32_t first_fresh = 0;  // segment ids from here on are the new session's own
  size_t scan_contexts = 0;  // how many the loaded map held
};

// A session to add: the last session of a map that joinSession (pipeline/session_merge.h) made
// from a snapshot.
struct NewSession {
  MapSession info;
  std::vector<MapSegment> entries;  // map frame; segment ids as joinSession gave them
  Eigen::MatrixXf descriptors;      // one row per entry
  std::vector<ScanContextDatabase::MappedScan> scans;
};
NewSession lastSessionOf(const TargetMap& merged, const MapSnapshot& snapshot);

struct SessionWrite {
  int64_t session = 0;  // the store's id of the new session
  size_t entries = 0;
  size_t joined_meanwhile = 0;  // entries joined to sessions that landed after the snapshot
  size_t new_segments = 0;
};

class PgMapStore {
 public:
  // Connects, checks PostGIS and creates or migrates the schema. Throws std::runtime_error
  // "<uri>: <what is wrong>" (one line) when any of it fails.
  explicit PgMapStore(const MapStoreUri& uri);
  ~PgMapStore();
  PgMapStore(const PgMapStore&) = delete;
  PgMapStore& operator=(const PgMapStore&) = delete;

  std::vector<StoredMap> list();
  StoredMap show(const std::string& name);
  std::vector<StoredSession> sessions(const std::string& name);
  bool exists(const std::string& name);

  // The whole map, or the entries whose centroids lie within `region` (2D) and the sessions
  // they belong to (whole, with their trajectories). Throws for a missing map or one of another
  // map format version.
  TargetMap load(const std::string& name, const std::optional<MapRegion>& region = {},
                 MapSnapshot* snapshot = nullptr);
  // The entries within `boxes` (each entry once, on a shared edge in one box) and their sessions.
  TargetMap loadBoxes(const std::string& name, const std::vector<MapBox>& boxes);
  // A new map, in one transaction. A map without sessions becomes one session named
  // `session_name`. Throws when `name` exists.
  void create(const std::string& name, const TargetMap& map, const std::string& session_name);
  // Adds `session`, aligned against `snapshot` (a whole load), in one transaction under the
  // map's lock; its new entries within `same_segment_m` of an entry of a session that landed
  // after the snapshot, of its class, join that entry's segment.
  SessionWrite addSession(const std::string& name, const NewSession& session,
                          const MapSnapshot& snapshot, double same_segment_m);
  void drop(const std::string& name);
  void dropSession(const std::string& name, int64_t session);

  const std::string& shown() const { return shown_; }

  struct Selection;  // store/pg_map_store.cpp

 private:
  TargetMap loadSelected(const std::string& name, const Selection& selection,
                         MapSnapshot* snapshot);
  // The map's id; throws, naming the maps there are, for one the store has not.
  int mapId(const std::string& name);
  PGconn* conn_ = nullptr;
  std::string shown_;
};

}  // namespace semsegmap
