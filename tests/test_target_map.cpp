// Target maps: building (duplicates), the saved file (round trip, float16, truncation, bit
// flips, other versions) and the compatibility check against the running describer.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/binary_io.h"
#include "semsegmap/localize/localizer.h"
#include "semsegmap/localize/target_map.h"
#include "semsegmap/pipeline/map_parameters.h"

namespace semsegmap {
namespace {

std::filesystem::path tempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "semsegmap_test_target_map";
  std::filesystem::create_directories(dir);
  return dir / name;
}

TargetMap randomMap(size_t n, int dim, bool points, uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.0f, 1.0f);
  TargetMap map;
  map.descriptor = "semsegmap-net";
  map.fingerprint = "0123456789abcdef";
  map.descriptors.resize(static_cast<Eigen::Index>(n), dim);
  for (size_t i = 0; i < n; ++i) {
    MapSegment s;
    s.centroid = Eigen::Vector3f(100 * g(rng), 100 * g(rng), g(rng));
    s.n_points = 100 + static_cast<uint32_t>(i);
    s.majority_class = static_cast<ClassId>(i % 20);
    if (points)
      for (int k = 0; k < 10; ++k)
        s.points.push_back(s.centroid + Eigen::Vector3f(g(rng), g(rng), g(rng)));
    map.segments.push_back(s);
    for (int k = 0; k < dim; ++k) map.descriptors(static_cast<Eigen::Index>(i), k) = g(rng);
  }
  return map;
}

