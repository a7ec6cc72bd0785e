#include "semsegmap/store/pg_map_store.h"

#include <libpq-fe.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <stdexcept>

#include "semsegmap/artefacts/map_codec.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/core/binary_io.h"
#include "semsegmap/pipeline/session_merge.h"

namespace semsegmap {

namespace {

// The advisory-lock namespace of this project (the first key of pg_advisory_xact_lock): the
// schema's migration, a map name being created, a map being written.
constexpr int kLockSpace = 7420;
constexpr int kLockMigration = 0, kLockName = 1, kLockMap = 2;

// Each entry migrates the schema from its index to the next version, in one transaction. New
// data of a segment (per-scan keys, denser points, more descriptors) goes into
// semsegmap_segment_extras by kind, without a migration of the segments themselves.
const char* const kMigrations[] = {
    R"sql(
CREATE TABLE semsegmap_maps (
  id serial PRIMARY KEY,
  name text UNIQUE NOT NULL,
  descriptor text NOT NULL,
  fingerprint text NOT NULL,
  dimension integer NOT NULL,
  format_version integer NOT NULL,
  next_segment bigint NOT NULL,
  scan_context_grid bytea,
  created timestamptz NOT NULL DEFAULT now());
CREATE TABLE semsegmap_map_parameters (
  map_id integer NOT NULL REFERENCES semsegmap_maps ON DELETE CASCADE,
  position integer NOT NULL,
  key text NOT NULL,
  value text NOT NULL,
  PRIMARY KEY (map_id, position));
CREATE TABLE semsegmap_sessions (
  id bigserial PRIMARY KEY,
  map_id integer NOT NULL REFERENCES semsegmap_maps ON DELETE CASCADE,
  name text NOT NULL,
  merged_unix_s bigint NOT NULL,
  frames integer NOT NULL,
  trajectory bytea NOT NULL);
CREATE INDEX semsegmap_sessions_map ON semsegmap_sessions (map_id);
CREATE TABLE semsegmap_segments (
  id bigserial PRIMARY KEY,
  map_id integer NOT NULL REFERENCES semsegmap_maps ON DELETE CASCADE,
  session_id bigint NOT NULL REFERENCES semsegmap_sessions ON DELETE CASCADE,
  segment bigint NOT NULL,
  class smallint NOT NULL,
  n_points integer NOT NULL,
  keyframe integer NOT NULL,
  centroid geometry(PointZ, 0) NOT NULL,
  descriptor bytea NOT NULL,
  points bytea);
CREATE INDEX semsegmap_segments_centroid ON semsegmap_segments USING gist (centroid);
CREATE INDEX semsegmap_segments_map ON semsegmap_segments (map_id, segment);
CREATE INDEX semsegmap_segments_session ON semsegmap_segments (session_id);
CREATE TABLE semsegmap_segment_extras (
  entry bigint NOT NULL REFERENCES semsegmap_segments ON DELETE CASCADE,
  kind text NOT NULL,
  data bytea NOT NULL,
  PRIMARY KEY (entry, kind));
CREATE TABLE semsegmap_scan_contexts (
  id bigserial PRIMARY KEY,
  map_id integer NOT NULL REFERENCES semsegmap_maps ON DELETE CASCADE,
  session_id bigint NOT NULL REFERENCES semsegmap_sessions ON DELETE CASCADE,
  position geometry(PointZ, 0) NOT NULL,
  pose bytea NOT NULL,
  bins bytea NOT NULL);
CREATE INDEX semsegmap_scan_contexts_position ON semsegmap_scan_contexts USING gist (position);
CREATE INDEX semsegmap_scan_contexts_session ON semsegmap_scan_contexts (session_id);
)sql",
};
constexpr int kSchemaVersion = static_cast<int>(sizeof(kMigrations) / sizeof(kMigrations[0]));

std::string firstLine(const char* message) {
  std::string s = message ? message : "";
  if (s.rfind("ERROR:  ", 0) == 0) s = s.substr(8);
  const size_t nl = s.find('\n');
  return nl == std::string::npos ? s : s.substr(0, nl);
}

struct Result {
  PGresult* r = nullptr;
  explicit Result(PGresult* result) : r(result) {}
  ~Result() { PQclear(r); }
  Result(Result&& o) noexcept : r(o.r) { o.r = nullptr; }
  Result(const Result&) = delete;
  Result& operator=(const Result&) = delete;
  int rows() const { return PQntuples(r); }
  bool null(int row, int col) const { return PQgetisnull(r, row, col); }
  std::string text(int row, int col) const { return PQgetvalue(r, row, col); }
  int64_t integer(int row, int col) const { return std::stoll(text(row, col)); }
  double number(int row, int col) const { return std::stod(text(row, col)); }
  std::string_view bytes(int row, int col) const {
    return {PQgetvalue(r, row, col), static_cast<size_t>(PQgetlength(r, row, col))};
  }
  // Binary results: PostgreSQL sends numbers big-endian.
  template <typename T>
  T big(int row, int col) const {
    const char* p = PQgetvalue(r, row, col);
    unsigned char b[sizeof(T)];
    for (size_t i = 0; i < sizeof(T); ++i) b[i] = static_cast<unsigned char>(p[sizeof(T) - 1 - i]);
    T v;
    std::memcpy(&v, b, sizeof(T));
    return v;
  }
};

// A connection's errors as one line naming the server: a lost connection says so.
[[noreturn]] void fail(PGconn* c, const std::string& shown, const std::string& doing) {
  if (PQstatus(c) == CONNECTION_BAD)
    throw std::runtime_error(shown + ": the connection to the server was lost while " + doing +
                             " (nothing of it was written): " + firstLine(PQerrorMessage(c)));
  throw std::runtime_error(shown + ": " + doing + ": " + firstLine(PQerrorMessage(c)));
}

Result run(PGconn* c, const std::string& shown, const std::string& doing, const std::string& sql,
           const std::vector<std::string>& params = {}, bool binary = false) {
  std::vector<const char*> values;
  for (const std::string& p : params) values.push_back(p.c_str());
  // Without parameters, as a simple query: a migration is several statements, which a
  // parameterised query cannot hold.
  Result r(params.empty() && !binary
               ? PQexec(c, sql.c_str())
               : PQexecParams(c, sql.c_str(), static_cast<int>(values.size()), nullptr,
                              values.data(), nullptr, nullptr, binary ? 1 : 0));
  const ExecStatusType status = PQresultStatus(r.r);
  if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) fail(c, shown, doing);
  return r;
}

