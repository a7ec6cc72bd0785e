// A dataset whose odometry comes from its own LiDAR scans (odometry/lidar_odometry.h): for data
// that has scans and no poses, or poses worse than a scan-matcher's.
#pragma once

#include <memory>

#include "semsegmap/core/frame_source.h"
#include "semsegmap/odometry/lidar_odometry.h"

namespace semsegmap {

// Frames of `source` with T_odom_base from LiDAR odometry (the base's pose, from the LiDAR's
// through the rig's T_base_lidar; the odometry frame is the base at frame 0), and
// info().has_odometry true. Registration runs in frame order: asking for frame i registers every
// frame up to i that has not been registered yet; an earlier frame is read again and gets its
// stored pose.
std::unique_ptr<FrameSource> withLidarOdometry(std::unique_ptr<FrameSource> source,
                                               const OdometryConfig& config);

}  // namespace semsegmap