std::string expectLoadError(const std::filesystem::path& path) {
  try {
    loadTargetMap(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "loading " << path << " did not fail";
  return "";
}

TEST(MapFile, RoundTripIsExactUpToFloat16) {
  const TargetMap map = randomMap(500, 64, true);
  const auto path = tempPath("roundtrip.map");
  const uint64_t bytes = saveTargetMap(path, map);
  EXPECT_EQ(bytes, std::filesystem::file_size(path));
  const TargetMap back = loadTargetMap(path);
  EXPECT_EQ(back.descriptor, map.descriptor);
  EXPECT_EQ(back.fingerprint, map.fingerprint);
  ASSERT_EQ(back.size(), map.size());
  ASSERT_EQ(back.dimension(), 64);
  for (size_t i = 0; i < map.size(); ++i) {
    EXPECT_EQ(back.segments[i].centroid, map.segments[i].centroid);  // float32: exact
    EXPECT_EQ(back.segments[i].n_points, map.segments[i].n_points);
    EXPECT_EQ(back.segments[i].majority_class, map.segments[i].majority_class);
    ASSERT_EQ(back.segments[i].points.size(), 10u);
    EXPECT_LT((back.segments[i].points[3] - map.segments[i].points[3]).norm(), 0.01f);
  }
  // float16 keeps 11 significant bits: relative error at most 2^-11.
  const Eigen::MatrixXf diff = (back.descriptors - map.descriptors).cwiseAbs();
  const Eigen::MatrixXf bound = map.descriptors.cwiseAbs() * (1.0f / 2048.0f);
  EXPECT_TRUE((diff.array() <= bound.array() + 1e-7f).all());
  EXPECT_GT(diff.maxCoeff(), 0.0f);  // it really is float16

  MapWriteOptions f32;
  f32.float16 = false;
  saveTargetMap(path, map, f32);
  EXPECT_EQ(loadTargetMap(path).descriptors, map.descriptors);
}

void resign(std::string& bytes) {
  const uint64_t sum = fnv1a64(bytes.data(), bytes.size() - 8, kProjectFnvSeed);
  std::memcpy(&bytes[bytes.size() - 8], &sum, sizeof(sum));
}

// A map's scan contexts (target_map.scan_context_apart_m) come back with their frames and their
// bins to float16, compare as they did, and a corrupt grid or pose is refused naming the file.
TEST(MapFile, ScanContextsRoundTripAndACorruptOneIsRefused) {
  TargetMap map = randomMap(20, 16, true);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> height(0.0f, 12.0f);
  for (int i = 0; i < 3; ++i) {
    Eigen::MatrixXf bins(20, 60);
    for (Eigen::Index k = 0; k < bins.size(); ++k) bins(k) = k % 3 == 0 ? 0.0f : height(rng);
    const Pose T = Eigen::Translation3d(1000.0 + i, -2.5 * i, 0.3) *
                   Eigen::AngleAxisd(0.4 * i, Eigen::Vector3d::UnitZ());
    map.scan_contexts.add(scanContextOfBins(bins), T);
  }
  const auto path = tempPath("scan_contexts.map");
  saveTargetMap(path, map);
  const TargetMap back = loadTargetMap(path);
  ASSERT_EQ(back.scan_contexts.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    const auto& a = map.scan_contexts.scans()[i];
    const auto& b = back.scan_contexts.scans()[i];
    EXPECT_LT((a.T_world_scan.translation() - b.T_world_scan.translation()).norm(), 1e-9);
    EXPECT_LT(rotationErrorDeg(a.T_world_scan, b.T_world_scan), 1e-3);
    EXPECT_LT((a.context.bins - b.context.bins).cwiseAbs().maxCoeff(), 0.01f);
    EXPECT_EQ(a.context.ring_key, b.context.ring_key);
    EXPECT_NEAR(scanContextDistance(b.context, a.context).distance, 0.0, 1e-6);
  }
  // The first scan's first rotation value (the quaternion's w), made 2: not a rotation.
  std::string bytes = readFileBytes(path);
  const size_t grid = bytes.size() - 8 - 3 * (24 + 16 + 2 * 20 * 60) - 8 - 12;
  float w = 0.0f;
  std::memcpy(&w, &bytes[grid + 12 + 8 + 24], sizeof(w));
  ASSERT_NEAR(w, 1.0f, 1e-6f) << "the layout docs/map-format.md gives";
  w = 2.0f;
  std::memcpy(&bytes[grid + 12 + 8 + 24], &w, sizeof(w));
  resign(bytes);
  writeBytesAtomically(path, bytes);
  const std::string error = expectLoadError(path);
  EXPECT_NE(error.find(path.string() + ": scan context 0: not a pose"), std::string::npos) << error;
  EXPECT_EQ(randomMap(20, 16, false).scan_contexts.size(), 0u);
}

// A map merged from sessions (pipeline/session_merge.h) keeps each entry's segment id, session
// and keyframe and each session's name, time and trajectory; a segment naming a session the map
// does not hold is refused naming the file. A map of one run reads as each entry its own segment.
TEST(MapFile, SessionsRoundTripAndASegmentOfNoSessionIsRefused) {
  TargetMap map = randomMap(12, 16, false);
  const auto path = tempPath("sessions.map");
  saveTargetMap(path, map);
  const TargetMap single = loadTargetMap(path);
  EXPECT_TRUE(single.sessions.empty());
  for (size_t i = 0; i < single.size(); ++i) EXPECT_EQ(single.segments[i].segment, i);

  map.sessions.push_back({"first", 0, {}});
  MapSession second{"sim:world=1,run=S1", 1796000000, {}};
  for (int k = 0; k < 4; ++k)
    second.trajectory.push_back(Eigen::Translation3d(10.0 * k, 1.0, 0.0) *
                                Eigen::AngleAxisd(0.1 * k, Eigen::Vector3d::UnitZ()));
  map.sessions.push_back(second);
  for (size_t i = 0; i < map.size(); ++i) {
    map.segments[i].segment = static_cast<uint32_t>(i % 8);  // 8 segments, 4 seen twice
    map.segments[i].session = i < 8 ? 0 : 1;
    map.segments[i].keyframe = i < 8 ? 0 : static_cast<uint32_t>(i - 8);
  }
  saveTargetMap(path, map);
  const TargetMap back = loadTargetMap(path);
  ASSERT_EQ(back.sessions.size(), 2u);
  EXPECT_EQ(back.sessions[1].name, second.name);
  EXPECT_EQ(back.sessions[1].merged_unix_s, second.merged_unix_s);
  ASSERT_EQ(back.sessions[1].trajectory.size(), 4u);
  EXPECT_LT(translationError(back.sessions[1].trajectory[3], second.trajectory[3]), 1e-9);
  EXPECT_LT(rotationErrorDeg(back.sessions[1].trajectory[3], second.trajectory[3]), 1e-3);
  for (size_t i = 0; i < map.size(); ++i) {
    EXPECT_EQ(back.segments[i].segment, map.segments[i].segment);
    EXPECT_EQ(back.segments[i].session, map.segments[i].session);
    EXPECT_EQ(back.segments[i].keyframe, map.segments[i].keyframe);
  }

  // Saving refuses what loading would: a keyframe beyond its session's trajectory.
  TargetMap bad = map;
  bad.segments[11].keyframe = 4;
  EXPECT_THROW(saveTargetMap(tempPath("bad_sessions.map"), bad), std::invalid_argument);
  // The last segment's session (after its uint32 segment id, before the checksum), made 7.
  std::string bytes = readFileBytes(path);
  const size_t at = bytes.size() - 8 - 10 + 4;
  uint16_t session = 0;
  std::memcpy(&session, &bytes[at], sizeof(session));
  ASSERT_EQ(session, 1u) << "the layout docs/map-format.md gives";
  session = 7;
  std::memcpy(&bytes[at], &session, sizeof(session));
  resign(bytes);
  writeBytesAtomically(path, bytes);
  const std::string error = expectLoadError(path);
  EXPECT_NE(error.find(path.string() + ": segment 11: session 7 of 2"), std::string::npos) << error;
}

TEST(MapFile, SizeIsAtMost150BytesASegmentWith64dDescriptors) {
  const TargetMap map = randomMap(10000, 64, false);
  const auto path = tempPath("size.map");
  const uint64_t bytes = saveTargetMap(path, map);
  EXPECT_LE(static_cast<double>(bytes) / 10000.0, 150.0);
}

TEST(MapFile, TruncatedOrCorruptFilesAreRejectedNamingTheFile) {
  const auto path = tempPath("good.map");
  saveTargetMap(path, randomMap(50, 16, false));
  const std::string good = readFileBytes(path);

  const auto truncated = tempPath("truncated.map");
  writeBytesAtomically(truncated, good.substr(0, good.size() - 100));
  std::string error = expectLoadError(truncated);
  EXPECT_NE(error.find(truncated.string()), std::string::npos) << error;

  // Every single flipped bit in the body is caught (checksum or header check).
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    std::string bad = good;
    const size_t at = std::uniform_int_distribution<size_t>(0, bad.size() - 1)(rng);
    bad[at] = static_cast<char>(bad[at] ^ (1 << (trial % 8)));
    const auto flipped = tempPath("flipped.map");
    writeBytesAtomically(flipped, bad);
    error = expectLoadError(flipped);
    EXPECT_NE(error.find(flipped.string()), std::string::npos) << error;
  }

  const auto empty = tempPath("empty.map");
  writeBytesAtomically(empty, "");
  EXPECT_NE(expectLoadError(empty).find("not a semsegmap map"), std::string::npos);
  EXPECT_NE(expectLoadError(tempPath("missing.map")).find("missing.map"), std::string::npos);
}

TEST(MapFile, AnotherFormatVersionIsRejectedWithItsNumber) {
  const auto path = tempPath("version.map");
  saveTargetMap(path, randomMap(5, 8, false));
  std::string bytes = readFileBytes(path);
  const uint32_t other = kMapFormatVersion + 1;
  std::memcpy(&bytes[8], &other, sizeof(other));
  // Re-sign, so that only the version is wrong.
  const uint64_t sum = fnv1a64(bytes.data(), bytes.size() - 8, kProjectFnvSeed);
  std::memcpy(&bytes[bytes.size() - 8], &sum, sizeof(sum));
  writeBytesAtomically(path, bytes);
  const std::string error = expectLoadError(path);
  EXPECT_NE(error.find("version " + std::to_string(other)), std::string::npos) << error;
}

// Re-signs `bytes` after a patch, so that only the patched value is wrong.

TEST(MapFile, Version1IsRefusedAskingToRebuild) {
  const auto path = tempPath("version1.map");
  saveTargetMap(path, randomMap(5, 8, false));
  std::string bytes = readFileBytes(path);
  const uint32_t one = 1;
  std::memcpy(&bytes[8], &one, sizeof(one));
  writeBytesAtomically(path, bytes);
  const std::string error = expectLoadError(path);
  EXPECT_EQ(error.rfind(path.string() + ": map format version 1", 0), 0u) << error;
  EXPECT_NE(error.find("rebuild the map with `semsegmap map`"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
}

TEST(MapFile, RecordsTheSettingsItWasBuiltWith) {
  TargetMap map = randomMap(20, 8, true);
  PipelineConfig config;
  config.segmentation.d_segment_m = 0.25;
  map.parameters = mapParametersOf(config);
  const auto path = tempPath("parameters.map");
  const uint64_t with = saveTargetMap(path, map);
  const TargetMap back = loadTargetMap(path);
  EXPECT_EQ(back.parameters, map.parameters);
  EXPECT_TRUE(mapParameterDifferences(back.parameters, mapParametersOf(config)).empty());
  TargetMap bare = map;
  bare.parameters.clear();
  EXPECT_LT(with - saveTargetMap(path, bare), 1200u) << "the settings stay small";
  EXPECT_TRUE(loadTargetMap(path).parameters.empty());
}

// The file offset of the first segment of a map with these strings and no parameters.
size_t firstSegmentOffset(const TargetMap& map) {
  return 8 + 4 + 4 + 1 + map.descriptor.size() + 1 + map.fingerprint.size() + 4 + 2 + 8;
}

// A NaN centroid, descriptor or point used to load and localize with exit 0 and "mean error
// 0.00 m"; saving refuses it too, so the file here is patched by hand.
TEST(MapFile, NonFiniteValuesAreRefusedNamingTheSegment) {
  const TargetMap map = randomMap(4, 8, true);
  const auto path = tempPath("finite.map");
  EXPECT_NO_THROW(saveTargetMap(path, map));
  MapWriteOptions f32;
  f32.float16 = false;
  saveTargetMap(path, map, f32);
  const std::string good = readFileBytes(path);
  const size_t segment = 12 + 4 + 2 + 8 * 4;
  const size_t second = firstSegmentOffset(map) + segment;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  auto patched = [&](size_t at, const void* value, size_t size) {
    std::string bytes = good;
    std::memcpy(&bytes[at], value, size);
    resign(bytes);
    writeBytesAtomically(path, bytes);
    return expectLoadError(path);
  };
  EXPECT_EQ(patched(second + 4, &nan, 4), path.string() + ": segment 1: non-finite centroid");
  EXPECT_EQ(patched(second + 18 + 12, &inf, 4),
            path.string() + ": segment 1: non-finite descriptor");
  const uint16_t half_inf = 0x7c00;  // the points are float16 offsets: count, then x y z
  EXPECT_EQ(patched(firstSegmentOffset(map) + 4 * segment + 2 + 2, &half_inf, 2),
            path.string() + ": segment 0: non-finite point");

  TargetMap bad = map;
  bad.descriptors(2, 3) = nan;
  try {
    saveTargetMap(path, bad);
    ADD_FAILURE() << "a NaN descriptor was saved";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), path.string() + ": segment 2: non-finite descriptor");
  }
}

TEST(MapParameters, DifferencesNameTheKeyAndBothValues) {
  PipelineConfig built, running;
  running.segmentation.d_segment_m = 0.5;
  running.local_map.voxel_size_m = 0.2;
  const auto d = mapParameterDifferences(mapParametersOf(built), mapParametersOf(running));
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].key, "local_map.voxel_size_m");
  EXPECT_EQ(d[0].map_value, "0.1");
  EXPECT_EQ(d[0].config_value, "0.2");
  EXPECT_EQ(describeDifference("m.map", d[1]),
            "m.map: segmentation.d_segment_m: the map was built with 0.3, the configuration has "
            "0.5");
  // A key the map lacks (an older build recorded fewer) or has extra is a difference too.
  MapParameters fewer = mapParametersOf(built);
  fewer.pop_back();
  fewer.emplace_back("segmentation.future_key", "1");
  const auto e = mapParameterDifferences(fewer, mapParametersOf(built));
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].map_value, "(none)");
  EXPECT_EQ(e[1].key, "segmentation.future_key");
  EXPECT_EQ(e[1].config_value, "(none)");
  EXPECT_TRUE(mapParameterDifferences({}, {}).empty());
}

