// The PostgreSQL + PostGIS map store ([fleet], docs/map-store.md), against a real server the
// test starts (pg_cluster.h): URIs and their errors, a map read back as from its file, regions,
// sessions written meanwhile, four writers at once, a writer killed mid-session, a dropped
// connection, dropping, and the command line on a store.
#include <gtest/gtest.h>
#include <libpq-fe.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <random>
#include <set>
#include <thread>

#include "command_result.h"
#include "pg_cluster.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/store/map_location.h"
#include "semsegmap/store/map_store_uri.h"
#include "semsegmap/store/pg_map_store.h"
#include "semsegmap/store/store_tiles.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

using test_support::PgCluster;
using test_support::TempDir;

constexpr int kDim = 8;

// One server for the whole executable: starting one takes about a second.
PgCluster& cluster() {
  static PgCluster c;
  return c;
}

#define SEMSEGMAP_NEED_SERVER() \
  ASSERT_EQ(cluster().problem(), "") << "the map store's tests need a PostgreSQL server"

// `n` segments on a grid from `origin`, `spacing` apart, with descriptors from `seed`, classes
// cycling through 1..5, every third with picture points; one session with a trajectory.
TargetMap gridMap(int n, Eigen::Vector2f origin, float spacing, unsigned seed,
                  uint32_t first_id = 0) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise;
  TargetMap map;
  map.descriptor = "eigen";
  map.fingerprint = "test-fingerprint";
  map.parameters = {{"segmentation.radius_m", "0.2"}, {"local_map.voxel_size_m", "0.1"}};
  map.descriptors.resize(n, kDim);
  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  for (int i = 0; i < n; ++i) {
    MapSegment s;
    s.centroid = Eigen::Vector3f(origin.x() + spacing * static_cast<float>(i % side),
                                 origin.y() + spacing * static_cast<float>(i / side),
                                 0.5f + 0.01f * static_cast<float>(i % 7));
    s.n_points = static_cast<uint32_t>(100 + i);
    s.majority_class = static_cast<ClassId>(1 + i % 5);
    s.segment = first_id + static_cast<uint32_t>(i);
    if (i % 3 == 0)
      for (int k = 0; k < 4; ++k) s.points.push_back(s.centroid + Eigen::Vector3f(0.1f * k, 0, 0));
    map.segments.push_back(s);
    for (int k = 0; k < kDim; ++k) map.descriptors(i, k) = noise(rng);
  }
  return map;
}

