// A throwaway PostgreSQL server for the map store's tests: initdb into a temporary folder, the
// server on a Unix socket in it (no TCP port to collide with), stopped and removed afterwards.
// As root (CI) the server runs as the unprivileged `postgres` user, which Debian's postgresql
// package creates: PostgreSQL refuses to run as root. The binaries are those of Debian's
// postgresql-15 (scripts/setup.sh); a machine without them fails the test, saying so. The
// benchmark of the store (bench/) starts its server the same way.
#pragma once

#include <pwd.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace semsegmap::test_support {

class PgCluster {
 public:
  PgCluster() {
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
    // fsync off: a test server loses nothing it must keep.
    if (!sh(as_ + bin_ + "/pg_ctl -D " + data + " -l " + log + " -w -t 60 -o \"-k " + dir_ +
            " -c listen_addresses='' -c fsync=off -c synchronous_commit=off "
            "-c full_page_writes=off\" start > /dev/null 2>&1") ||
        !sh(as_ + bin_ + "/createdb -h " + dir_ + " -U semsegmap semsegmap_test")) {
      error_ = "the server did not start (" + log + ")";
      return;
    }
    started_ = true;
  }
  ~PgCluster() {
    if (started_)
      sh(as_ + bin_ + "/pg_ctl -D " + dir_ + "/data -m immediate -w stop > /dev/null 2>&1");
    if (!dir_.empty() && !::getenv("SEMSEGMAP_KEEP_PG")) {
      std::error_code ignored;
      std::filesystem::remove_all(dir_, ignored);
    }
  }
  PgCluster(const PgCluster&) = delete;
  PgCluster& operator=(const PgCluster&) = delete;

  // Empty when the server runs, else why not.
  std::string problem() const {
    if (bin_.empty())
      return "no PostgreSQL server binaries under /usr/lib/postgresql (scripts/setup.sh "
             "installs postgresql and postgresql-15-postgis-3)";
    return started_ ? "" : error_;
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

 private:
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