TEST(MapParameters, TheBuilderRecordsThem) {
  TargetMapBuilder builder("eigen", "x", 2);
  PipelineConfig config;
  builder.setParameters(mapParametersOf(config));
  builder.add(MapSegment{}, Eigen::Vector2f(1, 0));
  const TargetMap map = builder.build();
  EXPECT_EQ(map.parameters, mapParametersOf(config));
  EXPECT_GE(map.parameters.size(), 20u);
}

TEST(MapFile, CompatibilityNamesWhatDiffers) {
  const TargetMap map = randomMap(3, 64, false);
  EXPECT_NO_THROW(checkMapCompatible("m.map", map, "semsegmap-net", "0123456789abcdef", 64));
  auto message = [&](const std::string& kind, const std::string& fp, int dim) {
    try {
      checkMapCompatible("m.map", map, kind, fp, dim);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("segmap-cnn", "0123456789abcdef", 64).find("segmap-cnn"), std::string::npos);
  EXPECT_NE(message("semsegmap-net", "ffffffffffffffff", 64).find("model"), std::string::npos);
  EXPECT_NE(message("semsegmap-net", "0123456789abcdef", 32).find("dimension"), std::string::npos);
}

TEST(TargetMapBuilder, ANewerSegmentReplacesADuplicateAtTheSamePlace) {
  TargetMapBuilderConfig config;
  config.duplicate_distance_m = 0.5;
  TargetMapBuilder builder("eigen", "x", 2, config);
  MapSegment a, b, c;
  a.centroid = {0, 0, 0};
  b.centroid = {10, 0, 0};
  c.centroid = {0.3f, 0, 0};  // the first one again
  builder.add(a, Eigen::Vector2f(1, 1));
  builder.add(b, Eigen::Vector2f(2, 2));
  builder.add(c, Eigen::Vector2f(3, 3));
  const TargetMap map = builder.build();
  EXPECT_EQ(builder.duplicatesRemoved(), 1u);
  ASSERT_EQ(map.size(), 2u);
  EXPECT_EQ(map.segments[0].centroid, b.centroid);
  EXPECT_EQ(map.segments[1].centroid, c.centroid);
  EXPECT_EQ(map.descriptors(1, 0), 3.0f);
  EXPECT_THROW(builder.add(a, Eigen::Vector3f(1, 1, 1)), std::invalid_argument);
}

}  // namespace
// ---- The localizer's map: shared when saved, its own when it grows ------------------------------