// BEGIN ... COMMIT; rolled back when left without commit() (an exception, a lost connection).
class Transaction {
 public:
  Transaction(PGconn* c, const std::string& shown, const std::string& doing)
      : c_(c), shown_(shown), doing_(doing) {
    run(c_, shown_, doing_, "BEGIN");
  }
  ~Transaction() {
    if (!done_) PQclear(PQexec(c_, "ROLLBACK"));
  }
  Transaction(const Transaction&) = delete;
  Transaction& operator=(const Transaction&) = delete;
  void lock(int key, const std::string& value_sql, const std::vector<std::string>& params) {
    run(c_, shown_, doing_,
        "SELECT pg_advisory_xact_lock(" + std::to_string(kLockSpace) + " + " + std::to_string(key) +
            ", " + value_sql + ")",
        params);
  }
  void commit() {
    run(c_, shown_, doing_, "COMMIT");
    done_ = true;
  }

 private:
  PGconn* c_;
  std::string shown_, doing_;
  bool done_ = false;
};

// COPY ... FROM STDIN in text format, `rows` already escaped and tab-separated.
void copyIn(PGconn* c, const std::string& shown, const std::string& doing, const std::string& sql,
            const std::string& rows) {
  Result start(PQexec(c, sql.c_str()));
  if (PQresultStatus(start.r) != PGRES_COPY_IN) fail(c, shown, doing);
  constexpr size_t kChunk = 1 << 20;
  for (size_t at = 0; at < rows.size(); at += kChunk)
    if (PQputCopyData(c, rows.data() + at, static_cast<int>(std::min(kChunk, rows.size() - at))) !=
        1)
      fail(c, shown, doing);
  if (PQputCopyEnd(c, nullptr) != 1) fail(c, shown, doing);
  bool ok = true;
  while (PGresult* r = PQgetResult(c)) {
    ok = ok && PQresultStatus(r) == PGRES_COMMAND_OK;
    PQclear(r);
  }
  if (!ok) fail(c, shown, doing);
}

// bytea in COPY's text format: \\x and hex digits.
void appendBytea(std::string& out, const std::string& bytes) {
  static const char* const kHex = "0123456789abcdef";
  out += "\\\\x";
  for (unsigned char b : bytes) {
    out += kHex[b >> 4];
    out += kHex[b & 15];
  }
}

void appendPoint(std::string& out, const Eigen::Vector3d& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "POINT(%.17g %.17g %.17g)", p.x(), p.y(), p.z());
  out += buf;
}

std::string descriptorBytes(const Eigen::MatrixXf& descriptors, Eigen::Index row) {
  BinaryWriter w;
  for (Eigen::Index k = 0; k < descriptors.cols(); ++k) putHalf(w, descriptors(row, k));
  return w.take();
}

// One segment row of COPY semsegmap_segments (map_id, session_id, segment, class, n_points,
// keyframe, centroid, descriptor, points).
void appendSegmentRow(std::string& out, int map_id, int64_t session_id, int64_t segment,
                      const MapSegment& s, const std::string& descriptor) {
  out += std::to_string(map_id) + '\t' + std::to_string(session_id) + '\t' +
         std::to_string(segment) + '\t' + std::to_string(s.majority_class) + '\t' +
         std::to_string(s.n_points) + '\t' + std::to_string(s.keyframe) + '\t';
  appendPoint(out, s.centroid.cast<double>());
  out += '\t';
  appendBytea(out, descriptor);
  out += '\t';
  if (s.points.empty()) {
    out += "\\N";
  } else {
    BinaryWriter w;
    putPoints(w, s);
    appendBytea(out, w.take());
  }
  out += '\n';
}

