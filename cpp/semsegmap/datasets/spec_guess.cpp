#include "semsegmap/datasets/spec_guess.h"

#include <algorithm>
#include <cctype>
#include <vector>

namespace semsegmap {

namespace fs = std::filesystem;

namespace {

// A folder with thousands of entries (scans) is not listed whole: a dataset's marks are
// sub-folders and a few named files, found among the first entries or by name.
constexpr size_t kMaxListed = 200;

std::string extensionOf(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

bool isDir(const fs::path& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

bool isFile(const fs::path& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// The first entries of `dir` in name order, so that a guess names the same one every time.
std::vector<fs::path> firstEntries(const fs::path& dir) {
  std::vector<fs::path> entries;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end && entries.size() < kMaxListed;
       it.increment(ec))
    entries.push_back(it->path());
  std::sort(entries.begin(), entries.end());
  return entries;
}

bool isScan(const fs::path& path) {
  const std::string ext = extensionOf(path);
  return (ext == ".pcd" || ext == ".ply" || ext == ".bin") && isFile(path);
}

std::optional<SpecGuess> bagFile(const fs::path& path) {
  const std::string ext = extensionOf(path);
  if (ext == ".bag") return SpecGuess{"rosbag:" + path.string(), "a ROS 1 bag"};
  if (ext == ".db3") return SpecGuess{"rosbag:" + path.string(), "a ROS 2 bag (sqlite3)"};
  if (ext == ".mcap") return SpecGuess{"rosbag:" + path.string(), "a ROS 2 bag (MCAP)"};
  return std::nullopt;
}

// A folder that is one dataset of a known kind by its own entries.
std::optional<SpecGuess> knownFolder(const fs::path& dir) {
  const std::string d = dir.string();
  if (isDir(dir / "velodyne_points" / "data"))
    return SpecGuess{"kitti-raw:" + d, "a KITTI raw drive"};
  if (isDir(dir / "velodyne_sync")) return SpecGuess{"nclt:" + d, "an NCLT session"};
  if (isDir(dir / "velodyne"))
    return SpecGuess{"semantickitti:" + d, "a SemanticKITTI or KITTI odometry sequence"};
  if (isFile(dir / "metadata.yaml"))
    for (const fs::path& entry : firstEntries(dir))
      if (const auto bag = bagFile(entry); bag && bag->what != "a ROS 1 bag")
        return SpecGuess{"rosbag:" + d, "a ROS 2 bag folder"};
  return std::nullopt;
}

// A folder above datasets, up to two levels: a KITTI raw date folder or the download's root
// above it, SemanticKITTI's root or its sequences/, a folder of bags. The first one found in name
// order is named; `budget` bounds the folders looked into.
std::optional<SpecGuess> folderAbove(const fs::path& dir, int levels, size_t& budget) {
  const fs::path sequences = isDir(dir / "sequences") ? dir / "sequences" : dir;
  for (const fs::path& entry : firstEntries(sequences)) {
    if (const auto bag = bagFile(entry); bag && isFile(entry))
      return SpecGuess{bag->spec, "a folder holding " + bag->what};
    if (!isDir(entry) || budget == 0) continue;
    --budget;
    if (const auto inner = knownFolder(entry))
      return SpecGuess{inner->spec, "a folder holding " + inner->what};
    if (levels > 1)
      if (auto deeper = folderAbove(entry, levels - 1, budget)) return deeper;
  }
  return std::nullopt;
}

std::optional<SpecGuess> guessFile(const fs::path& path) {
  if (auto bag = bagFile(path)) return bag;
  const std::string name = path.filename().string();
  fs::path folder = path.parent_path();
  if (folder.empty()) folder = ".";
  if (name == "meta.yaml")
    return SpecGuess{folder.string(), "the meta.yaml of a dataset directory"};
  if (name == "rig.yaml") return SpecGuess{"folder:" + folder.string(), "a rig file"};
  if (!isScan(path)) return std::nullopt;
  // A scan of a known dataset lies in its scan folder: SEQUENCE/velodyne/000000.bin,
  // DRIVE/velodyne_points/data/0000000000.bin, SESSION/velodyne_sync/N.bin.
  const std::string scans = folder.filename().string();
  if (scans == "velodyne" || scans == "velodyne_sync" || scans == "data")
    for (const fs::path& up : {folder.parent_path(), folder.parent_path().parent_path()})
      if (const auto dataset = knownFolder(up))
        return SpecGuess{dataset->spec, "a scan of " + dataset->what};
  return SpecGuess{"folder:" + folder.string(), "a scan"};
}

bool hasScans(const fs::path& dir) {
  const std::vector<fs::path> entries = firstEntries(dir);
  return std::any_of(entries.begin(), entries.end(), [](const fs::path& e) { return isScan(e); });
}

}  // namespace

std::optional<SpecGuess> guessDatasetSpec(const fs::path& path) {
  if (isFile(path)) return guessFile(path);
  if (!isDir(path)) return std::nullopt;
  if (auto known = knownFolder(path)) return known;
  if (hasScans(path)) return std::nullopt;  // read as folder:DIR
  size_t budget = 50;
  return folderAbove(path, 2, budget);
}

}  // namespace semsegmap
