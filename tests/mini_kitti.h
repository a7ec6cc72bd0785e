// ../shared/data/mini_kitti (real KITTI odometry frames with image_2 and SemanticKITTI labels)
// as a sequence folder the reader takes. Its calib.txt has P0..P3 but not Tr, which the official
// calib.txt files have; a scratch sequence folder links the sample's files and writes calib.txt
// with the sample's lines and KITTI odometry's Tr of sequences 04-10 (recording day 2011-09-30,
// both sequences of the sample). The shared data is only read.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace semsegmap::test_support {

inline const std::filesystem::path kMiniKitti =
    std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "mini_kitti" / "sequences";

// Velodyne -> rectified camera 0 of KITTI odometry sequences 04-10, as their calib.txt has it.
constexpr const char* kKittiTr0930 =
    "Tr: -1.857739385241e-03 -9.999659513510e-01 -8.039975204516e-03 -4.784029760483e-03 "
    "-6.481465826011e-03 8.051860151134e-03 -9.999466081774e-01 -7.337429464231e-02 "
    "9.999773098287e-01 -1.805528627661e-03 -6.496203536139e-03 -3.339968064433e-01\n";

inline bool haveMiniKitti() {
  return std::filesystem::exists(kMiniKitti / "05" / "calib.txt");
}

// ROOT/<sequence>: links to the sample's velodyne, image_2, labels, poses.txt and times.txt, and
// a calib.txt with Tr. Returns the folder.
inline std::filesystem::path miniKittiSequence(const std::filesystem::path& root,
                                               const std::string& sequence) {
  namespace fs = std::filesystem;
  const fs::path from = kMiniKitti / sequence, to = root / sequence;
  fs::create_directories(to);
  for (const char* dir : {"velodyne", "image_2", "labels"})
    fs::create_directory_symlink(from / dir, to / dir);
  for (const char* file : {"poses.txt", "times.txt"}) fs::create_symlink(from / file, to / file);
  std::ifstream in(from / "calib.txt");
  std::ofstream out(to / "calib.txt");
  out << in.rdbuf() << kKittiTr0930;
  return to;
}

// ../shared's ESPNetv2 (Cityscapes, 20 output channels: the 19 training ids and background).
inline const std::filesystem::path kEspNet = std::filesystem::path(SEMSEGMAP_SHARED_DATA) /
                                             "espnetv2_cityscapes_onnx" /
                                             "espnetv2_s2_city_384x1280.onnx";

// DIR/espnet.yaml: the shipped real-data settings (`config_dir`/lidar-camera.yaml up to its
// descriptor) with a semantics: section that runs ESPNetv2; its class map is the shipped
// Cityscapes one plus the background channel, which is no class of ours.
inline std::filesystem::path writeEspNetConfig(const std::filesystem::path& dir,
                                               const std::filesystem::path& config_dir) {
  std::ifstream map_in(config_dir / "class_maps" / "cityscapes.yaml");
  std::ofstream(dir / "espnet-classes.yaml")
      << map_in.rdbuf() << "  - {id: 19, name: background, class: unknown}\n";
  std::ifstream config_in(config_dir / "lidar-camera.yaml");
  const std::string settings((std::istreambuf_iterator<char>(config_in)),
                             std::istreambuf_iterator<char>());
  std::ofstream(dir / "espnet.yaml") << settings.substr(0, settings.find("descriptor:"))
                                     << "semantics:\n  model: " << kEspNet.string()
                                     << "\n  class_map: espnet-classes.yaml\n"
                                        "  input_width: 1280\n  input_height: 384\n";
  return dir / "espnet.yaml";
}

}  // namespace semsegmap::test_support

#define SEMSEGMAP_SKIP_WITHOUT_MINI_KITTI()                    \
  if (!semsegmap::test_support::haveMiniKitti())               \
  GTEST_SKIP() << "the real mini KITTI sample is absent ("     \
               << semsegmap::test_support::kMiniKitti.string() \
               << "): ../shared/data is not beside this checkout"