void appendScanRow(std::string& out, int map_id, int64_t session_id,
                   const ScanContextDatabase::MappedScan& scan) {
  out += std::to_string(map_id) + '\t' + std::to_string(session_id) + '\t';
  appendPoint(out, scan.T_world_scan.translation());
  out += '\t';
  BinaryWriter pose, bins;
  putPose(pose, scan.T_world_scan);
  appendBytea(out, pose.take());
  out += '\t';
  for (Eigen::Index i = 0; i < scan.context.bins.size(); ++i) putHalf(bins, scan.context.bins(i));
  appendBytea(out, bins.take());
  out += '\n';
}

std::string trajectoryBytes(const std::vector<Pose>& trajectory) {
  BinaryWriter w;
  for (const Pose& T : trajectory) putPose(w, T);
  return w.take();
}

// A text parameter holding bytes: bytea's hex input.
std::string byteaParam(const std::string& bytes) {
  std::string out;
  appendBytea(out, bytes);
  return out.substr(1);  // COPY's escaped backslash is one in a parameter
}

}  // namespace

int mapStoreSchemaVersion() {
  return kSchemaVersion;
}

namespace {

// PostGIS, then the schema from the store's version to this build's, once per store: the first
// writer to connect does it under the migration lock, the others find it done.
void migrate(PGconn* c, const std::string& shown) {
  const std::string doing = "preparing the map store";
  Transaction t(c, shown, doing);
  t.lock(kLockMigration, "0", {});
  if (run(c, shown, doing, "SELECT 1 FROM pg_extension WHERE extname = 'postgis'").rows() == 0) {
    if (run(c, shown, doing, "SELECT 1 FROM pg_available_extensions WHERE name = 'postgis'")
            .rows() == 0)
      throw std::runtime_error(shown +
                               ": the server has no PostGIS, which the map store needs (on "
                               "Debian: apt-get install postgresql-15-postgis-3)");
    run(c, shown, "creating the PostGIS extension (a superuser can: CREATE EXTENSION postgis)",
        "CREATE EXTENSION postgis");
  }
  run(c, shown, doing, "CREATE TABLE IF NOT EXISTS semsegmap_schema (version integer NOT NULL)");
  const Result v = run(c, shown, doing, "SELECT version FROM semsegmap_schema");
  const int version = v.rows() ? static_cast<int>(v.integer(0, 0)) : 0;
  if (version > kSchemaVersion)
    throw std::runtime_error(shown + ": the map store has schema version " +
                             std::to_string(version) + ", newer than this build's " +
                             std::to_string(kSchemaVersion) + ": update semsegmap");
  for (int from = version; from < kSchemaVersion; ++from)
    run(c, shown, "migrating the map store to schema version " + std::to_string(from + 1),
        kMigrations[from]);
  if (version == 0)
    run(c, shown, doing, "INSERT INTO semsegmap_schema VALUES ($1)",
        {std::to_string(kSchemaVersion)});
  else if (version < kSchemaVersion)
    run(c, shown, doing, "UPDATE semsegmap_schema SET version = $1",
        {std::to_string(kSchemaVersion)});
  t.commit();
}

void ignoreNotice(void*, const char*) {}

}  // namespace

PgMapStore::PgMapStore(const MapStoreUri& uri) : shown_(uri.shown) {
  conn_ = PQconnectdb(uri.conninfo.c_str());
  if (!conn_) throw std::runtime_error(shown_ + ": out of memory connecting");
  if (PQstatus(conn_) != CONNECTION_OK) {
    const std::string why = firstLine(PQerrorMessage(conn_));
    PQfinish(conn_);
    throw std::runtime_error(shown_ + ": cannot connect: " + why);
  }
  // "relation already exists, skipping" and the like are not the user's business.
  PQsetNoticeProcessor(conn_, ignoreNotice, nullptr);
  try {
    migrate(conn_, shown_);
  } catch (...) {
    PQfinish(conn_);
    throw;
  }
}

PgMapStore::~PgMapStore() {
  PQfinish(conn_);
}

int PgMapStore::mapId(const std::string& name) {
  const Result r = run(conn_, shown_, "looking up map " + name,
                       "SELECT id FROM semsegmap_maps WHERE name = $1", {name});
  if (r.rows() == 0) {
    std::string known;
    for (const StoredMap& m : list()) known += (known.empty() ? "" : ", ") + m.name;
    throw std::runtime_error(shown_ + ": no map named '" + name + "' in the store (" +
                             (known.empty() ? "it holds none" : "it holds " + known) + ")");
  }
  return static_cast<int>(r.integer(0, 0));
}