int64_t count(const std::string& sql) {
  PGconn* c = PQconnectdb(parseMapStoreUri(cluster().uri(), false).conninfo.c_str());
  PGresult* r = PQexec(c, sql.c_str());
  const int64_t v = PQresultStatus(r) == PGRES_TUPLES_OK ? std::stoll(PQgetvalue(r, 0, 0)) : -1;
  PQclear(r);
  PQfinish(c);
  return v;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(MapStoreUri, TakesTheMapAndRegionAndPassesTheRestToLibpq) {
  const MapStoreUri u = parseMapStoreUri(
      "postgresql://robot:secret@db.example:5433/fleet?sslmode=require&map=city.v2&region=10,-5.5,"
      "200");
  EXPECT_EQ(u.map, "city.v2");
  ASSERT_TRUE(u.region.has_value());
  EXPECT_DOUBLE_EQ(u.region->x, 10);
  EXPECT_DOUBLE_EQ(u.region->y, -5.5);
  EXPECT_DOUBLE_EQ(u.region->radius_m, 200);
  EXPECT_EQ(u.conninfo, "postgresql://robot:secret@db.example:5433/fleet?sslmode=require");
  EXPECT_EQ(u.shown.find("secret"), std::string::npos) << u.shown;
  EXPECT_NE(u.shown.find("robot:***@db.example"), std::string::npos) << u.shown;
  EXPECT_TRUE(isMapStoreUri("postgres://h/db"));
  EXPECT_FALSE(isMapStoreUri("maps/postgresql.map"));
  EXPECT_EQ(parseMapStoreUri("postgres:///db", false).map, "");
}

TEST(MapStoreUri, RefusesWhatItCannotUseInOneLine) {
  for (const auto& [uri, says] : std::vector<std::pair<std::string, std::string>>{
           {"postgresql://h/db", "which map? add ?map=NAME"},
           {"postgresql://h/db?map=a/b", "map name 'a/b' must be"},
           {"postgresql://h/db?map=a&region=1,2", "takes three numbers"},
           {"postgresql://h/db?map=a&region=1,x,3", "'x' is not a number"},
           {"postgresql://h/db?map=a&region=1,2,-3", "radius must be > 0"}}) {
    const std::string e = errorOf([&] { parseMapStoreUri(uri); });
    EXPECT_NE(e.find(says), std::string::npos) << uri << ": " << e;
    EXPECT_EQ(e.rfind(uri.substr(0, 17), 0), 0u) << e;  // names the URI first
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

// Everything a map file holds reads back from the store as from the file: the same code writes
// both (artefacts/map_codec.h).
TEST(MapStore, AMapReadsBackAsFromItsFile) {
  SEMSEGMAP_NEED_SERVER();
  TempDir tmp;
  TargetMap map = gridMap(50, {0, 0}, 2.0f, 1);
  map.sessions = {{"first drive", 1700000000, {}},
                  {"second drive", 1700000100, {Pose::Identity(), Pose::Identity()}}};
  map.sessions[1].trajectory[1].translation() = Eigen::Vector3d(1.5, -2.0, 0.1);
  for (size_t i = 25; i < map.segments.size(); ++i) {
    map.segments[i].session = 1;
    map.segments[i].keyframe = static_cast<uint32_t>(i % 2);
    map.segments[i].segment = static_cast<uint32_t>(i - 25);  // a second look at each
  }
  Eigen::MatrixXf bins = Eigen::MatrixXf::Constant(20, 60, 0.0f);
  bins(3, 7) = 2.5f;
  Pose T = Pose::Identity();
  T.translation() = Eigen::Vector3d(4, 5, 0);
  map.scan_contexts.add(scanContextOfBins(bins), T);
  const std::filesystem::path file = tmp.path() / "m.map";
  saveTargetMap(file, map);
  const TargetMap expected = loadTargetMap(file);
  saveMapAt(cluster().uri("readback"), map, {}, "unused");
  const TargetMap got = loadMapAt(cluster().uri("readback"));
  EXPECT_EQ(got.descriptor, expected.descriptor);
  EXPECT_EQ(got.fingerprint, expected.fingerprint);
  EXPECT_EQ(got.parameters, expected.parameters);
  ASSERT_EQ(got.size(), expected.size());
  EXPECT_TRUE(got.descriptors == expected.descriptors);
  for (size_t i = 0; i < got.size(); ++i) {
    const MapSegment &g = got.segments[i], &e = expected.segments[i];
    EXPECT_TRUE(g.centroid == e.centroid) << i;
    EXPECT_EQ(g.n_points, e.n_points);
    EXPECT_EQ(g.majority_class, e.majority_class);
    EXPECT_EQ(g.segment, e.segment);
    EXPECT_EQ(g.session, e.session);
    EXPECT_EQ(g.keyframe, e.keyframe);
    ASSERT_EQ(g.points.size(), e.points.size());
    for (size_t k = 0; k < g.points.size(); ++k) EXPECT_TRUE(g.points[k] == e.points[k]);
  }
  ASSERT_EQ(got.sessions.size(), 2u);
  EXPECT_EQ(got.sessions[1].name, "second drive");
  EXPECT_EQ(got.sessions[1].merged_unix_s, 1700000100);
  ASSERT_EQ(got.sessions[1].trajectory.size(), 2u);
  EXPECT_TRUE(got.sessions[1].trajectory[1].translation().isApprox(Eigen::Vector3d(1.5, -2, 0.1)));
  ASSERT_EQ(got.scan_contexts.size(), 1u);
  EXPECT_TRUE(got.scan_contexts.scans()[0].context.bins ==
              expected.scan_contexts.scans()[0].context.bins);
  EXPECT_NE(got.source.find("map=readback"), std::string::npos) << got.source;
}

TEST(MapStore, ARegionLoadsTheEntriesWithinItsRadiusAndTheirSessions) {
  SEMSEGMAP_NEED_SERVER();
  TargetMap map = gridMap(400, {-100, -100}, 10.0f, 2);  // 200 m x 200 m
  map.sessions = {{"near", 1, {}}, {"far", 2, {}}};
  for (size_t i = 0; i < 200; ++i) map.segments[i].session = 1;  // the south half
  saveMapAt(cluster().uri("region"), map, {}, "unused");
  const TargetMap part = loadMapAt(cluster().uri("region") + "&region=0,50,25");
  size_t within = 0;
  for (const MapSegment& s : map.segments)
    within += (s.centroid.head<2>() - Eigen::Vector2f(0, 50)).norm() <= 25.0f;
  EXPECT_GT(within, 10u);
  EXPECT_EQ(part.size(), within);
  for (const MapSegment& s : part.segments) {
    EXPECT_LE((s.centroid.head<2>() - Eigen::Vector2f(0, 50)).norm(), 25.0f);
    EXPECT_EQ(s.session, 0u);
  }
  ASSERT_EQ(part.sessions.size(), 1u);  // the far half's session has no entry there
  EXPECT_EQ(part.sessions[0].name, "near");
  const TargetMap whole = loadMapAt(cluster().uri("region"));
  EXPECT_EQ(whole.size(), 400u);
  EXPECT_EQ(whole.sessions.size(), 2u);
}

// Tiles: each entry once, an entry on a shared edge in one tile only, and only new tiles as the
// robot moves.
TEST(MapStore, TilesHandOutEachEntryOnceAsTheRobotMoves) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("tiles"), gridMap(400, {-100, -100}, 10.0f, 9), {}, "drive");
  StoreTiles tiles(parseMapStoreUri(cluster().uri("tiles")), {-60, -60}, 30.0, 20.0);
  const TargetMap first = tiles.around(-60, -60);
  EXPECT_EQ(tiles.centre(), Eigen::Vector2d(-60, -60));
  EXPECT_GT(first.size(), 0u);
  EXPECT_EQ(first.descriptor, "eigen");  // the header comes with every load
  for (const MapSegment& s : first.segments) {
    EXPECT_GE(s.centroid.x(), -100.0f);
    EXPECT_LT(s.centroid.x(), -20.0f);  // the tiles touching the disc: [-100, -20)
  }
  EXPECT_EQ(tiles.around(-60, -60).size(), 0u);  // nothing twice
  std::set<uint32_t> seen;
  for (const MapSegment& s : first.segments) EXPECT_TRUE(seen.insert(s.segment).second);
  size_t total = first.size();
  for (double x = -40; x <= 100; x += 20)
    for (const MapSegment& s : tiles.around(x, -60).segments) {
      EXPECT_TRUE(seen.insert(s.segment).second) << "segment " << s.segment << " twice";
      ++total;
    }
  // Row y in [-100, -20) of the grid, all x: 8 rows of 20.
  EXPECT_EQ(total, 160u);
}

TEST(MapStore, ErrorsAreOneLineNamingTheStore) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("exists"), gridMap(3, {0, 0}, 1, 3), {}, "d");
  const std::vector<std::pair<std::function<void()>, std::string>> cases = {
      {[] { loadMapAt(cluster().uri("nosuchmap")); }, "no map named 'nosuchmap' in the store"},
      {[] {
         saveMapAt(cluster().uri("exists"), gridMap(3, {0, 0}, 1, 3), {}, "d");
       },
       "map 'exists' exists already"},
      {[] { loadMapAt("postgresql://nohost.invalid/db?map=a&connect_timeout=5"); },
       "postgresql://nohost.invalid/db?map=a&connect_timeout=5: cannot connect"},
      {[] { loadMapAt("postgresql:///db?host=/nonexistent-socket-dir&map=a"); }, "cannot connect"},
      {[] { loadMapAt(cluster().uri("a", "nosuchdb")); }, "database \"nosuchdb\" does not exist"},
  };
  for (const auto& [f, says] : cases) {
    const std::string e = errorOf(f);
    EXPECT_NE(e.find(says), std::string::npos) << e;
    EXPECT_EQ(e.rfind("postgres", 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  EXPECT_NE(errorOf([] { loadMapAt(cluster().uri("nosuchmap")); }).find("it holds "),
            std::string::npos);
}

// A database whose user may not create PostGIS, and one whose schema is newer than this build.
TEST(MapStore, RefusesADatabaseWithoutPostgisOrOfANewerSchema) {
  SEMSEGMAP_NEED_SERVER();
  ASSERT_TRUE(cluster().psql("CREATE ROLE plain LOGIN"));
  ASSERT_TRUE(cluster().psql("CREATE DATABASE nopostgis OWNER plain"));
  const std::string e =
      errorOf([] { PgMapStore(parseMapStoreUri(cluster().uri("", "nopostgis", "plain"), false)); });
  EXPECT_NE(e.find("PostGIS"), std::string::npos) << e;
  EXPECT_NE(e.find("permission denied"), std::string::npos) << e;
  ASSERT_TRUE(cluster().psql("CREATE DATABASE newer"));
  { PgMapStore store(parseMapStoreUri(cluster().uri("", "newer"), false)); }
  ASSERT_TRUE(cluster().psql("UPDATE semsegmap_schema SET version = 99", "newer"));
  const std::string n =
      errorOf([] { PgMapStore(parseMapStoreUri(cluster().uri("", "newer"), false)); });
  EXPECT_NE(n.find("schema version 99, newer than this build's " +
                   std::to_string(mapStoreSchemaVersion())),
            std::string::npos)
      << n;
}

TEST(MapStore, RefusesAMapOfAnotherFormatVersion) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("oldformat"), gridMap(3, {0, 0}, 1, 4), {}, "d");
  ASSERT_TRUE(
      cluster().psql("UPDATE semsegmap_maps SET format_version = 1 WHERE name = 'oldformat'"));
  const std::string e = errorOf([] { loadMapAt(cluster().uri("oldformat")); });
  EXPECT_NE(e.find("map format version 1, this build reads version"), std::string::npos) << e;
}

