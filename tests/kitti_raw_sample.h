// The real KITTI raw sample beside the checkout (../shared/data: ten synced frames of 2011-09-26,
// one front camera on an HDL-64E) and the configuration of a robot's own rig that runs it, for
// the tests that map it end to end. A test skips when the sample is absent.
#pragma once

#include <filesystem>
#include <string>

#include "build_options.h"
#include "semsegmap/settings/config.h"

namespace semsegmap::test_support {

inline std::filesystem::path kittiRawSampleRun() {
  return std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti_raw_2011_09_26_sample" /
         "2011_09_26" / "sample_sync";
}

// config/lidar-camera.yaml, with the eigenvalue descriptor when the build has no libtorch.
inline PipelineConfig realRigConfig() {
  PipelineConfig config =
      loadPipelineConfig(std::string(SEMSEGMAP_SOURCE_DIR) + "/config/lidar-camera.yaml");
  if (!SEMSEGMAP_WITH_TORCH) config.descriptor = DescriptorConfig{"eigen", "", 64, ""};
  return config;
}

}  // namespace semsegmap::test_support

#define SEMSEGMAP_SKIP_WITHOUT_KITTI_RAW_SAMPLE()                             \
  if (!std::filesystem::exists(semsegmap::test_support::kittiRawSampleRun())) \
  GTEST_SKIP() << "the real KITTI sample is absent ("                         \
               << semsegmap::test_support::kittiRawSampleRun().string() << ")"