bool PgMapStore::exists(const std::string& name) {
  return run(conn_, shown_, "looking up map " + name,
             "SELECT 1 FROM semsegmap_maps WHERE name = $1", {name})
             .rows() > 0;
}

std::vector<StoredMap> PgMapStore::list() {
  const Result r = run(conn_, shown_, "listing the maps", R"sql(
SELECT m.name, m.descriptor, m.dimension, extract(epoch FROM m.created)::bigint,
  (SELECT count(*) FROM semsegmap_sessions s WHERE s.map_id = m.id),
  count(g.id), count(DISTINCT g.segment),
  coalesce(min(ST_X(g.centroid)), 0), coalesce(min(ST_Y(g.centroid)), 0),
  coalesce(max(ST_X(g.centroid)), 0), coalesce(max(ST_Y(g.centroid)), 0)
FROM semsegmap_maps m LEFT JOIN semsegmap_segments g ON g.map_id = m.id
GROUP BY m.id ORDER BY m.name)sql");
  std::vector<StoredMap> maps(static_cast<size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i) {
    StoredMap& m = maps[static_cast<size_t>(i)];
    m.name = r.text(i, 0);
    m.descriptor = r.text(i, 1);
    m.dimension = static_cast<int>(r.integer(i, 2));
    m.created_unix_s = r.integer(i, 3);
    m.sessions = static_cast<size_t>(r.integer(i, 4));
    m.entries = static_cast<size_t>(r.integer(i, 5));
    m.segments = static_cast<size_t>(r.integer(i, 6));
    m.min_x = r.number(i, 7), m.min_y = r.number(i, 8);
    m.max_x = r.number(i, 9), m.max_y = r.number(i, 10);
  }
  return maps;
}

StoredMap PgMapStore::show(const std::string& name) {
  mapId(name);  // the error naming the maps there are
  for (StoredMap& m : list())
    if (m.name == name) return m;
  throw std::runtime_error(shown_ + ": map '" + name + "' was dropped meanwhile");
}

std::vector<StoredSession> PgMapStore::sessions(const std::string& name) {
  const int id = mapId(name);
  const Result r = run(conn_, shown_, "listing the sessions of " + name, R"sql(
SELECT s.id, s.name, s.merged_unix_s, s.frames,
  (SELECT count(*) FROM semsegmap_segments g WHERE g.session_id = s.id)
FROM semsegmap_sessions s WHERE s.map_id = $1 ORDER BY s.id)sql",
                       {std::to_string(id)});
  std::vector<StoredSession> out(static_cast<size_t>(r.rows()));
  for (int i = 0; i < r.rows(); ++i)
    out[static_cast<size_t>(i)] = {r.integer(i, 0), r.text(i, 1), r.integer(i, 2),
                                   static_cast<size_t>(r.integer(i, 3)),
                                   static_cast<size_t>(r.integer(i, 4))};
  return out;
}

namespace {

// The map's entries that `where` selects (an SQL condition on the segments g, its parameters
// from $2; $1 is the map id), appended to `into` with their sessions' positions.
void readSegments(PGconn* c, const std::string& shown, const std::string& where,
                  std::vector<std::string> params, const std::map<int64_t, uint16_t>& position,
                  TargetMap& into) {
  const Result r = run(c, shown, "loading the segments",
                       R"sql(
SELECT g.session_id, g.segment, g.class, g.n_points, g.keyframe,
  ST_X(g.centroid), ST_Y(g.centroid), ST_Z(g.centroid), g.descriptor, g.points
FROM semsegmap_segments g WHERE g.map_id = $1 AND )sql" +
                           where + " ORDER BY g.id",
                       params, /*binary=*/true);
  const Eigen::Index dim = into.descriptors.cols(), before = into.descriptors.rows();
  into.descriptors.conservativeResize(before + r.rows(), dim);
  for (int i = 0; i < r.rows(); ++i) {
    MapSegment s;
    const auto session = position.find(r.big<int64_t>(i, 0));
    if (session == position.end()) throw std::runtime_error(shown + ": an entry of no session");
    s.session = session->second;
    s.segment = static_cast<uint32_t>(r.big<int64_t>(i, 1));
    s.majority_class = static_cast<ClassId>(r.big<int16_t>(i, 2));
    s.n_points = static_cast<uint32_t>(r.big<int32_t>(i, 3));
    s.keyframe = static_cast<uint32_t>(r.big<int32_t>(i, 4));
    s.centroid = Eigen::Vector3d(r.big<double>(i, 5), r.big<double>(i, 6), r.big<double>(i, 7))
                     .cast<float>();
    const std::string_view descriptor = r.bytes(i, 8);
    BinaryReader d(shown, descriptor, "map store entry");
    if (descriptor.size() != static_cast<size_t>(2 * dim))
      d.fail("a descriptor of " + std::to_string(descriptor.size()) + " bytes, the map's have " +
             std::to_string(2 * dim));
    for (Eigen::Index k = 0; k < dim; ++k)
      into.descriptors(before + i, k) = getHalf(d, "a descriptor");
    if (!r.null(i, 9)) {
      BinaryReader p(shown, r.bytes(i, 9), "map store entry");
      getPoints(p, r.bytes(i, 9).size() / 6, s);
    }
    into.segments.push_back(std::move(s));
  }
}

