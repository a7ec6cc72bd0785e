// A folder of a robot's own recordings as a FrameSource (`--dataset folder:DIR`): scans as .pcd,
// .ply or KITTI .bin files, camera pictures as .png or .jpg, the rig from a rig file
// (docs/rig-format.md). Scans and pictures are paired by the times in their file names, a times
// file, or equal file names. Scans named by frame numbers (000042.bin) keep them: pose files in
// KITTI format refer to them (datasets/pose_files.h).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/io/rig_file.h"

namespace semsegmap {

struct FolderOptions {
  // The rig file; empty: DIR/rig.yaml when it exists, else a LiDAR-only rig whose base is the
  // LiDAR (said on stderr).
  std::filesystem::path rig;
  // One time in seconds per line, one line per scan in file-name order; empty: DIR/times.txt
  // when it exists, else the times in the scans' file names.
  std::filesystem::path times;
  // How far apart a scan and a picture may be to be paired; <= 0: half the LiDAR period.
  double tolerance_s = 0.0;
};

// `folder:DIR[,rig=FILE][,times=FILE][,tolerance=SECONDS]` -> DIR and its options; throws
// std::invalid_argument naming the spec and the key.
std::filesystem::path parseFolderSpec(const std::string& spec, const std::string& args,
                                      FolderOptions& options);

// A picture by its extension: .png, .jpg or .jpeg, in any case.
bool isPictureFile(const std::filesystem::path& path);
// A file name's stem as a time in seconds: "1650000000.123456" (seconds), or an integer of
// nanoseconds (>= 18 digits), microseconds (15-17), milliseconds (12-14) or seconds (>= 1e8).
// Nothing for small integers (frame numbers such as 000042) and for other names.
std::optional<double> timeFromFileName(const std::string& stem);
// A file name's stem as a frame number: digits only and no time by timeFromFileName (000042 is
// 42). Nothing for times and other names.
std::optional<size_t> frameNumberFromFileName(const std::string& stem);

// The rig of a recording folder: options.rig, else DIR/rig.yaml (its path in `rig_path`), else a
// LiDAR alone at 10 Hz whose base is the LiDAR (said on stderr; `rig_path` empty). Throws
// std::runtime_error when DIR is no folder or the rig file is refused.
RigFile readFolderRig(const std::filesystem::path& dir, const FolderOptions& options,
                      std::filesystem::path& rig_path);
// The dataset's name: the rig file's, else "folder:" and the folder's name.
std::string folderName(const std::filesystem::path& dir, const RigFile& rig);

class FolderReader : public FrameSource {
 public:
  // Lists the scans and pictures, reads the rig and the first picture of every camera (its size
  // must be the rig's), pairs pictures with scans. Throws std::runtime_error naming the file.
  FolderReader(const std::filesystem::path& dir, const FolderOptions& options);
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return scans_.size(); }
  Frame frame(size_t index) override;
  double frameTime(size_t index) override { return times_.at(index); }
  // When every scan is named by a frame number: that number (KITTI pose lines refer to it).
  std::optional<size_t> frameNumber(size_t index) override;

 private:
  void pairPictures(size_t camera, const std::filesystem::path& folder);
  void madeUpTimes(const std::filesystem::path& lidar_dir);
  void describeOrigin(const std::filesystem::path& rig, const std::filesystem::path& lidar_dir,
                      const std::filesystem::path& times);

  std::filesystem::path dir_;
  DatasetInfo info_;
  std::vector<std::filesystem::path> scans_;
  std::vector<double> times_;
  std::vector<size_t> numbers_;  // the scans' frame numbers; empty unless all names are numbers
  double tolerance_s_ = 0.05;
  // pictures_[camera][scan]: the picture paired with the scan, empty when none was near.
  std::vector<std::vector<std::filesystem::path>> pictures_;
};

}  // namespace semsegmap
