// 2-D polylines: the streets, the lanes the vehicle and the agents follow.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace semsegmap::sim {

using Polyline = std::vector<Eigen::Vector2d>;

// Parallel polyline at signed distance `offset` to the left of the travel direction (negative:
// right), corners joined by mitres. A closed polyline is given without repeating its first point.
Polyline offsetPolyline(const Polyline& p, double offset, bool closed);
// Replaces each interior corner by a quadratic Bezier arc that starts and ends `cut_m` from the
// corner (at most a third of the adjacent segments), sampled every `step_m`.
Polyline roundCorners(const Polyline& p, double cut_m, double step_m);
double polylineLength(const Polyline& p, bool closed);

struct PolylinePoint {
  Eigen::Vector2d position;
  double heading;  // radians, direction of travel
};
// Point at arc length s (clamped for open polylines, wrapped for closed ones).
PolylinePoint pointAt(const Polyline& p, double s, bool closed);

// Shortest distance from q to the segment [a, b].
double distanceToSegment(const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                         const Eigen::Vector2d& b);

}  // namespace semsegmap::sim