// The new session of a map loaded at `snapshot`: `n` entries on the grid of `origin`, each an
// observation of nothing the snapshot held (fresh ids from snapshot.first_fresh).
NewSession freshSession(const std::string& name, int n, Eigen::Vector2f origin, unsigned seed,
                        const MapSnapshot& snapshot) {
  const TargetMap m = gridMap(n, origin, 2.0f, seed, snapshot.first_fresh);
  NewSession s;
  s.info = {name, 1700000000, {}};
  s.entries = m.segments;
  s.descriptors = m.descriptors;
  return s;
}

// Two robots aligned against one state of the map, written one after the other: the second's
// entries of the place the first added join the first's segments instead of duplicating them.
TEST(MapStore, ASessionJoinsTheSegmentsOfASessionWrittenMeanwhile) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("meanwhile"), gridMap(20, {0, 0}, 2.0f, 5), {}, "base");
  PgMapStore store(parseMapStoreUri(cluster().uri("meanwhile")));
  MapSnapshot snapshot;
  store.load("meanwhile", {}, &snapshot);
  EXPECT_EQ(snapshot.first_fresh, 20u);
  const NewSession a = freshSession("a", 9, {100, 0}, 6, snapshot);
  NewSession b = freshSession("b", 9, {100, 0}, 7, snapshot);
  b.entries.push_back(gridMap(20, {0, 0}, 2.0f, 5).segments[3]);  // a segment the base held
  b.descriptors.conservativeResize(10, kDim);
  b.descriptors.row(9).setZero();
  const SessionWrite wa = store.addSession("meanwhile", a, snapshot, 1.0);
  EXPECT_EQ(wa.new_segments, 9u);
  const SessionWrite wb = store.addSession("meanwhile", b, snapshot, 1.0);
  EXPECT_EQ(wb.joined_meanwhile, 9u);
  EXPECT_EQ(wb.new_segments, 0u);
  const TargetMap m = store.load("meanwhile");
  EXPECT_EQ(m.size(), 20u + 9u + 10u);
  std::set<uint32_t> ids;
  for (const MapSegment& s : m.segments) ids.insert(s.segment);
  EXPECT_EQ(ids.size(), 29u);
  EXPECT_EQ(m.sessions.size(), 3u);
}

