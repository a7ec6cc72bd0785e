// What `semsegmap view` reads and the scene its page is given: matches.csv and trajectory.csv
// written beside localizations.csv and read back, the folders of `slam` and `segment` read back
// with one-line errors naming the file, and the scene's JSON (counts, positions relative to its
// origin, points rebuilt from their 16-bit offsets, the estimated trajectory, the map's sessions,
// escaping).
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "error_text.h"
#include "semsegmap/artefacts/segments_io.h"
#include "semsegmap/io/csv_table.h"
#include "semsegmap/io/trajectory_file.h"
#include "semsegmap/outputs/localization_details.h"
#include "semsegmap/outputs/run_folders.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/viz/scene_export.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

using test_support::errorOf;
using test_support::TempDir;

// Five frames driven along x; ground truth is odometry moved by (10, 5); one localization at
// frame 2, 0.1 m off, with two matches.
LocalizationRun smallRun() {
  LocalizationRun run;
  for (int i = 0; i < 5; ++i) {
    run.trajectory_odom.push_back(planarPose(i, 0, 0, 0));
    run.trajectory_gt.push_back(planarPose(10 + i, 5, 0, 0));
  }
  LocalizationRecord r;
  r.frame_index = 2;
  r.timestamp_s = 0.2;
  r.T_map_base = planarPose(12.1, 5, 0, 0);
  r.inliers = 2;
  r.T_world_base = run.trajectory_gt[2];
  r.translation_error_m = 0.1;
  r.matches = {{{11, 6, 1}, {11.1, 6, 1}}, {{14, 3, 2}, {14, 3.2, 2}}};
  run.localizations.push_back(r);
  return run;
}

void writeRun(const std::filesystem::path& dir, const LocalizationRun& run) {
  std::filesystem::create_directories(dir);
  writeLocalizationsCsv(dir / "localizations.csv", run);
  writeLocalizationDetails(dir, run);
}

TargetMap smallMap() {
  TargetMap map;
  map.descriptor = "eigen";
  map.segments.resize(3);
  map.segments[0] = {{10, 4, 1}, 300, cls::kBuilding, {{9, 4, 1}, {11, 4.5, 2}}};
  map.segments[1] = {{16, 6, 0.5}, 40, cls::kPole, {{16, 6, 0}, {16, 6, 3}, {16.1, 6, 1}}};
  map.segments[2] = {{13, 2, 1}, 90, cls::kVegetation, {}};
  map.descriptors = Eigen::MatrixXf::Zero(3, 7);
  return map;
}

// The typed array a base64 field of the scene holds, as the page reads it.
template <typename T>
std::vector<T> decode(const std::string& b64) {
  static const std::string alphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string bytes;
  uint32_t buffer = 0;
  int bits = 0;
  for (const char c : b64) {
    if (c == '=') break;
    buffer = (buffer << 6) | static_cast<uint32_t>(alphabet.find(c));
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      bytes += static_cast<char>((buffer >> bits) & 0xff);
    }
  }
  std::vector<T> out(bytes.size() / sizeof(T));
  std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

TEST(LocalizationDetails, WrittenBesideTheCsvAndReadBack) {
  TempDir tmp;
  writeRun(tmp.path() / "run", smallRun());
  const LocalizationFolder f = readLocalizationFolder(tmp.path() / "run");
  ASSERT_EQ(f.localizations.size(), 1u);
  EXPECT_EQ(f.localizations[0].frame, 2u);
  EXPECT_EQ(f.localizations[0].inliers, 2);
  EXPECT_NEAR(f.localizations[0].T_map_base.translation().x(), 12.1, 1e-4);
  EXPECT_NEAR(*f.localizations[0].translation_error_m, 0.1, 1e-4);
  EXPECT_FALSE(f.localizations[0].refinement_m.has_value());
  ASSERT_TRUE(f.has_matches);
  ASSERT_EQ(f.matches.size(), 2u);
  EXPECT_EQ(f.matches[1].frame, 2u);
  EXPECT_NEAR(f.matches[1].target.y(), 3.2f, 1e-3);
  ASSERT_TRUE(f.has_trajectory);
  ASSERT_EQ(f.trajectory.size(), 5u);
  EXPECT_EQ(f.trajectory[4].frame, 4u);
  EXPECT_NEAR(f.trajectory[4].T_odom_base.translation().x(), 4.0, 1e-4);
  ASSERT_TRUE(f.trajectory[4].T_world_base.has_value());
  EXPECT_NEAR(f.trajectory[4].T_world_base->translation().y(), 5.0, 1e-4);
}

