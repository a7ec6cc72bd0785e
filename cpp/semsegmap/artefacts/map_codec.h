// The pieces of a saved target map as bytes, shared by the map file (map_file.h) and the map
// store (store/pg_map_store.h), so that a map reads back the same from either: descriptors and
// picture points as float16, poses as float64 position and float32 quaternion, the scan contexts
// as a block. The readers fail through BinaryReader: "<source>: <what is wrong>".
#pragma once

#include <cstdint>
#include <string>

#include "semsegmap/core/binary_io.h"
#include "semsegmap/core/pose.h"
#include "semsegmap/localize/scan_context.h"
#include "semsegmap/localize/target_map.h"

namespace semsegmap {

void putHalf(BinaryWriter& w, float v);
float getHalf(BinaryReader& r, const char* field);

// A pose as float64 x, y, z and a float32 unit quaternion w, x, y, z (40 bytes).
constexpr size_t kPoseBytes = 40;
void putPose(BinaryWriter& w, const Pose& T);
// `what` names the pose in the error ("scan context 3").
Pose getPose(BinaryReader& r, const std::string& what);

// The grid, then per scan its frame and its bins as float16.
void putScanContexts(BinaryWriter& w, const ScanContextDatabase& db);
ScanContextDatabase getScanContexts(BinaryReader& r);

// A segment's picture points as float16 offsets from its centroid (6 bytes a point): float16
// keeps centimetres within tens of metres. Throws std::invalid_argument beyond 65535 points.
void putPoints(BinaryWriter& w, const MapSegment& s);
// `count` points around `s.centroid` into s.points.
void getPoints(BinaryReader& r, size_t count, MapSegment& s);

// What a saver refuses because the loaders refuse it, so that a saved map always reads back: a
// descriptor count other than the segment count, a non-finite centroid, descriptor or point, a
// segment of a session the map has not or a keyframe beyond its session's trajectory. Empty when
// the map is fine, else the first problem ("segment 3: non-finite centroid").
std::string firstUnsavable(const TargetMap& map);
// The checks of firstUnsavable a loader makes once the map is read (all but the count).
std::string firstNonFinite(const TargetMap& map);
std::string firstOutOfSession(const TargetMap& map);

}  // namespace semsegmap
