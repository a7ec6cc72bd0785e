// A throwaway PostgreSQL server for the map store's tests: initdb into a temporary folder, the
// server on a Unix socket in it (no TCP port to collide with), stopped and removed afterwards.
// As root (CI) the server runs as the unprivileged `postgres` user, which Debian's postgresql
// package creates: PostgreSQL refuses to run as root. The binaries are those of Debian's
// postgresql-15 (scripts/setup.sh); a machine without them fails the test, saying so. The
// benchmark of the store (bench/bench_map_store.cpp) starts its server the same way, with extra
// server settings (`extra_options`: more `-c name=value`, after the defaults, so they override
// them) and restarts it with others between its phases.
#pragma once

#include <pwd.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>

namespace semsegmap::test_support {

class PgCluster {
 public:
  // `extra_options`: server options appended to the defaults, e.g. "-c shared_buffers=1GB".
  explicit PgCluster(std::string extra_options = "") {
    bin_ = findBin();
    if (bin_.empty()) return;
    char pattern[] = "/tmp/ssm-pg-XXXXXX";  // short: a socket path has at most 107 bytes
    dir_ = ::mkdtemp(pattern);
    as_ = ::geteuid() == 0 ? "runuser -u postgres -- " : "";
    if (!as_.empty()) {
      const passwd* pw = ::getpwnam("postgres");
      if (!pw || ::chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) {
        error_ = "running as root needs the postgres user (Debian's postgresql package)";
        return;
      }
    }
    // The server's log is its own file: one the shell made as root it could not write.
    const std::string data = dir_ + "/data", log = dir_ + "/server.log";
    if (!sh(as_ + bin_ + "/initdb -D " + data + " -U semsegmap --auth=trust --no-sync -E UTF8 > " +
            dir_ + "/initdb.log 2>&1")) {
      error_ = "initdb failed (" + dir_ + "/initdb.log)";
      return;
    }
    if (!start(extra_options) ||
        !sh(as_ + bin_ + "/createdb -h " + dir_ + " -U semsegmap semsegmap_test")) {
      error_ = "the server did not start (" + log + ")";
      return;
    }
  }
  ~PgCluster() { shutDown(); }
  // Stops the server and removes its folder (unless SEMSEGMAP_KEEP_PG is set); again, nothing.
  void shutDown() {
    if (started_)
      sh(as_ + bin_ + "/pg_ctl -D " + dir_ + "/data -m immediate -w stop > /dev/null 2>&1");
    started_ = false;
    if (!dir_.empty() && !::getenv("SEMSEGMAP_KEEP_PG")) {
      std::error_code ignored;
      std::filesystem::remove_all(dir_, ignored);
    }
  }
  // Stops the server (cleanly: what was written stays), runs `while_stopped`, and starts it
  // again with the defaults and `extra_options`; false when it does not come back.
  bool restart(const std::string& extra_options, const std::function<void()>& while_stopped = {}) {
    if (!started_) return false;
    if (!sh(as_ + bin_ + "/pg_ctl -D " + dir_ + "/data -m fast -w -t 300 stop > /dev/null 2>&1"))
      return false;
    started_ = false;
    if (while_stopped) while_stopped();
    return start(extra_options);
  }
  PgCluster(const PgCluster&) = delete;
  PgCluster& operator=(const PgCluster&) = delete;

  // Empty when the server runs, else why not.
  std::string problem() const {
    if (bin_.empty())
      return "no PostgreSQL server binaries under /usr/lib/postgresql (scripts/setup.sh "
             "installs postgresql and postgresql-15-postgis-3)";
    if (!error_.empty()) return error_;
    return started_ ? "" : "the server is not running (" + serverLog() + ")";
  }
  // The store's URI, with ?map=NAME when given.
  std::string uri(const std::string& map = "", const std::string& database = "semsegmap_test",
                  const std::string& user = "semsegmap") const {
    return "postgresql:///" + database + "?host=" + dir_ + "&user=" + user +
           (map.empty() ? "" : "&map=" + map);
  }
  // Runs psql as the superuser on `database`; true when it succeeded.
  bool psql(const std::string& sql, const std::string& database = "semsegmap_test") const {
    return sh(bin_ + "/psql -q -X -v ON_ERROR_STOP=1 -h " + dir_ + " -U semsegmap -d " + database +
              " -c \"" + sql + "\" > /dev/null 2>&1");
  }
  const std::string& socketDir() const { return dir_; }
  std::string dataDir() const { return dir_ + "/data"; }
  std::string serverLog() const { return dir_ + "/server.log"; }

 private:
  // fsync off: a test server loses nothing it must keep. Later `-c` settings override earlier.
  bool start(const std::string& extra_options) {
    started_ = sh(as_ + bin_ + "/pg_ctl -D " + dir_ + "/data -l " + dir_ + "/server.log" +
                  " -w -t 60 -o \"-k " + dir_ +
                  " -c listen_addresses='' -c fsync=off -c synchronous_commit=off "
                  "-c full_page_writes=off " +
                  extra_options + "\" start > /dev/null 2>&1");
    return started_;
  }
  static std::string findBin() {
    for (const char* v : {"17", "16", "15"}) {
      const std::string bin = std::string("/usr/lib/postgresql/") + v + "/bin";
      if (std::filesystem::exists(bin + "/initdb")) return bin;
    }
    return {};
  }
  static bool sh(const std::string& command) { return std::system(command.c_str()) == 0; }
  std::string bin_, dir_, as_, error_;
  bool started_ = false;
};

}  // namespace semsegmap::test_support