TEST(LocalizationDetails, WithoutGroundTruthTheGroundTruthColumnsStayEmpty) {
  TempDir tmp;
  LocalizationRun run = smallRun();
  run.trajectory_gt.clear();
  run.localizations[0].T_world_base.reset();
  writeRun(tmp.path(), run);
  const LocalizationFolder f = readLocalizationFolder(tmp.path());
  EXPECT_FALSE(f.localizations[0].translation_error_m.has_value());
  EXPECT_FALSE(f.trajectory[0].T_world_base.has_value());
}

// A frame is named as the dataset names it beside the run's index (scan 001576.bin is frame 27
// of the run), and a time the data does not have is left empty, never made up.
TEST(LocalizationDetails, FramesKeepTheDatasetsNumberAndOnlyTheDatasTime) {
  TempDir tmp;
  LocalizationRun run = smallRun();
  for (size_t i = 0; i < run.trajectory_odom.size(); ++i)
    run.frames.push_back({1574 + i, std::nullopt});  // named by number, no times in the data
  run.localizations[0].frame_number = 1576;
  run.localizations[0].timestamp_s.reset();
  writeRun(tmp.path(), run);
  const CsvTable csv = CsvTable::read(tmp.path() / "localizations.csv");
  EXPECT_EQ(csv.text(0, csv.column("frame")), "2");
  EXPECT_EQ(csv.text(0, csv.column("dataset_frame")), "1576");
  EXPECT_EQ(csv.text(0, csv.column("timestamp")), "");
  const LocalizationFolder f = readLocalizationFolder(tmp.path());
  EXPECT_EQ(f.localizations[0].frame, 2u);
  EXPECT_EQ(f.localizations[0].dataset_frame, std::optional<size_t>(1576));
  EXPECT_FALSE(f.localizations[0].timestamp_s.has_value());
  ASSERT_EQ(f.trajectory.size(), 5u);
  EXPECT_EQ(f.trajectory[3].dataset_frame, std::optional<size_t>(1577));
  EXPECT_FALSE(f.trajectory[3].timestamp_s.has_value());
  // The page is given both, the time as null.
  const TargetMap map = smallMap();
  viz::SceneInputs in;
  in.map = &map;
  in.localization = &f;
  const nlohmann::ordered_json record = viz::sceneJson(in)["localization"]["records"][0];
  EXPECT_EQ(record["frame"], 2);
  EXPECT_EQ(record["dataset_frame"], 1576);
  EXPECT_TRUE(record["time"].is_null()) << record["time"];
  // A time the data has is written as it is.
  run.localizations[0].timestamp_s = 1317384506.25;
  writeRun(tmp.path(), run);
  EXPECT_NEAR(readLocalizationFolder(tmp.path()).localizations[0].timestamp_s.value(),
              1317384506.25, 1e-6);
}

// Folders written before the schema had a version (no dataset_frame, a timestamp always, no
// "schema" in summary.json) are still read.
TEST(LocalizationDetails, Version1FilesAreStillRead) {
  TempDir tmp;
  std::ofstream(tmp.path() / "localizations.csv")
      << "frame,timestamp,x,y,z,qx,qy,qz,qw,inliers,translation_error_m,rotation_error_deg\n"
         "4,0.400000,1.0,2.0,0.0,0,0,0,1,7,,\n";
  std::ofstream(tmp.path() / "summary.json") << "{\"dataset\": \"old\"}\n";
  const LocalizationFolder f = readLocalizationFolder(tmp.path());
  ASSERT_EQ(f.localizations.size(), 1u);
  EXPECT_EQ(f.localizations[0].frame, 4u);
  EXPECT_FALSE(f.localizations[0].dataset_frame.has_value());
  EXPECT_NEAR(f.localizations[0].timestamp_s.value(), 0.4, 1e-9);
  EXPECT_EQ(f.schema, "semsegmap.localization/1");
  EXPECT_EQ(f.dataset, "old");
}