// Four writers at once, each a session of the same new place and one of its own, aligned
// against the same state: every entry lands, the shared place is one set of segments.
TEST(MapStore, FourWritersAtOnceLoseAndDuplicateNothing) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("fleet"), gridMap(30, {0, 0}, 2.0f, 8), {}, "base");
  MapSnapshot snapshot;
  PgMapStore(parseMapStoreUri(cluster().uri("fleet"))).load("fleet", {}, &snapshot);
  std::vector<std::thread> writers;
  std::vector<std::string> errors(4);
  for (int w = 0; w < 4; ++w)
    writers.emplace_back([&, w] {
      try {
        PgMapStore store(parseMapStoreUri(cluster().uri("fleet")));
        NewSession shared = freshSession("robot " + std::to_string(w), 16, {200, 0},
                                         10 + static_cast<unsigned>(w), snapshot);
        const NewSession own = freshSession("", 16, {400.0f + 100.0f * static_cast<float>(w), 0},
                                            20 + static_cast<unsigned>(w), snapshot);
        for (size_t i = 0; i < own.entries.size(); ++i) {
          shared.entries.push_back(own.entries[i]);
          shared.entries.back().segment += 100;  // the session's own ids stay distinct
        }
        shared.descriptors.conservativeResize(32, kDim);
        shared.descriptors.bottomRows(16) = own.descriptors;
        store.addSession("fleet", shared, snapshot, 1.0);
      } catch (const std::exception& e) {
        errors[static_cast<size_t>(w)] = e.what();
      }
    });
  for (std::thread& t : writers) t.join();
  for (const std::string& e : errors) EXPECT_EQ(e, "");
  const TargetMap m = loadMapAt(cluster().uri("fleet"));
  EXPECT_EQ(m.size(), 30u + 4u * 32u);
  EXPECT_EQ(m.sessions.size(), 5u);
  std::set<uint32_t> ids;
  for (const MapSegment& s : m.segments) ids.insert(s.segment);
  EXPECT_EQ(ids.size(), 30u + 16u + 4u * 16u);  // the shared place once, each own place once
}

