#include "semsegmap/core/atomic_file.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace semsegmap {
namespace fs = std::filesystem;

namespace {

// Beside the target so that the rename stays on one file system (and so is atomic); hidden and
// unique per process and call, so that concurrent writers never share a temporary.
fs::path temporaryPathFor(const fs::path& path) {
  static std::atomic<unsigned long> counter{0};
  std::ostringstream name;
  name << '.' << path.filename().string() << ".tmp-" << ::getpid() << '-' << counter++;
  return path.parent_path() / name.str();
}

// Absolute, without "." and ".." or a trailing separator: how scopes and files are compared.
fs::path normalizedPath(const fs::path& path) {
  fs::path p = fs::absolute(path).lexically_normal();
  if (p.filename().empty() && p.has_relative_path()) p = p.parent_path();
  return p;
}

// The scope itself, or a path below it: how many levels down, or -1 outside it.
int depthBelow(const fs::path& path, const fs::path& scope) {
  const fs::path rel = path.lexically_relative(scope);
  if (rel.empty() || *rel.begin() == "..") return -1;
  if (rel == ".") return 0;
  return static_cast<int>(std::distance(rel.begin(), rel.end()));
}

struct Watch {
  size_t id;
  fs::path scope;
  std::function<void(const fs::path&)> observer;
};

// The watches alive; observers are called with the mutex held, so that a watch that is being
// removed waits for a call in progress and is never called after its destructor returned.
struct WatchRegistry {
  std::mutex mutex;
  std::vector<Watch> watches;
  size_t next_id = 0;
};
WatchRegistry& watchRegistry() {
  static WatchRegistry registry;
  return registry;
}

// After the rename: `existed` is whether `path` was there before it. The nearest scope wins.
void reportNewFile(const fs::path& path, bool existed) {
  if (existed) return;
  WatchRegistry& r = watchRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  if (r.watches.empty()) return;
  const fs::path full = normalizedPath(path);
  int nearest = std::numeric_limits<int>::max();
  for (const Watch& w : r.watches) {
    const int depth = depthBelow(full, w.scope);
    if (depth >= 0) nearest = std::min(nearest, depth);
  }
  for (const Watch& w : r.watches)
    if (depthBelow(full, w.scope) == nearest) w.observer(full);
}

void removeQuietly(const fs::path& path) {
  std::error_code ignored;
  fs::remove(path, ignored);
}

}  // namespace

// No fsync: the guarantee is against the process dying (crash, Ctrl-C, full disk), which the
// rename covers; syncing every frame file would make dataset conversion disk-latency bound.
void writeFileAtomically(const fs::path& path, const std::function<void(std::ostream&)>& write) {
  const fs::path tmp = temporaryPathFor(path);
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out)
      throw std::runtime_error(path.string() + ": cannot create temporary file " + tmp.string() +
                               " (" + std::strerror(errno) + ")");
    write(out);
    out.flush();
    out.close();
    // Checked after close because a full disk often only shows when the last buffer is written.
    if (!out) throw std::runtime_error(path.string() + ": write failed (disk full?)");
    std::error_code ec;
    const bool existed = fs::exists(path, ec);
    fs::rename(tmp, path, ec);
    if (ec)
      throw std::runtime_error(path.string() + ": cannot rename temporary file into place (" +
                               ec.message() + ")");
    reportNewFile(path, existed);
  } catch (...) {
    // The callback's own exception is passed on unchanged: it knows best what went wrong.
    removeQuietly(tmp);
    throw;
  }
}

NewFileWatch::NewFileWatch(const fs::path& scope, std::function<void(const fs::path&)> observer) {
  WatchRegistry& r = watchRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  id_ = r.next_id++;
  r.watches.push_back({id_, normalizedPath(scope), std::move(observer)});
}

NewFileWatch::~NewFileWatch() {
  WatchRegistry& r = watchRegistry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.watches.erase(std::remove_if(r.watches.begin(), r.watches.end(),
                                 [this](const Watch& w) { return w.id == id_; }),
                  r.watches.end());
}

void writeBytesAtomically(const fs::path& path, const std::string& bytes) {
  writeFileAtomically(path, [&bytes](std::ostream& out) {
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
}

std::string readFileBytes(const fs::path& path) {
  std::error_code ec;
  // A directory opens fine as a stream on Linux and then reads as empty; say what it is instead.
  if (fs::is_directory(path, ec))
    throw std::runtime_error(path.string() + ": is a directory, expected a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  // Sized up front: scans are megabytes and are read once per frame.
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0, std::ios::beg);
  if (size < 0) throw std::runtime_error(path.string() + ": cannot determine its size");
  std::string bytes(static_cast<size_t>(size), '\0');
  in.read(bytes.data(), size);
  if (in.gcount() != size) throw std::runtime_error(path.string() + ": read failed");
  return bytes;
}

}  // namespace semsegmap