TEST(LocalizationDetails, BadFoldersAndFilesAreOneLineNamingThem) {
  TempDir tmp;
  std::string e = errorOf([&] { readLocalizationFolder(tmp.path() / "missing"); });
  EXPECT_MENTIONS(e, "missing: no such folder");
  EXPECT_ONE_LINE(e);
  e = errorOf([&] { readLocalizationFolder(tmp.path()); });
  EXPECT_MENTIONS(e, tmp.path().string() + ": no localizations.csv");
  EXPECT_ONE_LINE(e);
  writeRun(tmp.path(), smallRun());
  std::ofstream(tmp.path() / "matches.csv", std::ios::app) << "2,1,2\n";
  e = errorOf([&] { readLocalizationFolder(tmp.path()); });
  EXPECT_MENTIONS(e, "matches.csv:4: 3 fields where the header has 7");
  EXPECT_ONE_LINE(e);
  std::ofstream(tmp.path() / "matches.csv") << "frame,local_x,local_y,local_z,target_x,target_y,"
                                               "target_z\n2,1,2,x,4,5,6\n";
  e = errorOf([&] { readLocalizationFolder(tmp.path()); });
  EXPECT_MENTIONS(e, "matches.csv:2: column 'local_z': 'x' is not a number");
  std::ofstream(tmp.path() / "matches.csv") << "frame,local_x\n";
  e = errorOf([&] { readLocalizationFolder(tmp.path()); });
  EXPECT_MENTIONS(e, "matches.csv: no column 'local_y'");
}

TEST(SceneExport, CountsPositionsAndTheEstimatedTrajectory) {
  TempDir tmp;
  writeRun(tmp.path() / "run", smallRun());
  const LocalizationFolder f = readLocalizationFolder(tmp.path() / "run");
  const TargetMap map = smallMap();
  viz::SceneInputs in;
  in.map = &map;
  in.localization = &f;
  const nlohmann::ordered_json j = viz::sceneJson(in);
  EXPECT_EQ(j["version"], viz::kSceneVersion);
  const Eigen::Vector3d origin(j["origin"][0], j["origin"][1], j["origin"][2]);
  EXPECT_EQ(origin, Eigen::Vector3d(13, 4, 1));  // the centre of the centroids' box
  EXPECT_EQ(j["map"]["segments"], 3);
  EXPECT_EQ(j["map"]["stored_points"], 5);
  const auto centroids = decode<float>(j["map"]["centroids"]);
  ASSERT_EQ(centroids.size(), 9u);
  EXPECT_FLOAT_EQ(centroids[3], 16 - 13);
  EXPECT_EQ(decode<uint16_t>(j["map"]["classes"])[1], cls::kPole);
  EXPECT_EQ(decode<uint32_t>(j["map"]["sizes"])[2], 90u);

  const auto& records = j["localization"]["records"];
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0]["matches"].size(), 2u);
  EXPECT_DOUBLE_EQ(records[0]["matches"][0][3], 11.1 - 13);
  EXPECT_DOUBLE_EQ(records[0]["error_m"], 0.1);
  // From the localization on, odometry carried by it: frame 4 is 2 m further along x.
  const auto& t = j["localization"]["trajectory"];
  EXPECT_EQ(t["estimate_first_row"], 2);
  const auto estimate = decode<float>(t["estimate"]);
  ASSERT_EQ(estimate.size(), 9u);
  EXPECT_NEAR(estimate[6], 14.1 - 13, 1e-4);
  EXPECT_NEAR(estimate[7], 5 - 4, 1e-4);
  EXPECT_EQ(decode<float>(t["ground_truth"]).size(), 15u);
}

TEST(SceneExport, StoredPointsAreOffsetsFromTheirCentroid) {
  const TargetMap map = smallMap();
  viz::SceneInputs in;
  in.map = &map;
  const nlohmann::ordered_json points = viz::sceneJson(in)["map"]["points"];
  const auto counts = decode<uint32_t>(points["counts"]);
  EXPECT_EQ(counts, (std::vector<uint32_t>{2, 3, 0}));
  const auto offsets = decode<int16_t>(points["offsets"]);
  ASSERT_EQ(offsets.size(), 15u);
  const double scale = points["scale"];
  EXPECT_NEAR(map.segments[1].centroid.z() + offsets[3 * 3 + 2] * scale, 3.0, scale);
  EXPECT_NEAR(map.segments[0].centroid.x() + offsets[0] * scale, 9.0, scale);
}