void readScanContexts(PGconn* c, const std::string& shown, const std::string& where,
                      const std::vector<std::string>& params, std::string_view grid,
                      TargetMap& into) {
  BinaryReader g(shown, grid, "map store scan context grid");
  into.scan_contexts = getScanContexts(g);
  const ScanContextConfig& config = into.scan_contexts.config();
  const Result r = run(c, shown, "loading the scan contexts",
                       "SELECT pose, bins FROM semsegmap_scan_contexts WHERE map_id = $1 AND " +
                           where + " ORDER BY id",
                       params, /*binary=*/true);
  for (int i = 0; i < r.rows(); ++i) {
    BinaryReader pose(shown, r.bytes(i, 0), "map store scan context");
    const Pose T = getPose(pose, "scan context " + std::to_string(i));
    BinaryReader bins(shown, r.bytes(i, 1), "map store scan context");
    Eigen::MatrixXf b(config.rings, config.sectors);
    bins.need(static_cast<size_t>(b.size()), 2, "a scan context");
    for (Eigen::Index k = 0; k < b.size(); ++k) b(k) = getHalf(bins, "a scan context");
    into.scan_contexts.add(scanContextOfBins(std::move(b)), T);
  }
}

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

// Which entries and scan contexts a load reads: SQL conditions on the segment's centroid
// (g.centroid) and the scan context's position, their parameters from $2 ($1 is the map's id).
struct PgMapStore::Selection {
  std::string segments = "true", scans = "true";
  std::vector<std::string> params;
  bool every_session = true;  // else only those with entries selected
};

namespace {

PgMapStore::Selection regionSelection(const MapRegion& r) {
  PgMapStore::Selection s;
  const auto within = [](const char* column) {
    return std::string("ST_DWithin(") + column + ", ST_SetSRID(ST_MakePoint($2, $3), 0), $4)";
  };
  s.segments = within("g.centroid");
  s.scans = within("position");
  s.params = {number(r.x), number(r.y), number(r.radius_m)};
  s.every_session = false;
  return s;
}

// Half-open boxes [x0, x1) x [y0, y1): an entry on a shared edge is in one tile only. The bounding
// box test (&&) lets the spatial index find them.
PgMapStore::Selection boxSelection(const std::vector<MapBox>& boxes) {
  PgMapStore::Selection s;
  s.every_session = false;
  std::string segments, scans;
  for (const MapBox& b : boxes) {
    const auto n = [&](size_t k) { return "$" + std::to_string(2 + s.params.size() + k); };
    const std::string x0 = n(0), y0 = n(1), x1 = n(2), y1 = n(3);
    const auto in = [&](const std::string& c) {
      return "(" + c + " && ST_MakeEnvelope(" + x0 + ", " + y0 + ", " + x1 + ", " + y1 +
             ", 0) AND ST_X(" + c + ") >= " + x0 + " AND ST_X(" + c + ") < " + x1 + " AND ST_Y(" +
             c + ") >= " + y0 + " AND ST_Y(" + c + ") < " + y1 + ")";
    };
    segments += (segments.empty() ? "" : " OR ") + in("g.centroid");
    scans += (scans.empty() ? "" : " OR ") + in("position");
    for (double v : {b.x0, b.y0, b.x1, b.y1}) s.params.push_back(number(v));
  }
  if (boxes.empty()) segments = scans = "false";
  s.segments = "(" + segments + ")";
  s.scans = "(" + scans + ")";
  return s;
}

}  // namespace

TargetMap PgMapStore::load(const std::string& name, const std::optional<MapRegion>& region,
                           MapSnapshot* snapshot) {
  return loadSelected(name, region ? regionSelection(*region) : Selection{}, snapshot);
}

TargetMap PgMapStore::loadBoxes(const std::string& name, const std::vector<MapBox>& boxes) {
  return loadSelected(name, boxSelection(boxes), nullptr);
}

