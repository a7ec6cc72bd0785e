// What a --dataset given without a kind (`--dataset run.bag`) probably is, so that the error can
// say what to write instead: a bag file wants `rosbag:`, a KITTI raw drive `kitti-raw:`. Only
// cheap looks: the path's extension, and the names of a folder's entries two levels down.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

namespace semsegmap {

struct SpecGuess {
  std::string
      spec;  // what to write: "rosbag:run.bag", "kitti-raw:drive/2011_09_26_drive_0001_sync"
  std::string what;  // what the path looks like: "a ROS 1 bag", "a KITTI raw drive"
};

// For a file: a bag (rosbag:FILE), a scan or a rig file (folder: of its folder), a dataset's
// meta.yaml (its folder). For a folder without meta.yaml: a ROS 2 bag folder, a KITTI raw drive
// (or a date folder holding one), an NCLT session, a SemanticKITTI sequence (or the dataset's
// root holding sequences/), a folder holding a bag. Nothing when it looks like none of these; a
// folder of scans is none of these either (it is read as folder:DIR).
std::optional<SpecGuess> guessDatasetSpec(const std::filesystem::path& path);

}  // namespace semsegmap