// The number of store backends running a COPY into the segments: a writer mid-session.
int64_t copying() {
  return count(
      "SELECT count(*) FROM pg_stat_activity WHERE query LIKE 'COPY semsegmap_segments%' "
      "AND state = 'active'");
}

bool waitFor(const std::function<bool()>& done, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return false;
}

struct MapCounts {
  int64_t entries, sessions;
  bool operator==(const MapCounts& o) const {
    return entries == o.entries && sessions == o.sessions;
  }
};
MapCounts countsOf(const std::string& name) {
  const std::string id = "(SELECT id FROM semsegmap_maps WHERE name = '" + name + "')";
  return {count("SELECT count(*) FROM semsegmap_segments WHERE map_id = " + id),
          count("SELECT count(*) FROM semsegmap_sessions WHERE map_id = " + id)};
}

constexpr int kBigSession = 300000;  // long enough a COPY to be caught in the middle

TEST(MapStore, AWriterKilledMidSessionChangesNothing) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("killed"), gridMap(10, {0, 0}, 2.0f, 30), {}, "base");
  const MapCounts before = countsOf("killed");
  const pid_t child = ::fork();
  if (child == 0) {
    try {
      MapSnapshot snapshot;
      PgMapStore store(parseMapStoreUri(cluster().uri("killed")));
      store.load("killed", {}, &snapshot);
      store.addSession("killed", freshSession("doomed", kBigSession, {0, 500}, 31, snapshot),
                       snapshot, 1.0);
    } catch (...) {
    }
    ::_exit(0);
  }
  const bool caught = waitFor([] { return copying() > 0; }, 120);
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(caught) << "the writer was never seen mid-session";
  ASSERT_TRUE(WIFSIGNALED(status)) << "the writer finished before it was killed";
  ASSERT_TRUE(waitFor([] { return copying() == 0; }, 60));
  EXPECT_EQ(countsOf("killed"), before);
  EXPECT_EQ(loadMapAt(cluster().uri("killed")).size(), 10u);
}