TargetMap PgMapStore::loadSelected(const std::string& name, const Selection& selection,
                                   MapSnapshot* snapshot) {
  const std::string doing = "loading map " + name;
  Transaction t(conn_, shown_, doing);
  run(conn_, shown_, doing, "SET TRANSACTION ISOLATION LEVEL REPEATABLE READ");
  // A region's few thousand rows come from the spatial index in about a millisecond; a parallel
  // plan, which PostgreSQL picks for larger discs, spends 100 ms starting its worker.
  run(conn_, shown_, doing, "SET LOCAL max_parallel_workers_per_gather = 0");
  const int id = mapId(name);
  const std::string sid = std::to_string(id);
  const Result head = run(conn_, shown_, doing,
                          "SELECT descriptor, fingerprint, dimension, format_version, "
                          "scan_context_grid FROM semsegmap_maps WHERE id = $1",
                          {sid}, /*binary=*/true);
  const int version = head.big<int32_t>(0, 3);
  if (version != static_cast<int>(kMapFormatVersion))
    throw std::runtime_error(shown_ + ": map '" + name + "' is of map format version " +
                             std::to_string(version) + ", this build reads version " +
                             std::to_string(kMapFormatVersion) + " (rebuild it)");
  TargetMap map;
  map.descriptor = head.text(0, 0);
  map.fingerprint = head.text(0, 1);
  map.descriptors.resize(0, head.big<int32_t>(0, 2));
  const Result params = run(conn_, shown_, doing,
                            "SELECT key, value FROM semsegmap_map_parameters WHERE map_id = $1 "
                            "ORDER BY position",
                            {sid});
  for (int i = 0; i < params.rows(); ++i)
    map.parameters.emplace_back(params.text(i, 0), params.text(i, 1));
  std::vector<std::string> p = {sid};
  p.insert(p.end(), selection.params.begin(), selection.params.end());
  // A region's sessions are those with entries in it: a store of thousands of drives would
  // otherwise send every trajectory with every tile.
  const Result sessions =
      run(conn_, shown_, doing,
          "SELECT s.id, s.name, s.merged_unix_s, s.trajectory "
          "FROM semsegmap_sessions s WHERE s.map_id = $1 AND " +
              (selection.every_session ? std::string("true")
                                       : "s.id IN (SELECT g.session_id FROM semsegmap_segments g "
                                         "WHERE g.map_id = $1 AND " +
                                             selection.segments + ")") +
              " ORDER BY s.id",
          p, /*binary=*/true);
  std::map<int64_t, uint16_t> position;
  for (int i = 0; i < sessions.rows(); ++i) {
    position[sessions.big<int64_t>(i, 0)] = static_cast<uint16_t>(i);
    MapSession s{sessions.text(i, 1), sessions.big<int64_t>(i, 2), {}};
    BinaryReader r(shown_, sessions.bytes(i, 3), "map store trajectory");
    const size_t poses = sessions.bytes(i, 3).size() / kPoseBytes;
    for (size_t k = 0; k < poses; ++k)
      s.trajectory.push_back(getPose(r, "session " + s.name + " pose " + std::to_string(k)));
    r.expectEnd("the trajectory");
    map.sessions.push_back(std::move(s));
  }
  readSegments(conn_, shown_, selection.segments, p, position, map);
  if (!head.null(0, 4)) readScanContexts(conn_, shown_, selection.scans, p, head.bytes(0, 4), map);
  t.commit();
  if (const std::string bad = firstUnsavable(map); !bad.empty())
    throw std::runtime_error(shown_ + ": map '" + name + "': " + bad);
  if (snapshot) {
    *snapshot = {};
    if (!position.empty()) snapshot->last_session = position.rbegin()->first;
    for (const MapSegment& s : map.segments)
      snapshot->first_fresh = std::max(snapshot->first_fresh, s.segment + 1);
    snapshot->scan_contexts = map.scan_contexts.size();
  }
  map.source = shown_;
  return map;
}

namespace {

int64_t insertSession(PGconn* c, const std::string& shown, int map_id, const MapSession& s) {
  return run(c, shown, "writing session " + s.name,
             "INSERT INTO semsegmap_sessions (map_id, name, merged_unix_s, frames, trajectory) "
             "VALUES ($1, $2, $3, $4, $5) RETURNING id",
             {std::to_string(map_id), s.name, std::to_string(s.merged_unix_s),
              std::to_string(s.trajectory.size()), byteaParam(trajectoryBytes(s.trajectory))})
      .integer(0, 0);
}

const char* const kCopySegments =
    "COPY semsegmap_segments (map_id, session_id, segment, class, n_points, keyframe, centroid, "
    "descriptor, points) FROM STDIN";
const char* const kCopyScans =
    "COPY semsegmap_scan_contexts (map_id, session_id, position, pose, bins) FROM STDIN";

}  // namespace

