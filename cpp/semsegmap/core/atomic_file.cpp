#include "semsegmap/core/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <system_error>

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

std::mutex& observerMutex() {
  static std::mutex m;
  return m;
}
std::function<void(const fs::path&)>& newFileObserver() {
  static std::function<void(const fs::path&)> observer;
  return observer;
}

// After the rename: `existed` is whether `path` was there before it.
void reportNewFile(const fs::path& path, bool existed) {
  if (existed) return;
  const std::lock_guard<std::mutex> lock(observerMutex());
  if (newFileObserver()) newFileObserver()(path);
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

void setNewFileObserver(std::function<void(const fs::path&)> observer) {
  const std::lock_guard<std::mutex> lock(observerMutex());
  newFileObserver() = std::move(observer);
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