// A query of `n` map segments seen from a robot 3 m east and 1 m north of the map origin.
std::vector<Eigen::Vector3f> shiftedCentroids(const TargetMap& map, size_t n) {
  std::vector<Eigen::Vector3f> local;
  for (size_t i = 0; i < n; ++i)
    local.push_back(map.segments[i].centroid - Eigen::Vector3f(3, 1, 0));
  return local;
}

TEST(Localizer, AMapGrownSegmentBySegmentLocalizesAsTheWholeMap) {
  const TargetMap whole = randomMap(300, 16, false);
  const Localizer built(whole, LocalizerConfig{});
  TargetMap empty = whole;
  empty.segments.clear();
  empty.descriptors.resize(0, 16);
  Localizer grown(empty, LocalizerConfig{});
  for (size_t start = 0; start < whole.size(); start += 70) {
    const size_t n = std::min<size_t>(70, whole.size() - start);
    const std::vector<MapSegment> part(whole.segments.begin() + start,
                                       whole.segments.begin() + start + n);
    grown.append(part, whole.descriptors.middleRows(static_cast<Eigen::Index>(start), n));
  }
  ASSERT_EQ(grown.map().size(), whole.size());
  EXPECT_TRUE(grown.map().descriptors.isApprox(whole.descriptors));
  EXPECT_EQ(grown.index().size(), whole.size());
  const auto local = shiftedCentroids(whole, 40);
  const Eigen::MatrixXf query = whole.descriptors.topRows(40);
  const auto a = built.localize(local, query), b = grown.localize(local, query);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->matches, b->matches);
  EXPECT_LT((b->T_map_local.translation() - Eigen::Vector3d(3, 1, 0)).norm(), 1e-3);
}

