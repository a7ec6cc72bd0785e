// Writing segmentation results: segments.csv (one row per segment, its final observation) and
// the final observations' points as PLY with a segment id per point.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <vector>

#include "semsegmap/core/class_table.h"
#include "semsegmap/segment/segment.h"

namespace semsegmap {

// Columns: id, observations, points, centroid_x/y/z, class, first_frame, last_frame (the run's
// frame indices), first_dataset_frame, last_dataset_frame (the dataset's own numbers of those
// frames, `frame_numbers[index]`; empty where it has none), gt_instance, gt_purity (empty
// without ground truth). Atomic write.
void writeSegmentsCsv(const std::filesystem::path& path, const std::vector<Segment>& segments,
                      const ClassTable& classes, bool has_ground_truth,
                      const std::vector<std::optional<size_t>>& frame_numbers = {});

// Binary little-endian PLY: x y z float, red green blue uchar, class ushort, segment int.
void writeSegmentPointsPly(const std::filesystem::path& path, const std::vector<Segment>& segments);

}  // namespace semsegmap
