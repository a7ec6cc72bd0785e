#include "semsegmap/io/folder_follower.h"

#include <algorithm>
#include <optional>
#include <stdexcept>

#include "semsegmap/io/point_cloud_file.h"
#include "semsegmap/io/rig_file.h"

namespace semsegmap {

namespace fs = std::filesystem;

namespace {

// A name a driver writes to before renaming the file into place.
bool stillBeingWritten(const fs::path& p) {
  const std::string name = p.filename().string();
  const std::string ext = p.extension().string();
  return name.empty() || name[0] == '.' || ext == ".tmp" || ext == ".part";
}

// The files of `folder` that `keep` accepts and that were not seen before, sorted by name.
std::vector<fs::path> newFiles(const fs::path& folder, bool (*keep)(const fs::path&),
                               std::set<fs::path>& seen) {
  std::vector<fs::path> out;
  if (!fs::exists(folder)) return out;  // the driver has not begun to write there
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder, error)) {
    const fs::path& p = entry.path();
    if (!entry.is_regular_file() || stillBeingWritten(p) || !keep(p)) continue;
    if (seen.insert(p).second) out.push_back(p);
  }
  if (error) throw std::runtime_error(folder.string() + ": " + error.message());
  std::sort(out.begin(), out.end());
  return out;
}

double timeOfName(const fs::path& p) {
  const std::optional<double> t = timeFromFileName(p.stem().string());
  if (!t)
    throw std::runtime_error(p.string() +
                             ": following a folder needs each file's time in its name "
                             "(seconds such as 1650000000.123456, or nanoseconds)");
  return *t;
}

}  // namespace

FolderFollower::FolderFollower(const fs::path& dir, const FolderOptions& options) {
  fs::path rig_path;
  const RigFile rig = readFolderRig(dir, options, rig_path);
  info_.name = folderName(dir, rig);
  info_.rig = rig.rig;
  info_.classes = ClassTable::Default();
  info_.has_frame_times = true;
  lidar_dir_ = rig.lidar_folder.empty() ? dir : dir / rig.lidar_folder;
  for (const std::string& folder : rig.camera_folders) camera_dirs_.push_back(dir / folder);
  info_.origin.kind =
      "folder followed as it grows" +
      (rig_path.empty() ? std::string(", no rig file") : ", rig " + rig_path.string());
  info_.origin.lidar = (lidar_dir_ / "*").string() + ", times from the names";
}

void FolderFollower::poll(std::vector<FollowedScan>& scans,
                          std::vector<FollowedPicture>& pictures) {
  for (const fs::path& p : newFiles(lidar_dir_, &isPointCloudFile, seen_))
    scans.push_back({timeOfName(p), p});
  for (size_t c = 0; c < camera_dirs_.size(); ++c)
    for (const fs::path& p : newFiles(camera_dirs_[c], &isPictureFile, seen_))
      pictures.push_back({c, timeOfName(p), p});
  const auto byTime = [](const auto& a, const auto& b) { return a.stamp_s < b.stamp_s; };
  std::stable_sort(scans.begin(), scans.end(), byTime);
  std::stable_sort(pictures.begin(), pictures.end(), byTime);
}

}  // namespace semsegmap