TEST(MapStore, ADroppedConnectionIsOneErrorLineAndNoPartialSession) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("dropped"), gridMap(10, {0, 0}, 2.0f, 40), {}, "base");
  const MapCounts before = countsOf("dropped");
  std::string error;
  std::thread writer([&] {
    try {
      MapSnapshot snapshot;
      PgMapStore store(parseMapStoreUri(cluster().uri("dropped")));
      store.load("dropped", {}, &snapshot);
      store.addSession("dropped", freshSession("cut", kBigSession, {0, 500}, 41, snapshot),
                       snapshot, 1.0);
    } catch (const std::exception& e) {
      error = e.what();
    }
  });
  const bool caught = waitFor([] { return copying() > 0; }, 120);
  if (caught)
    count(
        "SELECT count(pg_terminate_backend(pid)) FROM pg_stat_activity WHERE query LIKE "
        "'COPY semsegmap_segments%'");
  writer.join();
  ASSERT_TRUE(caught) << "the writer was never seen mid-session";
  EXPECT_EQ(error.rfind(cluster().uri("dropped"), 0), 0u) << error;
  EXPECT_NE(error.find("connection to the server was lost"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos) << error;
  EXPECT_EQ(countsOf("dropped"), before);
}

TEST(MapStore, DropsOneSessionOrTheWholeMap) {
  SEMSEGMAP_NEED_SERVER();
  saveMapAt(cluster().uri("dropping"), gridMap(10, {0, 0}, 2.0f, 50), {}, "base");
  PgMapStore store(parseMapStoreUri(cluster().uri("dropping")));
  MapSnapshot snapshot;
  store.load("dropping", {}, &snapshot);
  const SessionWrite w =
      store.addSession("dropping", freshSession("bad", 5, {50, 0}, 51, snapshot), snapshot, 1.0);
  EXPECT_EQ(store.load("dropping").size(), 15u);
  const std::string e = errorOf([&] { store.dropSession("dropping", w.session + 100); });
  EXPECT_NE(e.find("has no session " + std::to_string(w.session + 100)), std::string::npos) << e;
  store.dropSession("dropping", w.session);
  const TargetMap m = store.load("dropping");
  EXPECT_EQ(m.size(), 10u);
  EXPECT_EQ(m.sessions.size(), 1u);
  store.drop("dropping");
  EXPECT_FALSE(store.exists("dropping"));
  EXPECT_EQ(count("SELECT count(*) FROM semsegmap_segments g WHERE NOT EXISTS (SELECT 1 FROM "
                  "semsegmap_maps m WHERE m.id = g.map_id)"),
            0);
}

}  // namespace
}  // namespace semsegmap

