// How complete an observation of a segment is, estimated at run time without ground truth: from
// the segment's own growth. A segment the robot is still uncovering gains points from frame to
// frame; one it has seen from every side it passes stops growing. So the share of its points the
// segment already had a window of frames before an observation says how much of it the sensor
// had seen by then: near 0 while it is being uncovered, near 1 once it has stopped growing.
#pragma once

#include <cstddef>
#include <vector>

namespace semsegmap {

struct ObservationSize {
  size_t frame_index = 0;
  size_t n_points = 0;
};

// Per observation (in the order taken): max over observations j <= k of
// n(frame_j - window_frames) / n_j, where n(f) is the points of the last observation taken at or
// before frame f (0 before the first). The running maximum makes the estimate monotone over a
// segment's observations, as the true completeness of a growing segment is: once the segment has
// held still for a window, a later spurt (a merge, a far side coming into view) does not make
// what was seen before less complete. A first observation, or one a window after nothing, is 0.
std::vector<double> estimateCompleteness(const std::vector<ObservationSize>& observations,
                                         size_t window_frames);

}  // namespace semsegmap
