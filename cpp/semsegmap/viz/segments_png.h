// Bird's-eye picture of segments: the final observation of each segment, each in its own colour,
// over the trajectory that produced them.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "semsegmap/core/pose.h"
#include "semsegmap/segment/segment.h"

namespace semsegmap::viz {

// A colour per segment id, stable across runs and far from its neighbours' (golden-ratio hues).
void segmentColor(SegmentId id, uint8_t& r, uint8_t& g, uint8_t& b);

void writeSegmentsPng(const std::filesystem::path& png, const std::vector<Segment>& segments,
                      const std::vector<Pose>& trajectory, const std::string& title,
                      double metres_per_pixel = 0.2);

}  // namespace semsegmap::viz
