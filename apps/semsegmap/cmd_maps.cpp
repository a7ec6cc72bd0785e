// semsegmap maps list|show|export|import|drop: the maps of a PostgreSQL + PostGIS map store
// (docs/map-store.md). `map --out/--into` and `localize --map` take the same URIs.
#include <cstdio>
#include <ctime>
#include <iostream>

#include "cli_args.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/store/map_store_uri.h"
#include "semsegmap/store/pg_map_store.h"

namespace semsegmap::app {

namespace {

MapStoreUri storeUri(const CliArgs& a, const std::string& option, bool need_map) {
  try {
    return parseMapStoreUri(a.get(option), need_map);
  } catch (const std::invalid_argument& e) {
    throw UsageError("--" + option + " " + e.what());
  }
}

std::string date(int64_t unix_s) {
  const std::time_t t = static_cast<std::time_t>(unix_s);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M", std::gmtime(&t));
  return text;
}

int runList(const CliArgs& a) {
  const MapStoreUri uri = storeUri(a, "store", false);
  PgMapStore store(uri);
  const std::vector<StoredMap> maps = store.list();
  std::printf("%-24s %-14s %8s %10s %10s  %-16s %s\n", "map", "descriptor", "sessions", "entries",
              "segments", "created (UTC)", "extent x, y (m)");
  for (const StoredMap& m : maps)
    std::printf("%-24s %-14s %8zu %10zu %10zu  %-16s %.0f..%.0f, %.0f..%.0f\n", m.name.c_str(),
                m.descriptor.c_str(), m.sessions, m.entries, m.segments,
                date(m.created_unix_s).c_str(), m.min_x, m.max_x, m.min_y, m.max_y);
  std::printf("%zu maps in %s\n", maps.size(), uri.shown.c_str());
  return 0;
}

int runShow(const CliArgs& a) {
  const MapStoreUri uri = storeUri(a, "map", true);
  PgMapStore store(uri);
  const StoredMap m = store.show(uri.map);
  std::printf(
      "map %s: %s descriptors of %d, %zu entries of %zu segments, extent x %.1f..%.1f "
      "y %.1f..%.1f m\n",
      m.name.c_str(), m.descriptor.c_str(), m.dimension, m.entries, m.segments, m.min_x, m.max_x,
      m.min_y, m.max_y);
  std::printf("%8s  %-16s %7s %8s  %s\n", "session", "merged (UTC)", "frames", "entries", "name");
  for (const StoredSession& s : store.sessions(uri.map))
    std::printf("%8lld  %-16s %7zu %8zu  %s\n", static_cast<long long>(s.id),
                date(s.merged_unix_s).c_str(), s.frames, s.entries, s.name.c_str());
  return 0;
}

int runExport(const CliArgs& a) {
  const MapStoreUri uri = storeUri(a, "map", true);
  PgMapStore store(uri);
  const TargetMap map = store.load(uri.map, uri.region);
  const uint64_t bytes = saveTargetMap(a.get("out"), map);
  std::printf("%zu entries of %zu sessions, %llu bytes\nwrote %s\n", map.size(),
              map.sessions.size(), static_cast<unsigned long long>(bytes), a.get("out").c_str());
  return 0;
}

int runImport(const CliArgs& a) {
  const MapStoreUri uri = storeUri(a, "map", true);
  if (uri.region) throw UsageError("--map: region= selects what to load, not where to write");
  const TargetMap map = loadTargetMap(a.get("from"));  // read whole before connecting
  PgMapStore store(uri);
  store.create(uri.map, map, a.get("from"));
  std::printf("%zu entries imported into map %s of %s\n", map.size(), uri.map.c_str(),
              uri.shown.c_str());
  return 0;
}

int runDrop(const CliArgs& a) {
  const MapStoreUri uri = storeUri(a, "map", true);
  PgMapStore store(uri);
  if (a.has("session")) {
    const auto session = static_cast<int64_t>(a.getCount("session"));
    store.dropSession(uri.map, session);
    std::printf("dropped session %lld of map %s\n", static_cast<long long>(session),
                uri.map.c_str());
    return 0;
  }
  store.drop(uri.map);
  std::printf("dropped map %s\n", uri.map.c_str());
  return 0;
}

const char* const kStoreNotes =
    "A store is a PostgreSQL database with PostGIS: postgresql://[user@]host[:port]/db, or a\n"
    "Unix socket: postgresql:///db?host=/run/postgresql. A map in it adds ?map=NAME.\n";

OptionSpec mapOption(const std::string& help) {
  return {"map", Value::kText, "URI", "", help, kRequired};
}

}  // namespace

const CommandSpec& mapsListCommand() {
  static const CommandSpec c{
      "maps list",
      "lists the maps of a PostgreSQL map store (docs/map-store.md)",
      {{"store", Value::kText, "URI", "", "the store: postgresql://...", kRequired}},
      kStoreNotes,
      runList};
  return c;
}

const CommandSpec& mapsShowCommand() {
  static const CommandSpec c{"maps show",
                             "a store map's size, extent and sessions",
                             {mapOption("postgresql://...?map=NAME")},
                             kStoreNotes,
                             runShow};
  return c;
}

const CommandSpec& mapsExportCommand() {
  static const CommandSpec c{
      "maps export",
      "writes a store map (or its region=X,Y,RADIUS) to a map file",
      {mapOption("postgresql://...?map=NAME[&region=X,Y,RADIUS]"),
       {"out", Value::kText, "FILE", "", "the map file to write", kRequired}},
      kStoreNotes,
      runExport};
  return c;
}

const CommandSpec& mapsImportCommand() {
  static const CommandSpec c{
      "maps import",
      "adds a map file to a store as a new map",
      {{"from", Value::kText, "FILE", "", "the map file (semsegmap map)", kRequired},
       mapOption("postgresql://...?map=NAME, a name the store does not hold yet")},
      kStoreNotes,
      runImport};
  return c;
}

const CommandSpec& mapsDropCommand() {
  static const CommandSpec c{"maps drop",
                             "removes a map from a store, or one session of it (--session)",
                             {mapOption("postgresql://...?map=NAME"),
                              {"session", Value::kCount, "ID", "",
                               "remove only this session (its id in `maps show`) and its entries"}},
                             kStoreNotes,
                             runDrop};
  return c;
}

}  // namespace semsegmap::app