// A map merged from two drives: each entry's session, and each session's name, number of entries
// and trajectory (none for the first, which defines the map's frame); the map of one run is one
// session, "this run"; an entry of a session the map does not have is an error naming it.
TEST(SceneExport, TheSessionsOfAMergedMapWithTheirEntriesAndTrajectories) {
  TargetMap map = smallMap();
  viz::SceneInputs in;
  in.map = &map;
  nlohmann::ordered_json j = viz::sceneJson(in);
  EXPECT_TRUE(j["map"]["sessions"].is_null()) << j["map"]["sessions"];
  ASSERT_EQ(j["sessions"].size(), 1u) << j["sessions"];
  EXPECT_EQ(j["sessions"][0]["name"], "this run");
  EXPECT_EQ(j["sessions"][0]["entries"], 3);
  EXPECT_TRUE(j["sessions"][0]["trajectory"].is_null());

  map.sessions = {{"sim:world=1,run=S0", 1700000000, {}},
                  {"sim:world=1,run=S2",
                   1700086400,
                   {planarPose(10, 4, 1, 0), planarPose(12, 4, 1, 0), planarPose(14, 5, 1, 0)}}};
  map.segments[1].session = 1;
  map.segments[2].session = 1;
  in.colouring = "session";
  j = viz::sceneJson(in);
  EXPECT_EQ(j["colouring"], "session");
  EXPECT_EQ(decode<uint16_t>(j["map"]["sessions"]), (std::vector<uint16_t>{0, 1, 1}));
  ASSERT_EQ(j["sessions"].size(), 2u) << j["sessions"];
  EXPECT_EQ(j["sessions"][0]["name"], "sim:world=1,run=S0");
  EXPECT_EQ(j["sessions"][0]["entries"], 1);
  EXPECT_TRUE(j["sessions"][0]["trajectory"].is_null());
  EXPECT_EQ(j["sessions"][1]["name"], "sim:world=1,run=S2");
  EXPECT_EQ(j["sessions"][1]["entries"], 2);
  const auto trajectory = decode<float>(j["sessions"][1]["trajectory"]);  // origin (13, 4, 1)
  ASSERT_EQ(trajectory.size(), 9u);
  EXPECT_FLOAT_EQ(trajectory[3], 12 - 13);
  EXPECT_FLOAT_EQ(trajectory[7], 5 - 4);
  EXPECT_FLOAT_EQ(trajectory[8], 0);

  map.segments[2].session = 2;
  map.source = "ab.map";
  const std::string e = errorOf([&] { viz::sceneJson(in); });
  EXPECT_MENTIONS(e, "ab.map: segment 2 is of session 2, but the map has 2 sessions");
  EXPECT_ONE_LINE(e);
}

TEST(SceneExport, ThePageHoldsTheSceneEscaped) {
  const TargetMap map = smallMap();
  viz::SceneInputs in;
  in.map = &map;
  in.title = "a </script><!-- title";
  const std::string head = "<script type=\"application/json\">", tail = "</script>";
  const std::string page = viz::viewerPage(head + "@SEMSEGMAP_SCENE@" + tail, viz::sceneJson(in));
  EXPECT_EQ(page.find("</script><!--"), std::string::npos);
  EXPECT_NE(page.find("a \\u003c/script>\\u003c!-- title"), std::string::npos);
  const std::string json = page.substr(head.size(), page.size() - head.size() - tail.size());
  EXPECT_EQ(nlohmann::json::parse(json)["title"], in.title);
  const std::string e = errorOf([&] { viz::viewerPage("<html></html>", viz::sceneJson(in)); });
  EXPECT_MENTIONS(e, "no place for the scene");
}

std::vector<Segment> twoSegments() {
  std::vector<Segment> segments(2);
  for (int s = 0; s < 2; ++s) {
    segments[s].id = 7 + s;
    SegmentObservation o;
    o.majority_class = s ? cls::kTrunk : cls::kCar;
    for (int k = 0; k < 4; ++k) {
      EnrichedPoint p;
      p.x = 3.0f * s + 0.1f * k;
      p.y = 1;
      p.z = 0.5f;
      p.class_id = o.majority_class;
      p.has_color = true;
      p.v = 0.8f;
      o.points.push_back(p);
    }
    o.n_points = o.points.size();
    o.centroid = Eigen::Vector3d(3.0 * s + 0.15, 1, 0.5);
    segments[s].observations.push_back(o);
  }
  return segments;
}

