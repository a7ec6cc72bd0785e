// The map store at a fleet's scale ([fleet] targets; docs/map-store.md, "At scale (bench)"): a
// PostgreSQL + PostGIS store of millions of segments on a server of its own, and what a robot
// asks of it, measured on this machine. A plain program, not a Google Benchmark: a run at 10
// million segments takes half an hour.
//
//   semsegmap_store_bench --source MAP --json OUT [--queries MAP] [--segments N] [options]
//
// The city: the source map (one simulated run's target map) copied over a grid of tiles, each
// shifted by the map's extent plus --margin so that no two overlap, until N segments; each tile
// one session written by PgMapStore (create for the first, addSession for the others: the
// library's own path, no bulk path). Then, against a durable server (fsync on) restarted with its
// files evicted from the page cache:
// - region loads (a disc of --radius, 100 m: the 200 m x 200 m target as the inscribed disc, and
//   the circumscribed disc as well) at random places of the city: first load (cold) and again
//   (warm), the connection made before and not timed;
// - sessions of --insert-size entries inserted at new places with addSession (then dropped);
// - localization of robot-like queries (another run's segments around a place, in a rotated
//   local frame) against the region loaded around the true place, against a file map of the
//   whole city (saveTargetMap, loaded and indexed once, timed apart) and against the source map
//   alone (no look-alike tiles: the reference);
// - the whole map loaded from the store (what `map --into` on a store does first).
// Every number goes to the JSON, written after each phase ("complete": false until the end).
// Wrong input (a missing or unreadable map, a bad option) exits non-zero with one line. The
// server is stopped and its folder removed however the program ends: a watchdog process does it
// when this one exits, even by SIGKILL.
#include <fcntl.h>
#include <libpq-fe.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "pg_cluster.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/localize/localizer.h"
#include "semsegmap/store/map_store_uri.h"
#include "semsegmap/store/pg_map_store.h"

using namespace semsegmap;
using json = nlohmann::json;
using test_support::PgCluster;

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

const char* const kUsage =
    "usage: semsegmap_store_bench --source MAP --json OUT [--queries MAP] [--segments N]\n"
    "  --source MAP       the target map tiled over the city (a map file of one run)\n"
    "  --json OUT         where the numbers go\n"
    "  --queries MAP      another run's map of the same world: the robot's segments\n"
    "                     (default: the source's own entries, perturbed)\n"
    "  --segments N       segments in the store (default 10000000)\n"
    "  --margin M         metres between tiles (default 50)\n"
    "  --radius R         region radius, metres (default 100: the disc in a 200 m square)\n"
    "  --loads K          region loads, each at a new random place (default 200)\n"
    "  --inserts K        sessions inserted (default 10)\n"
    "  --insert-size N    entries per inserted session (default 1000)\n"
    "  --localizations K  localization queries (default 100)\n"
    "  --query-radius R   the robot's local segments: within R metres (default 50)\n"
    "  --seed S           (default 1)\n"
    "  --no-file-map      skip the file map of the whole city (memory: ~9 GB at 10M)\n"
    "  --no-whole-load    skip loading the whole map from the store (several GB at 10M)\n";

struct Options {
  std::string source, queries, json;
  size_t segments = 10'000'000;
  double margin_m = 50.0, radius_m = 100.0, query_radius_m = 50.0;
  size_t loads = 200, inserts = 10, insert_size = 1000, localizations = 100;
  unsigned seed = 1;
  bool file_map = true, whole_load = true;
};

size_t positiveCount(const std::string& flag, const std::string& v) {
  size_t used = 0;
  unsigned long long n = 0;
  try {
    n = std::stoull(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v.size() || v.empty() || v[0] == '-' || n == 0)
    throw UsageError(flag + " takes a positive whole number, not '" + v + "'");
  return static_cast<size_t>(n);
}

double positiveNumber(const std::string& flag, const std::string& v, bool zero_ok = false) {
  size_t used = 0;
  double x = 0;
  try {
    x = std::stod(v, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != v.size() || v.empty() || !std::isfinite(x) || x < 0 || (x == 0 && !zero_ok))
    throw UsageError(flag + " takes a number " + (zero_ok ? ">= 0" : "> 0") + ", not '" + v + "'");
  return x;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    }
    if (a == "--no-file-map") {
      o.file_map = false;
      continue;
    }
    if (a == "--no-whole-load") {
      o.whole_load = false;
      continue;
    }
    if (a.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + a + "'");
    if (i + 1 >= argc) throw UsageError(a + " needs a value");
    const std::string v = argv[++i];
    if (a == "--source")
      o.source = v;
    else if (a == "--queries")
      o.queries = v;
    else if (a == "--json")
      o.json = v;
    else if (a == "--segments")
      o.segments = positiveCount(a, v);
    else if (a == "--margin")
      o.margin_m = positiveNumber(a, v, /*zero_ok=*/true);
    else if (a == "--radius")
      o.radius_m = positiveNumber(a, v);
    else if (a == "--loads")
      o.loads = positiveCount(a, v);
    else if (a == "--inserts")
      o.inserts = positiveCount(a, v);
    else if (a == "--insert-size")
      o.insert_size = positiveCount(a, v);
    else if (a == "--localizations")
      o.localizations = positiveCount(a, v);
    else if (a == "--query-radius")
      o.query_radius_m = positiveNumber(a, v);
    else if (a == "--seed")
      o.seed = static_cast<unsigned>(positiveCount(a, v));
    else
      throw UsageError("unknown option " + a);
  }
  if (o.source.empty()) throw UsageError("--source MAP is required");
  if (o.json.empty()) throw UsageError("--json OUT is required");
  return o;
}

