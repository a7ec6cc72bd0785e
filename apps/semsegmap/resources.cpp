#include "resources.h"

#include <stdexcept>
#include <system_error>

namespace semsegmap::app {

namespace fs = std::filesystem;

namespace {

bool holdsData(const fs::path& dir) {
  std::error_code ignored;
  return fs::is_regular_file(dir / "config" / "semsegmap.yaml", ignored);
}

}  // namespace

fs::path dataDir() {
  static const fs::path found = [] {
    std::error_code error;
    const fs::path exe = fs::read_symlink("/proc/self/exe", error);
    const fs::path installed = exe.parent_path().parent_path() / "share" / "semsegmap";
    if (!error && holdsData(installed)) return installed;
    const fs::path source = SEMSEGMAP_SOURCE_DIR;
    if (holdsData(source)) return source;
    throw std::runtime_error("cannot find semsegmap's configs and models: neither " +
                             installed.string() + " nor " + source.string() +
                             " holds config/semsegmap.yaml (reinstall, or pass the files)");
  }();
  return found;
}

fs::path shippedFile(const std::string& relative) {
  return dataDir() / relative;
}

}  // namespace semsegmap::app