void PgMapStore::create(const std::string& name, const TargetMap& map,
                        const std::string& session_name) {
  if (!isMapName(name))
    throw std::invalid_argument(shown_ + ": map name '" + name +
                                "' must be 1..63 letters, digits, '.', '_' or '-'");
  if (const std::string bad = firstUnsavable(map); !bad.empty())
    throw std::invalid_argument(shown_ + ": " + bad);
  const std::string doing = "writing map " + name;
  Transaction t(conn_, shown_, doing);
  t.lock(kLockName, "hashtext($1)", {name});
  if (exists(name))
    throw std::runtime_error(shown_ + ": map '" + name +
                             "' exists already (add a drive to it with `semsegmap map --into`, "
                             "or remove it with `semsegmap maps drop`)");
  uint32_t next_segment = 0;
  for (const MapSegment& s : map.segments) next_segment = std::max(next_segment, s.segment + 1);
  BinaryWriter grid;
  putScanContexts(grid, ScanContextDatabase(map.scan_contexts.config()));
  const int id = static_cast<int>(
      run(conn_, shown_, doing,
          "INSERT INTO semsegmap_maps (name, descriptor, fingerprint, dimension, "
          "format_version, next_segment, scan_context_grid) VALUES ($1, $2, $3, $4, $5, $6, $7) "
          "RETURNING id",
          {name, map.descriptor, map.fingerprint, std::to_string(map.dimension()),
           std::to_string(kMapFormatVersion), std::to_string(next_segment),
           byteaParam(grid.take())})
          .integer(0, 0));
  for (size_t i = 0; i < map.parameters.size(); ++i)
    run(conn_, shown_, doing,
        "INSERT INTO semsegmap_map_parameters (map_id, position, key, value) "
        "VALUES ($1, $2, $3, $4)",
        {std::to_string(id), std::to_string(i), map.parameters[i].first, map.parameters[i].second});
  std::vector<MapSession> sessions = map.sessions;
  if (sessions.empty()) sessions.push_back({session_name, std::time(nullptr), {}});
  std::vector<int64_t> session_ids;
  for (const MapSession& s : sessions) session_ids.push_back(insertSession(conn_, shown_, id, s));
  std::string rows;
  for (size_t i = 0; i < map.segments.size(); ++i) {
    const MapSegment& s = map.segments[i];
    // A map without sessions is one session's: its keyframes index no trajectory.
    MapSegment row = s;
    if (map.sessions.empty()) row.session = 0, row.keyframe = 0;
    appendSegmentRow(rows, id, session_ids[row.session], row.segment, row,
                     descriptorBytes(map.descriptors, static_cast<Eigen::Index>(i)));
  }
  copyIn(conn_, shown_, doing, kCopySegments, rows);
  rows.clear();
  // A map file does not say which session made a scan context: they go with the first.
  for (const ScanContextDatabase::MappedScan& scan : map.scan_contexts.scans())
    appendScanRow(rows, id, session_ids.front(), scan);
  copyIn(conn_, shown_, doing, kCopyScans, rows);
  t.commit();
}

NewSession lastSessionOf(const TargetMap& merged, const MapSnapshot& snapshot) {
  if (merged.sessions.empty()) throw std::invalid_argument("lastSessionOf: a map of no session");
  NewSession out;
  out.info = merged.sessions.back();
  const auto index = static_cast<uint16_t>(merged.sessions.size() - 1);
  std::vector<Eigen::Index> rows;
  for (size_t i = 0; i < merged.segments.size(); ++i)
    if (merged.segments[i].session == index) {
      out.entries.push_back(merged.segments[i]);
      rows.push_back(static_cast<Eigen::Index>(i));
    }
  out.descriptors.resize(static_cast<Eigen::Index>(rows.size()), merged.dimension());
  for (size_t k = 0; k < rows.size(); ++k)
    out.descriptors.row(static_cast<Eigen::Index>(k)) = merged.descriptors.row(rows[k]);
  const auto& scans = merged.scan_contexts.scans();
  out.scans.assign(
      scans.begin() + static_cast<std::ptrdiff_t>(std::min(snapshot.scan_contexts, scans.size())),
      scans.end());
  return out;
}

namespace {

// For each of `session`'s entries that are its own (segment id >= snapshot.first_fresh), the
// segment of an entry of a session that landed after the snapshot that it is an observation of
// (joinSession's rule), or -1. Runs under the map's lock.
std::vector<int64_t> joinMeanwhile(PGconn* c, const std::string& shown, int map_id,
                                   const NewSession& session, const MapSnapshot& snapshot,
                                   double same_segment_m) {
  std::vector<int64_t> joined(session.entries.size(), -1);
  const std::vector<std::string> p = {std::to_string(map_id),
                                      std::to_string(snapshot.last_session)};
  const Result later = run(c, shown, "reading the sessions written meanwhile",
                           "SELECT id FROM semsegmap_sessions WHERE map_id = $1 AND id > $2 "
                           "ORDER BY id",
                           p);
  if (later.rows() == 0) return joined;
  TargetMap newer;
  newer.descriptors.resize(0, session.descriptors.cols());
  std::map<int64_t, uint16_t> position;
  for (int i = 0; i < later.rows(); ++i) {
    position[later.integer(i, 0)] = static_cast<uint16_t>(i);
    newer.sessions.push_back({});
  }
  readSegments(c, shown, "g.session_id > $2", p, position, newer);
  if (newer.segments.empty()) return joined;
  TargetMap own;
  std::vector<size_t> index;
  for (size_t i = 0; i < session.entries.size(); ++i)
    if (session.entries[i].segment >= snapshot.first_fresh) index.push_back(i);
  own.descriptors.resize(static_cast<Eigen::Index>(index.size()), session.descriptors.cols());
  for (size_t k = 0; k < index.size(); ++k) {
    own.segments.push_back(session.entries[index[k]]);
    own.descriptors.row(static_cast<Eigen::Index>(k)) =
        session.descriptors.row(static_cast<Eigen::Index>(index[k]));
  }
  uint32_t newer_next = 0;
  for (const MapSegment& s : newer.segments) newer_next = std::max(newer_next, s.segment + 1);
  const size_t before = newer.segments.size();
  joinSession(newer, own, {}, same_segment_m);
  for (size_t k = 0; k < index.size(); ++k)
    if (newer.segments[before + k].segment < newer_next)
      joined[index[k]] = newer.segments[before + k].segment;
  return joined;
}

}  // namespace