TEST(RunFolders, SegmentsReadBackAndGroupedBySegment) {
  TempDir tmp;
  std::vector<Segment> segments = twoSegments();
  segments[0].first_frame = 1;
  segments[0].last_frame = 5;
  // Frames 0 and 1 of the run are the dataset's scans 40 and 42; frame 5 has no number.
  writeSegmentsCsv(tmp.path() / "segments.csv", segments, ClassTable::Default(), false, {40, 42});
  writeSegmentPointsPly(tmp.path() / "segments.ply", segments);
  const CsvTable csv = CsvTable::read(tmp.path() / "segments.csv");
  EXPECT_EQ(csv.text(0, csv.column("first_frame")), "1");
  EXPECT_EQ(csv.text(0, csv.column("first_dataset_frame")), "42");
  EXPECT_EQ(csv.text(0, csv.column("last_frame")), "5");
  EXPECT_EQ(csv.text(0, csv.column("last_dataset_frame")), "");
  EXPECT_EQ(csv.text(0, csv.column("gt_purity")), "");  // no ground truth: unknown, not 0
  const SegmentFolder f = readSegmentFolder(tmp.path());
  ASSERT_EQ(f.segments.size(), 2u);
  EXPECT_EQ(f.segments[1].id, 8);
  EXPECT_EQ(f.segments[1].class_name, "trunk");
  ASSERT_EQ(f.points.size(), 8u);
  EXPECT_EQ(f.points[5].segment, 8);
  EXPECT_EQ(f.points[5].class_id, cls::kTrunk);
  EXPECT_FLOAT_EQ(f.points[5].p.x(), 3.1f);
  EXPECT_GT(f.points[5].rgb[0], 150);  // value 0.8, no saturation: light grey

  const TargetMap map = smallMap();
  viz::SceneInputs in;
  in.map = &map;
  in.segments = &f;
  const nlohmann::ordered_json j = viz::sceneJson(in)["segments"];
  EXPECT_EQ(j["groups"], 2);
  EXPECT_EQ(j["ids"][1], 8);
  EXPECT_EQ(decode<uint8_t>(j["rgb"]).size(), 24u);

  const auto size = std::filesystem::file_size(tmp.path() / "segments.ply");
  std::filesystem::resize_file(tmp.path() / "segments.ply", size - 5);
  const std::string e = errorOf([&] { readSegmentFolder(tmp.path()); });
  EXPECT_MENTIONS(e, "segments.ply: truncated after 7 of 8 points");
  EXPECT_ONE_LINE(e);
}

TEST(RunFolders, SlamFolderAndItsLoopsAgainstTheTrajectory) {
  TempDir tmp;
  std::vector<StampedPose> poses;
  for (int i = 0; i < 3; ++i) poses.push_back({0.1 * i, planarPose(i, 0, 0, 0)});
  std::string e = errorOf([&] { readSlamFolder(tmp.path()); });
  EXPECT_MENTIONS(e, "no trajectory_tum.txt (not the output of semsegmap slam)");
  writeTum(tmp.path() / "trajectory_tum.txt", poses);
  std::ofstream(tmp.path() / "loops.csv") << "frame,old_frame,inliers,correction_m\n2,0,9,0.4\n";
  const SlamFolder f = readSlamFolder(tmp.path());
  EXPECT_EQ(f.trajectory.size(), 3u);
  EXPECT_TRUE(f.odometry.empty());
  ASSERT_EQ(f.loops.size(), 1u);
  EXPECT_EQ(f.loops[0].inliers, 9);
  std::ofstream(tmp.path() / "loops.csv", std::ios::app) << "5,1,9,0.4\n";
  e = errorOf([&] { readSlamFolder(tmp.path()); });
  EXPECT_MENTIONS(e, "loops.csv: loop 2 joins frames 1 and 5, beyond the trajectory's 3 poses");
  EXPECT_ONE_LINE(e);
}

// A slam run over data without frame times writes KITTI files alone: the view reads them; the
// TUM files win where both are there.
TEST(RunFolders, ASlamFolderWithoutTimesIsReadFromItsKittiFiles) {
  TempDir tmp;
  std::vector<StampedPose> poses;
  for (int i = 0; i < 3; ++i) poses.push_back({0.1 * i, planarPose(i, 0, 0, 0)});
  writeKitti(tmp.path() / "trajectory_kitti.txt", poses);
  writeKitti(tmp.path() / "odometry_kitti.txt", {poses[0], poses[1]});
  SlamFolder f = readSlamFolder(tmp.path());
  ASSERT_EQ(f.trajectory.size(), 3u);
  EXPECT_NEAR(f.trajectory[2].T.translation().x(), 2.0, 1e-9);
  EXPECT_EQ(f.odometry.size(), 2u);
  writeTum(tmp.path() / "trajectory_tum.txt", {poses[0]});
  f = readSlamFolder(tmp.path());
  EXPECT_EQ(f.trajectory.size(), 1u);
}

}  // namespace
}  // namespace semsegmap