namespace semsegmap {
namespace {

test_support::Result runCli(const std::string& args) {
  static int counter = 0;
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string stem =
      "semsegmap_store_cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  const std::filesystem::path out = dir / (stem + ".out"), err = dir / (stem + ".err");
  const int status = std::system((std::string("'") + SEMSEGMAP_BINARY + "' " + args + " > '" +
                                  out.string() + "' 2> '" + err.string() + "' < /dev/null")
                                     .c_str());
  test_support::Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = test_support::readFile(out);
  r.err = test_support::readFile(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

// What docs/map-store.md shows: a drive mapped into a store, a second drive joined in place, the
// map listed, shown, localized against, exported, imported and dropped.
TEST(MapStoreCli, MapsJoinsLocalizesListsExportsImportsAndDrops) {
  if (!SEMSEGMAP_WITH_SIM || !SEMSEGMAP_WITH_TORCH)
    GTEST_SKIP() << "needs the simulator and libtorch (the shipped configuration's model)";
  SEMSEGMAP_NEED_SERVER();
  TempDir tmp;
  const std::string uri = "'" + cluster().uri("town") + "'";
  const std::string config = " --config " SEMSEGMAP_SOURCE_DIR "/config/semsegmap.yaml";
  const auto m =
      runCli("map --dataset sim:world=1,run=S0,preset=tiny,frames=45" + config + " --out " + uri);
  ASSERT_EQ(m.code, 0) << m.err;
  const auto again =
      runCli("map --dataset sim:world=1,run=S0,preset=tiny,frames=3" + config + " --out " + uri);
  EXPECT_EQ(again.code, 1);
  EXPECT_NE(again.err.find("map 'town' exists already"), std::string::npos) << again.err;
  const auto into = runCli("map --dataset sim:world=1,run=S0,preset=tiny,frames=45,traffic=7" +
                           config + " --poses odom --into " + uri + " --out " + uri);
  ASSERT_EQ(into.code, 0) << into.err;
  EXPECT_NE(into.out.find("written into"), std::string::npos) << into.out;
  PgMapStore store(parseMapStoreUri(cluster().uri("town")));
  const std::vector<StoredSession> sessions = store.sessions("town");
  ASSERT_EQ(sessions.size(), 2u);
  EXPECT_NE(sessions[1].name.find("traffic=7"), std::string::npos);
  EXPECT_EQ(sessions[1].frames, 45u);

  const auto list = runCli("maps list --store '" + cluster().uri() + "'");
  ASSERT_EQ(list.code, 0) << list.err;
  EXPECT_NE(list.out.find("town"), std::string::npos) << list.out;
  const auto show = runCli("maps show --map " + uri);
  ASSERT_EQ(show.code, 0) << show.err;
  EXPECT_NE(show.out.find("traffic=7"), std::string::npos) << show.out;

  // Localized in tiles from a region around the map's middle (store_tiles.h).
  Eigen::Vector3f middle = Eigen::Vector3f::Zero();
  const TargetMap town = store.load("town");
  for (const MapSegment& s : town.segments) middle += s.centroid / static_cast<float>(town.size());
  const auto localize =
      runCli("localize --dataset sim:world=1,run=S1,preset=tiny,frames=25" + config + " --map '" +
             cluster().uri("town") + "&region=" + std::to_string(middle.x()) + "," +
             std::to_string(middle.y()) + ",150' --out " + (tmp.path() / "loc").string());
  ASSERT_EQ(localize.code, 0) << localize.err;
  EXPECT_NE(localize.err.find("map tiles: "), std::string::npos) << localize.err;
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / "loc" / "localizations.csv"));

  // The viewer on a region of the store, each session in its colour (a build with the viewer).
  const std::string page = (tmp.path() / "town.html").string();
  const auto view = runCli("view --map '" + cluster().uri("town") +
                           "&region=0,0,500' --colour session --out " + page);
  if (view.err.find("this build has no viewer") == std::string::npos) {
    ASSERT_EQ(view.code, 0) << view.err;
    const std::string html = test_support::readFile(page);
    EXPECT_NE(html.find("traffic=7"), std::string::npos);  // the joined session's name
  }

  const std::string file = (tmp.path() / "town.map").string();
  const auto exported = runCli("maps export --map " + uri + " --out " + file);
  ASSERT_EQ(exported.code, 0) << exported.err;
  EXPECT_EQ(loadTargetMap(file).size(), store.load("town").size());
  const auto imported =
      runCli("maps import --from " + file + " --map '" + cluster().uri("copy") + "'");
  ASSERT_EQ(imported.code, 0) << imported.err;
  EXPECT_EQ(store.load("copy").size(), store.load("town").size());

  const auto drop_session =
      runCli("maps drop --map " + uri + " --session " + std::to_string(sessions[1].id));
  ASSERT_EQ(drop_session.code, 0) << drop_session.err;
  EXPECT_EQ(store.sessions("town").size(), 1u);
  const auto drop = runCli("maps drop --map '" + cluster().uri("copy") + "'");
  ASSERT_EQ(drop.code, 0) << drop.err;
  EXPECT_FALSE(store.exists("copy"));
  const auto gone = runCli("maps show --map '" + cluster().uri("copy") + "'");
  EXPECT_EQ(gone.code, 1);
  EXPECT_NE(gone.err.find("no map named 'copy'"), std::string::npos) << gone.err;
}

}  // namespace
}  // namespace semsegmap