SessionWrite PgMapStore::addSession(const std::string& name, const NewSession& session,
                                    const MapSnapshot& snapshot, double same_segment_m) {
  const std::string doing = "writing session " + session.info.name + " into map " + name;
  if (static_cast<size_t>(session.descriptors.rows()) != session.entries.size())
    throw std::invalid_argument(shown_ + ": " + doing + ": entries and descriptors differ");
  Transaction t(conn_, shown_, doing);
  const int id = mapId(name);
  t.lock(kLockMap, "$1", {std::to_string(id)});
  const std::string sid = std::to_string(id);
  const int64_t dimension =
      run(conn_, shown_, doing, "SELECT dimension FROM semsegmap_maps WHERE id = $1", {sid})
          .integer(0, 0);
  if (dimension != session.descriptors.cols())
    throw std::runtime_error(shown_ + ": " + doing + ": descriptors of dimension " +
                             std::to_string(session.descriptors.cols()) + ", the map's have " +
                             std::to_string(dimension));
  SessionWrite out;
  out.entries = session.entries.size();
  std::vector<int64_t> segment =
      joinMeanwhile(conn_, shown_, id, session, snapshot, same_segment_m);
  std::map<uint32_t, int64_t> fresh;  // the session's own ids -> the store's
  for (size_t i = 0; i < segment.size(); ++i) {
    const uint32_t own = session.entries[i].segment;
    if (segment[i] >= 0)
      ++out.joined_meanwhile;
    else if (own < snapshot.first_fresh)
      segment[i] = own;
    else
      fresh.emplace(own, -1);
  }
  out.new_segments = fresh.size();
  const int64_t base = run(conn_, shown_, doing,
                           "UPDATE semsegmap_maps SET next_segment = next_segment + $2 "
                           "WHERE id = $1 RETURNING next_segment - $2",
                           {sid, std::to_string(fresh.size())})
                           .integer(0, 0);
  int64_t next = base;
  for (auto& [own, store] : fresh) store = next++;
  if (next > static_cast<int64_t>(UINT32_MAX))
    throw std::runtime_error(shown_ + ": map '" + name + "' has run out of segment ids");
  for (size_t i = 0; i < segment.size(); ++i)
    if (segment[i] < 0) segment[i] = fresh.at(session.entries[i].segment);
  out.session = insertSession(conn_, shown_, id, session.info);
  std::string rows;
  for (size_t i = 0; i < session.entries.size(); ++i)
    appendSegmentRow(rows, id, out.session, segment[i], session.entries[i],
                     descriptorBytes(session.descriptors, static_cast<Eigen::Index>(i)));
  copyIn(conn_, shown_, doing, kCopySegments, rows);
  rows.clear();
  for (const ScanContextDatabase::MappedScan& scan : session.scans)
    appendScanRow(rows, id, out.session, scan);
  copyIn(conn_, shown_, doing, kCopyScans, rows);
  t.commit();
  return out;
}

void PgMapStore::drop(const std::string& name) {
  Transaction t(conn_, shown_, "dropping map " + name);
  const int id = mapId(name);
  t.lock(kLockMap, "$1", {std::to_string(id)});
  run(conn_, shown_, "dropping map " + name, "DELETE FROM semsegmap_maps WHERE id = $1",
      {std::to_string(id)});
  t.commit();
}

void PgMapStore::dropSession(const std::string& name, int64_t session) {
  const std::string doing = "dropping session " + std::to_string(session) + " of map " + name;
  Transaction t(conn_, shown_, doing);
  const int id = mapId(name);
  t.lock(kLockMap, "$1", {std::to_string(id)});
  const Result r =
      run(conn_, shown_, doing, "DELETE FROM semsegmap_sessions WHERE id = $1 AND map_id = $2",
          {std::to_string(session), std::to_string(id)});
  if (std::string(PQcmdTuples(r.r)) != "1") {
    std::string known;
    for (const StoredSession& s : sessions(name))
      known += (known.empty() ? "" : ", ") + std::to_string(s.id);
    throw std::runtime_error(shown_ + ": map '" + name + "' has no session " +
                             std::to_string(session) + " (its sessions: " + known + ")");
  }
  t.commit();
}

}  // namespace semsegmap