TEST(Localizer, ASharedMapIsNotCopiedUntilItChanges) {
  const auto saved = std::make_shared<const TargetMap>(randomMap(50, 8, false));
  const Localizer a(saved, LocalizerConfig{});
  Localizer b(saved, LocalizerConfig{});
  EXPECT_EQ(&a.map(), saved.get());
  EXPECT_EQ(&b.map(), saved.get());
  b.setCentroid(0, Eigen::Vector3f(1, 2, 3));  // b's own copy from now on
  EXPECT_NE(&b.map(), saved.get());
  EXPECT_EQ(b.map().segments[0].centroid, Eigen::Vector3f(1, 2, 3));
  EXPECT_EQ(saved->segments[0].centroid, a.map().segments[0].centroid);
  EXPECT_NE(saved->segments[0].centroid, Eigen::Vector3f(1, 2, 3));
  EXPECT_THROW(b.append({MapSegment{}}, Eigen::MatrixXf::Zero(1, 5)), std::invalid_argument);
}

TEST(Localizer, GrowingPastTheExactLimitRebuildsAsIvfOnce) {
  LocalizerConfig config;
  config.index.exact_below = 400;
  const TargetMap whole = randomMap(600, 8, false);
  TargetMap first = whole;
  first.segments.resize(300);
  first.descriptors = whole.descriptors.topRows(300);
  Localizer grown(first, config);
  EXPECT_FALSE(grown.index().approximate());
  grown.append({whole.segments.begin() + 300, whole.segments.end()},
               whole.descriptors.bottomRows(300));
  EXPECT_TRUE(grown.index().approximate());
  EXPECT_EQ(grown.index().size(), 600u);
}

}  // namespace semsegmap
