// Writing segmentation results: segments.csv (one row per segment, its final observation) and
// the final observations' points as PLY with a segment id per point.
#pragma once

#include <filesystem>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/segment/segment.h"

namespace semsegmap {

// Columns: id, observations, points, centroid_x/y/z, class, first_frame, last_frame,
// gt_instance, gt_purity (the last two empty without ground truth). Atomic write.
void writeSegmentsCsv(const std::filesystem::path& path, const std::vector<Segment>& segments,
                      const ClassTable& classes, bool has_ground_truth);

// Binary little-endian PLY: x y z float, red green blue uchar, class ushort, segment int.
void writeSegmentPointsPly(const std::filesystem::path& path, const std::vector<Segment>& segments);

}  // namespace semsegmap