// A map file that must be there: a missing one says so before loadTargetMap's own message.
TargetMap loadInput(const std::string& flag, const std::string& path) {
  if (!std::filesystem::is_regular_file(path))
    throw std::runtime_error(flag + " " + path + ": no such map file");
  TargetMap map = loadTargetMap(path);
  if (map.size() == 0) throw std::runtime_error(flag + " " + path + ": the map has no segments");
  return map;
}

// Nearest-rank percentile of `v` (0..100); 0 for none.
double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double rank = std::ceil(p / 100.0 * static_cast<double>(v.size()));
  const size_t i = static_cast<size_t>(std::clamp(rank, 1.0, static_cast<double>(v.size()))) - 1;
  return v[i];
}

json stats(const std::vector<double>& v) {
  const double mean =
      v.empty() ? 0.0 : std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  return {{"n", v.size()},
          {"median", percentile(v, 50)},
          {"p95", percentile(v, 95)},
          {"min", v.empty() ? 0.0 : *std::min_element(v.begin(), v.end())},
          {"max", v.empty() ? 0.0 : *std::max_element(v.begin(), v.end())},
          {"mean", mean}};
}

std::string firstLineOf(std::string s) {
  const size_t nl = s.find('\n');
  return nl == std::string::npos ? s : s.substr(0, nl);
}

std::string procField(const char* file, const std::string& key) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key, 0) == 0) {
      const size_t colon = line.find(':');
      std::string v = colon == std::string::npos ? line.substr(key.size()) : line.substr(colon + 1);
      v.erase(0, v.find_first_not_of(" \t"));
      return v;
    }
  return "";
}

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

double peakRssMb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// This process's CPU time so far (all its threads), seconds: beside a phase's wall time, it says
// how much of that the phase worked and how much it waited for the shared cores.
double cpuSeconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec) / 1e6;
}

void writeJson(const std::string& path, const json& j) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    out << j.dump(2) << "\n";
    if (!out) throw std::runtime_error(path + ": cannot write the results");
  }
  std::filesystem::rename(tmp, path);
}

// A child process that stops the server and removes its folder when this process ends, however
// it ends (the end of its pipe closes with the process, even on SIGKILL). It ignores the
// terminal's signals so that a Ctrl-C of the group leaves it to clean up.
class Watchdog {
 public:
  explicit Watchdog(PgCluster& cluster) {
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("cannot make the watchdog's pipe");
    std::fflush(nullptr);
    pid_ = ::fork();
    if (pid_ < 0) throw std::runtime_error("cannot start the watchdog process");
    if (pid_ == 0) {
      ::close(fds[1]);
      ::signal(SIGINT, SIG_IGN);
      ::signal(SIGTERM, SIG_IGN);
      ::signal(SIGHUP, SIG_IGN);
      ::signal(SIGQUIT, SIG_IGN);
      char byte;
      while (true) {
        const ssize_t n = ::read(fds[0], &byte, 1);
        if (n == 0 || (n < 0 && errno != EINTR)) break;
      }
      cluster.shutDown();
      ::_exit(0);
    }
    ::close(fds[0]);
    fd_ = fds[1];
    // Not inherited by pg_ctl, psql or the server they start, which would keep it open.
    ::fcntl(fd_, F_SETFD, FD_CLOEXEC);
  }
  ~Watchdog() {
    ::close(fd_);
    ::waitpid(pid_, nullptr, 0);
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

 private:
  pid_t pid_ = -1;
  int fd_ = -1;
};

// Written pages to disk and then out of the page cache, file by file: the server's files read
// from the disk afterwards (a cold start), without touching anyone else's cache.
size_t evictFromPageCache(const std::filesystem::path& dir) {
  size_t bytes = 0;
  for (const auto& e : std::filesystem::recursive_directory_iterator(
           dir, std::filesystem::directory_options::skip_permission_denied)) {
    if (!e.is_regular_file()) continue;
    const int fd = ::open(e.path().c_str(), O_RDONLY);
    if (fd < 0) continue;
    ::fdatasync(fd);
    if (::posix_fadvise(fd, 0, 0, POSIX_FADV_DONTNEED) == 0) bytes += e.file_size();
    ::close(fd);
  }
  return bytes;
}

// A plain connection for the bench's own SQL (sizes, VACUUM, versions).
class Sql {
 public:
  explicit Sql(const std::string& conninfo) : c_(PQconnectdb(conninfo.c_str())) {
    if (PQstatus(c_) != CONNECTION_OK)
      throw std::runtime_error("cannot connect to the bench's server: " +
                               firstLineOf(PQerrorMessage(c_)));
  }
  ~Sql() { PQfinish(c_); }
  Sql(const Sql&) = delete;
  Sql& operator=(const Sql&) = delete;
  std::string value(const std::string& sql) {
    PGresult* r = PQexec(c_, sql.c_str());
    const ExecStatusType s = PQresultStatus(r);
    std::string v;
    if (s == PGRES_TUPLES_OK && PQntuples(r) > 0) v = PQgetvalue(r, 0, 0);
    PQclear(r);
    if (s != PGRES_TUPLES_OK && s != PGRES_COMMAND_OK)
      throw std::runtime_error(sql + ": " + firstLineOf(PQerrorMessage(c_)));
    return v;
  }
  int64_t integer(const std::string& sql) { return std::stoll(value(sql)); }

 private:
  PGconn* c_;
};

// The city: tile t at column t % columns, row t / columns of a grid of `pitch` cells; a tile's
// entries are the source's moved by offset(t).
struct City {
  size_t source_size = 0, segments = 0, tiles = 0, full_tiles = 0, columns = 0, rows = 0;
  Eigen::Vector2d min = Eigen::Vector2d::Zero(), extent = Eigen::Vector2d::Zero();
  Eigen::Vector2d pitch = Eigen::Vector2d::Zero();

  Eigen::Vector3d offset(size_t t) const {
    const Eigen::Vector2d cell(static_cast<double>(t % columns) * pitch.x(),
                               static_cast<double>(t / columns) * pitch.y());
    const Eigen::Vector2d o = cell - min;
    return {o.x(), o.y(), 0.0};
  }
  size_t entriesOf(size_t t) const {
    return std::min(source_size, segments - std::min(segments, t * source_size));
  }
};

City layOut(const TargetMap& source, size_t segments, double margin_m) {
  City c;
  c.source_size = source.size();
  c.segments = segments;
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = Eigen::Vector2d::Constant(-1e300);
  for (const MapSegment& s : source.segments) {
    lo = lo.cwiseMin(s.centroid.head<2>().cast<double>());
    hi = hi.cwiseMax(s.centroid.head<2>().cast<double>());
  }
  c.min = lo;
  c.extent = hi - lo;
  c.pitch = c.extent + Eigen::Vector2d::Constant(margin_m);
  if (c.pitch.minCoeff() <= 0)
    throw std::runtime_error("the source map's segments lie on a line: no area to tile");
  c.tiles = (segments + c.source_size - 1) / c.source_size;
  c.full_tiles = segments / c.source_size;
  // Roughly square in metres.
  c.columns = std::max<size_t>(1, static_cast<size_t>(std::ceil(std::sqrt(
                                      static_cast<double>(c.tiles) * c.pitch.y() / c.pitch.x()))));
  c.rows = (c.tiles + c.columns - 1) / c.columns;
  return c;
}

// `count` entries of `source` moved by `offset`, as one session (keyframes 0: no trajectory).
NewSession tileSession(const TargetMap& source, const Eigen::Vector3d& offset, size_t count,
                       const std::string& name) {
  NewSession s;
  s.info = {name, static_cast<int64_t>(std::time(nullptr)), {}};
  const Eigen::Vector3f o = offset.cast<float>();
  s.entries.reserve(count);
  for (size_t i = 0; i < count; ++i) {
    MapSegment e = source.segments[i];
    e.centroid += o;
    for (Eigen::Vector3f& p : e.points) p += o;
    e.session = 0;
    e.keyframe = 0;
    s.entries.push_back(std::move(e));
  }
  s.descriptors = source.descriptors.topRows(static_cast<Eigen::Index>(count));
  return s;
}

// A robot's query: its local segments (centroids in its local frame, descriptors) and where it
// truly is, T_tile_local in the source map's frame, in tile `tile` of the city.
struct Query {
  size_t tile = 0;
  std::vector<Eigen::Vector3f> centroids;
  Eigen::MatrixXf descriptors;
  Pose T_tile_local = Pose::Identity();
};

std::vector<Query> makeQueries(const TargetMap& from, bool perturb, const City& city, size_t count,
                               double radius_m, std::mt19937_64& rng) {
  std::uniform_int_distribution<size_t> tile(0, city.full_tiles - 1), entry(0, from.size() - 1);
  std::uniform_real_distribution<double> yaw(-M_PI, M_PI);
  std::normal_distribution<float> noise(0.0f, 1.0f);
  // Perturbing the source's own entries: 0.1 m on the centroids, a tenth of the components' RMS
  // on the descriptors.
  const float descriptor_sigma = 0.1f * std::sqrt(from.descriptors.squaredNorm() /
                                                  static_cast<float>(from.descriptors.size()));
  std::vector<Query> out;
  for (size_t attempt = 0; out.size() < count && attempt < 100 * count; ++attempt) {
    const Eigen::Vector3f c = from.segments[entry(rng)].centroid;
    std::vector<size_t> near;
    for (size_t i = 0; i < from.size(); ++i)
      if ((from.segments[i].centroid - c).head<2>().norm() <= radius_m) near.push_back(i);
    if (near.size() < 6) continue;  // LocalizerConfig::min_local_segments
    Query q;
    q.tile = tile(rng);
    // The robot's local frame: at c, turned by a random yaw.
    Pose T_local_tile = Pose::Identity();
    T_local_tile.linear() = Eigen::AngleAxisd(yaw(rng), Eigen::Vector3d::UnitZ()).matrix();
    T_local_tile.translation() = -(T_local_tile.linear() * c.cast<double>());
    q.T_tile_local = T_local_tile.inverse();
    q.descriptors.resize(static_cast<Eigen::Index>(near.size()), from.dimension());
    for (size_t k = 0; k < near.size(); ++k) {
      Eigen::Vector3f p = from.segments[near[k]].centroid;
      Eigen::VectorXf d = from.descriptors.row(static_cast<Eigen::Index>(near[k])).transpose();
      if (perturb) {
        for (int a = 0; a < 3; ++a) p[a] += 0.1f * noise(rng);
        for (Eigen::Index a = 0; a < d.size(); ++a) d[a] += descriptor_sigma * noise(rng);
      }
      q.centroids.push_back((T_local_tile * p.cast<double>()).cast<float>());
      q.descriptors.row(static_cast<Eigen::Index>(k)) = d.transpose();
    }
    out.push_back(std::move(q));
  }
  if (out.size() < count)
    throw std::runtime_error("the query map has too few places with 6 segments within " +
                             std::to_string(radius_m) + " m");
  return out;
}

Pose translated(const Eigen::Vector3d& t, const Pose& T) {
  Pose out = T;
  out.translation() += t;
  return out;
}

// What one localizer made of the queries, each against its own truth (the query's pose in the
// localizer's map frame).
struct Tally {
  std::vector<double> localize_ms, true_candidate_share;
  size_t localized = 0, correct = 0, wrong = 0;
  size_t in_a_copy = 0;  // wrong, but within kWrongM of the true place moved by whole tiles
  json toJson(size_t queries) const {
    return {{"localize_ms", stats(localize_ms)},
            {"localized", localized},
            {"correct", correct},
            {"wrong_over_5m", wrong},
            {"wrong_in_another_tile", in_a_copy},
            {"recall", static_cast<double>(correct) / static_cast<double>(queries)},
            {"segments_with_a_true_candidate", stats(true_candidate_share)}};
  }
};

constexpr double kCorrectM = 1.0, kCorrectDeg = 5.0, kWrongM = 5.0;
// A retrieved map entry within this of a local segment's true place is a true candidate (the
// store's same_segment_m: within it, two observations are one segment).
constexpr double kTrueCandidateM = 1.5;

void tallyOne(const Localizer& localizer, const Query& q, const Pose& T_map_local,
              const Eigen::Vector2d& pitch, Tally& t) {
  const auto t0 = Clock::now();
  const std::optional<Localization> l = localizer.localize(q.centroids, q.descriptors);
  t.localize_ms.push_back(msSince(t0));
  if (l) {
    ++t.localized;
    const double dt = (l->T_map_local.translation() - T_map_local.translation()).norm();
    const double dr =
        Eigen::AngleAxisd(l->T_map_local.linear().transpose() * T_map_local.linear()).angle() *
        180.0 / M_PI;
    if (dt < kCorrectM && dr < kCorrectDeg) ++t.correct;
    if (dt > kWrongM) {
      ++t.wrong;
      const Eigen::Vector2d d =
          (l->T_map_local.translation() - T_map_local.translation()).head<2>();
      const Eigen::Vector2d tiles = d.cwiseQuotient(pitch).array().round().matrix();
      if (tiles.norm() > 0 && (d - tiles.cwiseProduct(pitch)).norm() < kWrongM) ++t.in_a_copy;
    }
  }
  // Retrieval alone: does any of a local segment's k nearest descriptors lie where it truly is?
  const Neighbours nn = localizer.index().search(q.descriptors);
  size_t hit = 0;
  for (size_t s = 0; s < q.centroids.size(); ++s) {
    const Eigen::Vector3f truth = (T_map_local * q.centroids[s].cast<double>()).cast<float>();
    for (int j = 0; j < nn.k; ++j) {
      const int64_t id = nn.id(s, j);
      if (id < 0) break;
      if ((localizer.map().segments[static_cast<size_t>(id)].centroid - truth).norm() <=
          kTrueCandidateM) {
        ++hit;
        break;
      }
    }
  }
  t.true_candidate_share.push_back(static_cast<double>(hit) /
                                   static_cast<double>(q.centroids.size()));
}

// The whole city as one map in memory, for the file map: every tile's entries, one session each
// (when there are few enough for a map file), segment ids unique.
TargetMap cityMap(const TargetMap& source, const City& city) {
  TargetMap m;
  m.descriptor = source.descriptor;
  m.fingerprint = source.fingerprint;
  m.parameters = source.parameters;
  m.scan_contexts = ScanContextDatabase(source.scan_contexts.config());
  const bool sessions = city.tiles <= 65535;
  m.segments.reserve(city.segments);
  m.descriptors.resize(static_cast<Eigen::Index>(city.segments), source.dimension());
  Eigen::Index row = 0;
  for (size_t t = 0; t < city.tiles; ++t) {
    const size_t n = city.entriesOf(t);
    const Eigen::Vector3f o = city.offset(t).cast<float>();
    if (sessions) m.sessions.push_back({"tile-" + std::to_string(t), 0, {}});
    for (size_t i = 0; i < n; ++i) {
      MapSegment e = source.segments[i];
      e.centroid += o;
      for (Eigen::Vector3f& p : e.points) p += o;
      e.segment = static_cast<uint32_t>(t * city.source_size + i);
      e.session = sessions ? static_cast<uint16_t>(t) : 0;
      e.keyframe = 0;
      m.segments.push_back(std::move(e));
    }
    m.descriptors.middleRows(row, static_cast<Eigen::Index>(n)) =
        source.descriptors.topRows(static_cast<Eigen::Index>(n));
    row += static_cast<Eigen::Index>(n);
  }
  return m;
}

// Server settings. The build: the test server's (fsync off) with room for a bulk write. The
// measurements: durable as a fleet's server would be.
const char* const kBuildOptions =
    "-c shared_buffers=1GB -c maintenance_work_mem=1GB -c max_wal_size=8GB "
    "-c checkpoint_timeout=30min";
const char* const kMeasureOptions =
    "-c shared_buffers=1GB -c maintenance_work_mem=1GB -c max_wal_size=4GB "
    "-c fsync=on -c full_page_writes=on -c synchronous_commit=on";

// The run as the JSON's first lines: what was asked, and of what machine.
json describeRun(const Options& o) {
  json out;
  out["schema"] = "semsegmap.store-bench/1";
  out["complete"] = false;
  out["command"] = {{"segments", o.segments},
                    {"source", o.source},
                    {"queries", o.queries},
                    {"margin_m", o.margin_m},
                    {"radius_m", o.radius_m},
                    {"loads", o.loads},
                    {"inserts", o.inserts},
                    {"insert_size", o.insert_size},
                    {"localizations", o.localizations},
                    {"query_radius_m", o.query_radius_m},
                    {"seed", o.seed}};
  out["machine"] = {
      {"nproc", ::sysconf(_SC_NPROCESSORS_ONLN)},
      {"cpu", procField("/proc/cpuinfo", "model name")},
      {"memory_gb",
       std::strtod(procField("/proc/meminfo", "MemTotal").c_str(), nullptr) / 1024.0 / 1024.0},
      {"load_average_at_start", loadAverage()}};
  return out;
}

// The maps the run reads: the source, tiled over the city, and another run's map for the
// robot's queries when --queries gives one.
struct Inputs {
  TargetMap source;
  std::optional<TargetMap> query_map;
};

Inputs loadInputs(const Options& o) {
  Inputs in{loadInput("--source", o.source), std::nullopt};
  const TargetMap& source = in.source;
  if (source.size() < o.insert_size)
    throw std::runtime_error("--source " + o.source + ": " + std::to_string(source.size()) +
                             " entries, fewer than --insert-size " + std::to_string(o.insert_size));
  if (o.segments < source.size())
    throw std::runtime_error("--segments " + std::to_string(o.segments) +
                             ": fewer than one tile (the source map has " +
                             std::to_string(source.size()) + " entries)");
  if (!o.queries.empty()) {
    in.query_map = loadInput("--queries", o.queries);
    checkMapCompatible("--queries " + o.queries, *in.query_map, source.descriptor,
                       source.fingerprint, source.dimension());
  }
  return in;
}

// The source and the city laid out from it, written before anything is built.
void describeCity(const Options& o, const TargetMap& source, const City& city, json& out) {
  out["source"] = {
      {"entries", source.size()},
      {"descriptor", source.descriptor},
      {"dimension", source.dimension()},
      {"extent_m", {city.extent.x(), city.extent.y()}},
      {"entries_with_points", std::count_if(source.segments.begin(), source.segments.end(),
                                            [](const MapSegment& s) { return !s.points.empty(); })},
      {"scan_contexts", source.scan_contexts.size()}};
  out["city"] = {
      {"segments", city.segments},
      {"tiles", city.tiles},
      {"full_tiles", city.full_tiles},
      {"columns", city.columns},
      {"rows", city.rows},
      {"pitch_m", {city.pitch.x(), city.pitch.y()}},
      {"extent_m",
       {static_cast<double>(city.columns) * city.pitch.x(),
        static_cast<double>(city.rows) * city.pitch.y()}},
      {"area_km2", static_cast<double>(city.tiles) * city.pitch.x() * city.pitch.y() / 1e6}};
  writeJson(o.json, out);  // a JSON that cannot be written fails now, not after the build
  std::fprintf(stderr,
               "city: %zu segments, %zu tiles of %zu entries (%.0f x %.0f m each, %.0f m apart), "
               "%zu x %zu\n",
               city.segments, city.tiles, city.source_size, city.extent.x(), city.extent.y(),
               o.margin_m, city.columns, city.rows);
}

json describeServer(const std::string& conninfo) {
  Sql sql(conninfo);
  return {{"postgresql", sql.value("SHOW server_version")},
          {"build_options", kBuildOptions},
          {"measure_options", kMeasureOptions},
          {"test_defaults", "fsync=off synchronous_commit=off full_page_writes=off"}};
}

// A line at each whole percent of the tiles written (and at the last one), with the median of
// the last 50 tiles: the build is most of a run at 10 million segments.
void reportBuildProgress(const std::vector<double>& tile_ms, size_t tiles,
                         Clock::time_point build_t0, size_t& reported) {
  const size_t done = tile_ms.size();
  if (done != tiles && done * 100 / tiles <= reported) return;
  reported = done * 100 / tiles;
  const double s_so_far = msSince(build_t0) / 1000.0;
  const size_t from = done > 50 ? done - 50 : 0;
  std::fprintf(
      stderr, "build %3zu%%: %zu tiles, %.0f s, %.0f s left, last tiles %.0f ms\n", reported, done,
      s_so_far, s_so_far / static_cast<double>(done) * static_cast<double>(tiles - done),
      percentile(
          std::vector<double>(tile_ms.begin() + static_cast<std::ptrdiff_t>(from), tile_ms.end()),
          50));
}

// The build: the library's own writes, one transaction per tile. Each tile's time, in order.
std::vector<double> writeTiles(const TargetMap& source, const City& city, const std::string& uri,
                               const std::string& conninfo, Clock::time_point build_t0,
                               json& server) {
  std::vector<double> tile_ms;
  tile_ms.reserve(city.tiles);
  PgMapStore store(parseMapStoreUri(uri));
  Sql sql(conninfo);
  server["postgis"] = sql.value("SELECT postgis_lib_version()");
  MapSnapshot snapshot;  // the newest session: nothing lands meanwhile
  size_t reported = 0;
  for (size_t t = 0; t < city.tiles; ++t) {
    NewSession s =
        tileSession(source, city.offset(t), city.entriesOf(t), "tile-" + std::to_string(t));
    const auto t0 = Clock::now();
    if (t == 0) {
      TargetMap first;
      first.descriptor = source.descriptor;
      first.fingerprint = source.fingerprint;
      first.parameters = source.parameters;
      first.scan_contexts = ScanContextDatabase(source.scan_contexts.config());
      first.sessions = {s.info};
      first.segments = std::move(s.entries);
      first.descriptors = std::move(s.descriptors);
      store.create("city", first, s.info.name);
      snapshot.last_session = store.sessions("city").back().id;
    } else {
      snapshot.last_session = store.addSession("city", s, snapshot, 1.5).session;
    }
    tile_ms.push_back(msSince(t0));
    reportBuildProgress(tile_ms, city.tiles, build_t0, reported);
  }
  return tile_ms;
}

// The median tile time in each tenth of the build, in order.
json medianByTenth(const std::vector<double>& tile_ms) {
  json deciles = json::array();
  for (size_t d = 0; d < 10; ++d) {
    const size_t a = tile_ms.size() * d / 10, b = tile_ms.size() * (d + 1) / 10;
    if (b > a)
      deciles.push_back(
          percentile(std::vector<double>(tile_ms.begin() + static_cast<std::ptrdiff_t>(a),
                                         tile_ms.begin() + static_cast<std::ptrdiff_t>(b)),
                     50));
  }
  return deciles;
}

// The built store settled (VACUUM ANALYZE, CHECKPOINT) and measured, and its entries counted.
void settleAndMeasure(const std::string& conninfo, const City& city, json& build) {
  Sql sql(conninfo);
  auto t0 = Clock::now();
  sql.value("VACUUM ANALYZE");
  build["vacuum_analyze_s"] = msSince(t0) / 1000.0;
  t0 = Clock::now();
  sql.value("CHECKPOINT");
  build["checkpoint_s"] = msSince(t0) / 1000.0;
  build["database_bytes"] = sql.integer("SELECT pg_database_size(current_database())");
  build["segments_table_bytes"] = sql.integer("SELECT pg_table_size('semsegmap_segments')");
  build["segments_index_bytes"] = sql.integer("SELECT pg_indexes_size('semsegmap_segments')");
  build["centroid_index_bytes"] =
      sql.integer("SELECT pg_relation_size('semsegmap_segments_centroid')");
  const int64_t rows = sql.integer("SELECT count(*) FROM semsegmap_segments");
  if (rows != static_cast<int64_t>(city.segments))
    throw std::runtime_error("the store holds " + std::to_string(rows) + " entries, not " +
                             std::to_string(city.segments));
}

void buildCity(const Options& o, const TargetMap& source, const City& city, const std::string& uri,
               const std::string& conninfo, json& out) {
  const auto build_t0 = Clock::now();
  const std::vector<double> tile_ms =
      writeTiles(source, city, uri, conninfo, build_t0, out["server"]);
  const double build_s = msSince(build_t0) / 1000.0;
  out["build"] = {{"seconds", build_s},
                  {"path", "PgMapStore::create, then PgMapStore::addSession per tile"},
                  {"tile_ms", stats(tile_ms)},
                  {"tile_ms_median_by_tenth", medianByTenth(tile_ms)}};
  settleAndMeasure(conninfo, city, out["build"]);
  writeJson(o.json, out);
  std::fprintf(stderr, "built in %.0f s; %.2f GB\n", build_s,
               out["build"]["database_bytes"].get<double>() / 1e9);
}

// Cold: the server restarted durable, its files out of the page cache. The store's connection
// is made here, timed on its own: the loads after it are timed without it.
std::unique_ptr<PgMapStore> restartCold(PgCluster& cluster, const std::string& uri,
                                        json& region_load) {
  size_t evicted = 0;
  if (!cluster.restart(kMeasureOptions, [&] { evicted = evictFromPageCache(cluster.dataDir()); }))
    throw std::runtime_error("the bench's server did not restart (" + cluster.serverLog() + ")");
  region_load["evicted_bytes"] = evicted;
  const auto t0 = Clock::now();
  auto store = std::make_unique<PgMapStore>(parseMapStoreUri(uri));
  region_load["connect_ms"] = msSince(t0);
  return store;
}

// `count` places uniform over the city's full tiles.
std::vector<Eigen::Vector2d> randomPlaces(const City& city, size_t count, std::mt19937_64& rng) {
  std::uniform_int_distribution<size_t> any_tile(0, city.full_tiles - 1);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Eigen::Vector2d> places;
  for (size_t i = 0; i < count; ++i) {
    const Eigen::Vector3d cell =
        city.offset(any_tile(rng)) + Eigen::Vector3d(city.min.x(), city.min.y(), 0);
    places.emplace_back(cell.x() + unit(rng) * city.pitch.x(),
                        cell.y() + unit(rng) * city.pitch.y());
  }
  return places;
}

// The region of `radius` around each place loaded once: each load's time; each region's entries
// and sessions go to `entries` and `sessions`.
std::vector<double> loadRegions(PgMapStore& from, const std::vector<Eigen::Vector2d>& places,
                                double radius, std::vector<double>& entries,
                                std::vector<double>& sessions) {
  std::vector<double> ms;
  for (const Eigen::Vector2d& p : places) {
    const auto l0 = Clock::now();
    const TargetMap m = from.load("city", MapRegion{p.x(), p.y(), radius});
    ms.push_back(msSince(l0));
    entries.push_back(static_cast<double>(m.size()));
    sessions.push_back(static_cast<double>(m.sessions.size()));
  }
  return ms;
}

// The same places, warm (a second pass), at the radius and at larger discs: the one
// circumscribing the 200 m square (a superset of the square's entries) and three times the
// radius (the docs' example); each also through a connection with PostgreSQL's parallel query
// off (a libpq option in the URI): a plan with a parallel worker pays for starting it.
json loadsByRadius(PgMapStore& store, const std::string& uri,
                   const std::vector<Eigen::Vector2d>& places, double radius_m,
                   const std::vector<double>& warm, const std::vector<double>& entries) {
  PgMapStore serial(parseMapStoreUri(uri + "&options=-c%20max_parallel_workers_per_gather%3D0"));
  std::vector<double> unused_e, unused_s;
  json radii = json::array();
  for (const double radius : {radius_m, radius_m * std::sqrt(2.0), 3.0 * radius_m}) {
    std::vector<double> ms = warm, e = entries, s;
    if (radius != radius_m) {
      loadRegions(store, places, radius, unused_e, unused_s);  // the first pass: partly cold
      e.clear();
      ms = loadRegions(store, places, radius, e, s);
    }
    const std::vector<double> serial_ms = loadRegions(serial, places, radius, unused_e, unused_s);
    radii.push_back({{"radius_m", radius},
                     {"warm_ms", stats(ms)},
                     {"warm_ms_without_parallel_query", stats(serial_ms)},
                     {"entries", stats(e)}});
  }
  return radii;
}

void measureRegionLoads(const Options& o, PgMapStore& store, const std::string& uri,
                        const std::vector<Eigen::Vector2d>& places, json& out) {
  std::vector<double> entries, sessions, unused_e, unused_s;
  const std::vector<double> cold = loadRegions(store, places, o.radius_m, entries, sessions);
  const std::vector<double> warm = loadRegions(store, places, o.radius_m, unused_e, unused_s);
  out["region_load"].update({{"radius_m", o.radius_m},
                             {"places", places.size()},
                             {"cold_ms", stats(cold)},
                             {"warm_ms", stats(warm)},
                             {"entries", stats(entries)},
                             {"sessions", stats(sessions)}});
  out["region_load"]["radii"] = loadsByRadius(store, uri, places, o.radius_m, warm, entries);
  writeJson(o.json, out);
  std::fprintf(stderr,
               "region load (%.0f m): cold median %.1f ms, warm median %.1f ms, %.0f entries\n",
               o.radius_m, percentile(cold, 50), percentile(warm, 50), percentile(entries, 50));
}

// Inserts: new sessions at new places (the grid's next cells), then dropped again.
json insertSessions(const Options& o, PgMapStore& store, const TargetMap& source, const City& city,
                    const std::string& conninfo) {
  Sql sql(conninfo);
  MapSnapshot snapshot;
  snapshot.last_session = sql.integer("SELECT max(id) FROM semsegmap_sessions");
  std::vector<double> insert_ms, drop_ms;
  std::vector<int64_t> written;
  for (size_t i = 0; i < o.inserts; ++i) {
    const NewSession s = tileSession(source, city.offset(city.tiles + i), o.insert_size,
                                     "insert-" + std::to_string(i));
    const auto i0 = Clock::now();
    const SessionWrite w = store.addSession("city", s, snapshot, 1.5);
    insert_ms.push_back(msSince(i0));
    snapshot.last_session = w.session;
    written.push_back(w.session);
  }
  for (int64_t id : written) {
    const auto d0 = Clock::now();
    store.dropSession("city", id);
    drop_ms.push_back(msSince(d0));
  }
  std::fprintf(stderr, "insert of %zu entries: median %.0f ms\n", o.insert_size,
               percentile(insert_ms, 50));
  return {{"entries", o.insert_size},
          {"ms", stats(insert_ms)},
          {"each_ms", insert_ms},
          {"drop_session_ms", stats(drop_ms)}};
}

// Each query against the region loaded around its true place: the load, the index and the
// localization timed for each query.
json localizeInRegions(PgMapStore& store, const std::vector<Query>& queries, const City& city,
                       const LocalizerConfig& config, double radius_m) {
  Tally tally;
  std::vector<double> load_ms, index_ms, total_ms, entries_loaded;
  for (const Query& q : queries) {
    const Pose T_city_local = translated(city.offset(q.tile), q.T_tile_local);
    const Eigen::Vector3d at = T_city_local.translation();
    const auto q0 = Clock::now();
    auto region =
        std::make_shared<const TargetMap>(store.load("city", MapRegion{at.x(), at.y(), radius_m}));
    load_ms.push_back(msSince(q0));
    entries_loaded.push_back(static_cast<double>(region->size()));
    const auto b0 = Clock::now();
    const Localizer localizer(region, config);
    index_ms.push_back(msSince(b0));
    tallyOne(localizer, q, T_city_local, city.pitch, tally);
    total_ms.push_back(load_ms.back() + index_ms.back() + tally.localize_ms.back());
  }
  json region = tally.toJson(queries.size());
  region.update({{"load_ms", stats(load_ms)},
                 {"index_ms", stats(index_ms)},
                 {"total_ms", stats(total_ms)},
                 {"entries", stats(entries_loaded)}});
  return region;
}

// The queries against the source map alone, in its own frame: no look-alike tiles.
json localizeInSource(const TargetMap& source, const std::vector<Query>& queries, const City& city,
                      const LocalizerConfig& config) {
  Tally tally;
  const Localizer localizer(std::make_shared<const TargetMap>(source), config);
  for (const Query& q : queries) tallyOne(localizer, q, q.T_tile_local, city.pitch, tally);
  return tally.toJson(queries.size());
}

// The queries against the region around each and against the source alone; the whole city's
// file map comes after, once the store is closed.
void localizeAgainstRegions(const Options& o, const Inputs& in, const City& city, PgMapStore& store,
                            const std::vector<Query>& queries, const LocalizerConfig& config,
                            json& out) {
  std::vector<double> local_segments;
  for (const Query& q : queries) local_segments.push_back(static_cast<double>(q.centroids.size()));
  json loc = {
      {"queries_from", in.query_map ? "another run's map (--queries), segments within the query "
                                      "radius of one of its entries"
                                    : "the source's own entries, perturbed"},
      {"queries", queries.size()},
      {"local_segments", stats(local_segments)},
      {"k", config.index.k},
      {"correct_within", {{"m", kCorrectM}, {"deg", kCorrectDeg}}},
      {"true_candidate_within_m", kTrueCandidateM}};
  loc["region"] = localizeInRegions(store, queries, city, config, o.radius_m);
  loc["single_tile"] = localizeInSource(in.source, queries, city, config);
  out["localization"] = loc;
  writeJson(o.json, out);
  std::fprintf(stderr, "localization against the region: recall %.2f\n",
               loc["region"]["recall"].get<double>());
}

// The whole city assembled in memory and saved as a map file, each timed; the copy in memory is
// gone before the file is loaded back.
json saveCityMap(const TargetMap& source, const City& city, const std::filesystem::path& file) {
  json f;
  auto c0 = Clock::now();
  const TargetMap whole = cityMap(source, city);
  f["assemble_s"] = msSince(c0) / 1000.0;
  c0 = Clock::now();
  f["bytes"] = saveTargetMap(file, whole);
  f["save_s"] = msSince(c0) / 1000.0;
  return f;
}

// The same queries against a file map of the whole city (saveTargetMap, loaded and indexed
// once, each timed apart).
void localizeInFileMap(const Options& o, const std::filesystem::path& file, const TargetMap& source,
                       const City& city, const std::vector<Query>& queries,
                       const LocalizerConfig& config, json& out) {
  json f = saveCityMap(source, city, file);
  auto c0 = Clock::now();
  auto whole = std::make_shared<const TargetMap>(loadTargetMap(file));
  f["load_s"] = msSince(c0) / 1000.0;
  c0 = Clock::now();
  const double cpu0 = cpuSeconds();
  const Localizer localizer(whole, config);
  f["index_s"] = msSince(c0) / 1000.0;
  f["index_cpu_s"] = cpuSeconds() - cpu0;
  f["index_lists"] = localizer.index().lists();
  Tally tally;
  for (const Query& q : queries)
    tallyOne(localizer, q, translated(city.offset(q.tile), q.T_tile_local), city.pitch, tally);
  f.update(tally.toJson(queries.size()));
  out["localization"]["file"] = f;
  std::filesystem::remove(file);
  writeJson(o.json, out);
  std::fprintf(stderr, "localization against the file map: recall %.2f\n",
               f["recall"].get<double>());
}

// The whole map loaded from the store (what `map --into` on a store does first).
void loadWholeCity(const Options& o, const std::string& uri, json& out) {
  PgMapStore whole_store(parseMapStoreUri(uri));
  const auto t0 = Clock::now();
  const TargetMap whole = whole_store.load("city");
  out["whole_load"] = {{"seconds", msSince(t0) / 1000.0},
                       {"entries", whole.size()},
                       {"sessions", whole.sessions.size()}};
  writeJson(o.json, out);
}

void finish(const Options& o, Clock::time_point started, json& out) {
  out["peak_rss_mb"] = peakRssMb();
  out["seconds"] = msSince(started) / 1000.0;
  out["machine"]["load_average_at_end"] = loadAverage();
  out["complete"] = true;
  writeJson(o.json, out);
  std::fprintf(stderr, "done in %.0f s: %s\n", msSince(started) / 1000.0, o.json.c_str());
}

int run(const Options& o) {
  const auto started = Clock::now();
  json out = describeRun(o);
  const Inputs in = loadInputs(o);
  const City city = layOut(in.source, o.segments, o.margin_m);
  describeCity(o, in.source, city, out);

  PgCluster cluster(kBuildOptions);
  if (!cluster.problem().empty())
    throw std::runtime_error("the bench's PostgreSQL server: " + cluster.problem());
  Watchdog watchdog(cluster);
  const std::string uri = cluster.uri("city");
  const std::string conninfo = parseMapStoreUri(cluster.uri(), false).conninfo;
  out["server"] = describeServer(conninfo);
  buildCity(o, in.source, city, uri, conninfo, out);

  std::unique_ptr<PgMapStore> store = restartCold(cluster, uri, out["region_load"]);
  std::mt19937_64 rng(o.seed);
  measureRegionLoads(o, *store, uri, randomPlaces(city, o.loads, rng), out);
  out["insert"] = insertSessions(o, *store, in.source, city, conninfo);
  writeJson(o.json, out);

  // Localization: the same queries against the region, the source alone and the whole city.
  // They draw from the generator after the places did: one seed gives both.
  const bool perturb = !in.query_map;
  const std::vector<Query> queries = makeQueries(in.query_map ? *in.query_map : in.source, perturb,
                                                 city, o.localizations, o.query_radius_m, rng);
  const LocalizerConfig config;  // k 16, resolution 0.4 m, 6 inliers: config/semsegmap.yaml's
  localizeAgainstRegions(o, in, city, *store, queries, config, out);
  store.reset();

  if (o.file_map)
    localizeInFileMap(o, cluster.socketDir() + "/city.map", in.source, city, queries, config, out);
  if (o.whole_load) loadWholeCity(o, uri, out);
  finish(o, started, out);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const UsageError& e) {
    std::fprintf(stderr, "semsegmap_store_bench: %s (--help says how)\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "semsegmap_store_bench: %s\n", firstLineOf(e.what()).c_str());
    return 1;
  }
}
