// `semsegmap view` through the built binary and its page in a real browser: the command's
// one-line errors; the tiny simulated world mapped, localized, segmented and loop-closed by the
// commands as a user types them, its page opened from disk in headless Chromium with the network
// off (tests/test_viewer_browser.mjs, Playwright), the numbers the page reports checked against
// the files, a click on a localization showing its matches, the play button and the frame slider,
// and a screenshot that is not blank; a map merged from two sessions coloured by session in the
// page's switch (each session in its own colour, its legend entry, its trajectory);
// and a map of 100k segments, loaded and turned, with its file size, load time and frame rate.
// A build without the viewer, a machine without Chromium or a Node.js older than 20 (which
// Playwright needs) skips what it cannot run, saying why.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <future>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include "command_result.h"
#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/core/json.h"
#include "semsegmap/io/csv_table.h"
#include "temp_dir.h"

#ifndef SEMSEGMAP_TEST_VIEWER
#error "tests/CMakeLists.txt passes SEMSEGMAP_TEST_VIEWER, SEMSEGMAP_BINARY and the tools' paths"
#endif

namespace semsegmap {
namespace {

using test_support::TempDir;

const std::string kSource = SEMSEGMAP_SOURCE_DIR;
// Where screenshots are kept for a person to look at (the build folder, not a temporary one).
const std::filesystem::path kScreenshots = SEMSEGMAP_VIEWER_SCREENSHOTS;

using test_support::readFile;
using test_support::Result;

// Runs a shell command line with stdout and stderr into files named after `stem` (two threads
// may run commands in one folder).
Result shell(const std::string& command, const std::filesystem::path& dir,
             const std::string& stem = "command") {
  const std::filesystem::path out = dir / (stem + ".out"), err = dir / (stem + ".err");
  const int status = std::system(
      (command + " > '" + out.string() + "' 2> '" + err.string() + "' < /dev/null").c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, readFile(out), readFile(err)};
}

Result semsegmap(const std::string& args, const std::filesystem::path& dir,
                 const std::string& stem = "command") {
  return shell("'" SEMSEGMAP_BINARY "' " + args, dir, stem);
}

// Runs the commands one after the other; what the first that failed printed, or "".
std::string runAll(const std::vector<std::string>& commands, const std::filesystem::path& dir,
                   const std::string& stem) {
  for (const std::string& args : commands) {
    const Result r = semsegmap(args, dir, stem);
    if (r.code != 0)
      return "semsegmap " + args + " exited " + std::to_string(r.code) + ":\n" + r.err;
  }
  return "";
}

// Why the browser tests cannot run here, or "" when they can.
std::string browserMissing() {
  if (!SEMSEGMAP_TEST_VIEWER) return "this build has no viewer (SEMSEGMAP_WITH_VIEWER, Node.js)";
  if (!std::filesystem::exists(SEMSEGMAP_CHROMIUM))
    return "no Chromium at '" SEMSEGMAP_CHROMIUM "' (scripts/setup.sh installs Debian's chromium)";
  if (!std::filesystem::exists(SEMSEGMAP_VIEWER_NODE_MODULES "/playwright-core"))
    return "playwright-core is not in " SEMSEGMAP_VIEWER_NODE_MODULES
           " (scripts/setup.sh runs npm ci in viewer/)";
  TempDir tmp;
  const Result v =
      shell("'" SEMSEGMAP_NODE
            "' -e 'process.exit(+process.versions.node.split(\".\")[0] >= 20 ? 0 : 1)'",
            tmp.path());
  if (v.code != 0) return "Playwright needs Node.js 20 or newer";
  return "";
}

// The page in Chromium (tests/test_viewer_browser.mjs): what it reported, as JSON; with
// `colouring`, that colouring picked in the page's switch before the screenshot.
nlohmann::json openInBrowser(const std::filesystem::path& page, const std::filesystem::path& png,
                             int rotate_ms, const std::filesystem::path& dir,
                             const std::string& colouring = "") {
  const Result r =
      shell("'" SEMSEGMAP_NODE "' '" + kSource + "/tests/test_viewer_browser.mjs' '" +
                SEMSEGMAP_VIEWER_NODE_MODULES + "' '" + SEMSEGMAP_CHROMIUM + "' '" + page.string() +
                "' '" + png.string() + "' " + std::to_string(rotate_ms) + " " + colouring,
            dir);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << r.out << r.err;
  return j.is_discarded() ? nlohmann::json::object() : j;
}

// The share of a screenshot's pixels that differ from its corner's (the background), and the
// number of distinct colours (16 levels a channel).
std::pair<double, size_t> screenshotContent(const std::filesystem::path& png) {
  const cv::Mat image = cv::imread(png.string(), cv::IMREAD_COLOR);
  if (image.empty()) return {0.0, 0};
  const cv::Vec3b background = image.at<cv::Vec3b>(image.rows - 1, image.cols / 2);
  size_t other = 0;
  std::set<int> colours;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3b p = image.at<cv::Vec3b>(y, x);
      other += cv::norm(p, background, cv::NORM_L1) > 30;
      colours.insert((p[0] >> 4) * 256 + (p[1] >> 4) * 16 + (p[2] >> 4));
    }
  return {static_cast<double>(other) / static_cast<double>(image.total()), colours.size()};
}

TEST(ViewCommand, BadInputIsOneLineNamingTheFileAndLeavesNoPage) {
  TempDir tmp;
  const std::string out = (tmp.path() / "view.html").string();
  if (!SEMSEGMAP_TEST_VIEWER) {
    const Result r = semsegmap("view --map m.map --out " + out, tmp.path());
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("semsegmap view: error: this build has no viewer"), std::string::npos)
        << r.err;
    GTEST_SKIP() << "this build has no viewer (SEMSEGMAP_WITH_VIEWER, Node.js)";
  }
  const auto expectOneLine = [&](const Result& r, int code, const std::string& text) {
    EXPECT_EQ(r.code, code) << r.err;
    EXPECT_NE(r.err.find(text), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), code == 1 ? 1 : 2) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
  };
  const std::string missing = (tmp.path() / "missing.map").string();
  expectOneLine(semsegmap("view --map " + missing + " --out " + out, tmp.path()), 1,
                "semsegmap view: error: " + missing + ": ");
  TargetMap map;
  map.descriptor = "eigen";
  map.segments.push_back({{1, 2, 3}, 10, cls::kPole, {}});
  map.descriptors = Eigen::MatrixXf::Zero(1, 7);
  const std::string map_path = (tmp.path() / "one.map").string();
  saveTargetMap(map_path, map);
  std::filesystem::create_directories(tmp.path() / "empty");
  expectOneLine(semsegmap("view --map " + map_path + " --localization " +
                              (tmp.path() / "empty").string() + " --out " + out,
                          tmp.path()),
                1, (tmp.path() / "empty").string() + ": no localizations.csv");
  expectOneLine(semsegmap("view --map " + map_path + " --slam " + (tmp.path() / "empty").string() +
                              " --out " + out,
                          tmp.path()),
                1, "no trajectory_tum.txt (not the output of semsegmap slam)");
  expectOneLine(semsegmap("view --out " + out, tmp.path()), 2, "--map");
  expectOneLine(semsegmap("view --map " + map_path + " --colour hue --out " + out, tmp.path()), 2,
                "--colour");
  const Result ok = semsegmap("view --map " + map_path + " --out " + out, tmp.path());
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  // A localization folder from before matches.csv: shown, with a note that matches are missing.
  std::ofstream(tmp.path() / "empty" / "localizations.csv")
      << "frame,timestamp,x,y,z,qx,qy,qz,qw,inliers,translation_error_m,rotation_error_deg\n"
         "3,0.3,1,2,0,0,0,0,1,7,,\n";
  const Result old = semsegmap("view --map " + map_path + " --localization " +
                                   (tmp.path() / "empty").string() + " --out " + out,
                               tmp.path());
  EXPECT_EQ(old.code, 0) << old.err;
  EXPECT_NE(old.err.find("has no matches.csv"), std::string::npos) << old.err;
}

size_t csvRows(const std::filesystem::path& path) {
  return CsvTable::read(path).rows();
}

// The tiny world as a user runs it: a map of S0's first frames with 16 points a segment and S2
// localized against it, beside a segmentation of S2's start and loop closure on S0 (in a second
// thread: each command spends seconds starting, loading its models and building the world).
void runTinyWorld(const std::filesystem::path& dir) {
  const std::string config = " --config " + kSource + "/config/semsegmap.yaml";
  const std::string s0 = " --dataset sim:world=1,run=S0,preset=tiny",
                    s2 = " --dataset sim:world=1,run=S2,preset=tiny";
  const std::string map = (dir / "tiny.map").string();
  auto side = std::async(std::launch::async, [&] {
    return runAll({"segment" + s2 + config + " --max-frames 10 --out " + (dir / "seg").string(),
                   "slam" + s0 + config + " --max-frames 30 --out " + (dir / "slam").string()},
                  dir, "side");
  });
  const std::string localized =
      runAll({"map" + s0 + config + " --points 16 --max-frames 60 --out " + map,
              "localize" + s2 + config + " --map " + map + " --max-frames 40 --out " +
                  (dir / "loc").string()},
             dir, "main");
  const std::string segmented = side.get();
  ASSERT_EQ(localized, "");
  ASSERT_EQ(segmented, "");
}

// What the page reported against what the files hold.
void expectCountsOf(const nlohmann::json& page, const std::filesystem::path& dir) {
  const nlohmann::json& stats = page["stats"];
  const size_t segments = loadTargetMap(dir / "tiny.map").size();
  const size_t localizations = csvRows(dir / "loc" / "localizations.csv");
  EXPECT_GT(localizations, 0u);
  EXPECT_EQ(stats["segments"], segments);
  EXPECT_EQ(page["dom"]["segments"], segments);
  EXPECT_GT(stats["mapPoints"].get<size_t>(), segments);  // the stored points are drawn
  EXPECT_EQ(stats["localizations"], localizations);
  EXPECT_EQ(page["dom"]["localizations"], localizations);
  EXPECT_EQ(page["dom"]["listed"], localizations);
  EXPECT_EQ(stats["matches"], csvRows(dir / "loc" / "matches.csv"));
  EXPECT_EQ(stats["frames"], csvRows(dir / "loc" / "trajectory.csv"));
  EXPECT_EQ(stats["segmentRunSegments"], csvRows(dir / "seg" / "segments.csv"));
  EXPECT_EQ(stats["loops"], csvRows(dir / "slam" / "loops.csv"));
  EXPECT_GT(page["dom"]["legend"].get<int>(), 2);
  // Class unknown (a LiDAR-only map is all of it) in a light neutral grey, not the class table's
  // black, which vanishes on the page's near-black background.
  const nlohmann::json& unknown = page["unknownColour"];
  ASSERT_EQ(unknown.size(), 3u) << unknown;
  EXPECT_GE(unknown[0].get<int>(), 150) << unknown;
  EXPECT_EQ(unknown[0], unknown[1]) << unknown;
  EXPECT_EQ(unknown[1], unknown[2]) << unknown;
}

void expectInteraction(const nlohmann::json& page) {
  const nlohmann::json& click = page["click"];
  ASSERT_TRUE(click["target"].is_object()) << "no localization with matches was clickable";
  const int clicked = click["target"]["index"];
  ASSERT_TRUE(click["selected"].is_object()) << "the click selected nothing: " << click;
  EXPECT_EQ(click["selected"]["index"], clicked);
  EXPECT_GT(click["selected"]["matches"].get<int>(), 0);
  EXPECT_EQ(click["domMatches"], click["selected"]["matches"]);
  EXPECT_NE(click["text"].get<std::string>().find("inliers"), std::string::npos);
  EXPECT_EQ(page["list"]["selected"]["index"], page["list"]["index"]);
  EXPECT_NE(page["play"]["after"], page["play"]["before"]);
  // The End key on the slider: the last frame, and the last localization with it.
  EXPECT_EQ(page["slider"]["label"],
            "frame " + std::to_string(page["stats"]["frames"].get<int>() - 1));
  EXPECT_EQ(page["slider"]["selected"]["index"], page["stats"]["localizations"].get<int>() - 1);
}

TEST(ViewerPage, TinyWorldOpensOfflineInChromiumAndAClickShowsMatches) {
  if (!SEMSEGMAP_WITH_SIM || !SEMSEGMAP_WITH_TORCH)
    GTEST_SKIP() << "the tiny world needs the simulator and the learned descriptors";
  const std::string missing = browserMissing();
  if (!missing.empty()) GTEST_SKIP() << missing;
  TempDir tmp;
  const auto dir = tmp.path();
  ASSERT_NO_FATAL_FAILURE(runTinyWorld(dir));
  const std::string page = (dir / "tiny.html").string();
  const Result v = semsegmap("view --map " + (dir / "tiny.map").string() + " --localization " +
                                 (dir / "loc").string() + " --slam " + (dir / "slam").string() +
                                 " --segments " + (dir / "seg").string() + " --out " + page,
                             dir);
  ASSERT_EQ(v.code, 0) << v.err;
  std::filesystem::create_directories(kScreenshots);
  const std::filesystem::path png = kScreenshots / "viewer_tiny.png";
  const nlohmann::json j = openInBrowser(page, png, 0, dir);
  ASSERT_FALSE(j.contains("failed")) << j.dump();
  ASSERT_TRUE(j["error"].is_null()) << j["error"];
  EXPECT_EQ(j["foreignRequests"].size(), 0u) << j["foreignRequests"];
  EXPECT_EQ(j["pageErrors"].size(), 0u) << j["pageErrors"];
  expectCountsOf(j, dir);
  expectInteraction(j);
  EXPECT_GT(j["canvas"]["nonBackground"].get<double>(), 0.02) << j["canvas"];
  EXPECT_GT(j["canvas"]["colours"].get<int>(), 8) << j["canvas"];
  const auto [share, colours] = screenshotContent(png);
  EXPECT_GT(share, 0.05) << png;
  EXPECT_GT(colours, 20u) << png;
  std::cout << "page " << std::filesystem::file_size(page) << " bytes, ready in " << j["wallMs"]
            << " ms; screenshot " << png.string() << "\n";
}

// Two drives past a row of houses: S0 (the map's first session, which defines its frame and has
// no trajectory) saw 24 segments along y = 0, S2 16 along y = 10 and drove between them; a few
// classes, so that colouring by class is not one colour either. 8 stored points a segment.
TargetMap twoSessionMap() {
  const ClassId classes[] = {cls::kBuilding, cls::kVegetation, cls::kPole, cls::kFence};
  TargetMap map;
  map.descriptor = "eigen";
  map.sessions = {{"sim:world=1,run=S0,preset=tiny", 1700000000, {}},
                  {"sim:world=1,run=S2,preset=tiny", 1700086400, {}}};
  for (int k = 0; k <= 40; ++k) map.sessions[1].trajectory.push_back(planarPose(k, 5, 0, 0));
  for (uint16_t session = 0; session < 2; ++session)
    for (int i = 0; i < (session == 0 ? 24 : 16); ++i) {
      MapSegment s;
      s.centroid = {1.7f * static_cast<float>(i), session == 0 ? 0.0f : 10.0f, 2.0f};
      s.n_points = 200;
      s.majority_class = classes[i % 4];
      for (int p = 0; p < 8; ++p)
        s.points.push_back(s.centroid + Eigen::Vector3f(0.1f * static_cast<float>(p % 4) - 0.15f,
                                                        0.3f * static_cast<float>(p / 4), 0.2f));
      s.segment = static_cast<uint32_t>(map.segments.size());
      s.session = session;
      s.keyframe = session == 0 ? 0 : static_cast<uint32_t>(i);
      map.segments.push_back(s);
    }
  map.descriptors = Eigen::MatrixXf::Zero(static_cast<Eigen::Index>(map.size()), 7);
  return map;
}

// What the page showed after the switch to session colouring, against the map's sessions: the
// map drawn in exactly one colour per session (each its entries' points), distinct, each the
// session's swatch in the legend (name and number of entries) and on the canvas.
void expectSessionColouring(const nlohmann::json& page, const std::vector<std::string>& names,
                            const std::vector<size_t>& entries, size_t points_per_entry) {
  const size_t n = names.size();
  ASSERT_TRUE(page.contains("colouring")) << page.dump();
  const nlohmann::json& c = page["colouring"];
  EXPECT_EQ(page["stats"]["sessions"], n);
  EXPECT_EQ(c["selected"], "session");
  EXPECT_TRUE(c["sessionLegendShown"].get<bool>()) << c;
  EXPECT_FALSE(c["classLegendShown"].get<bool>()) << c;
  EXPECT_GT(c["before"].size(), n) << "colouring by class drew as few colours as by session";
  ASSERT_EQ(c["legend"].size(), n) << c["legend"];
  ASSERT_EQ(c["sessionColours"].size(), n) << c;
  ASSERT_EQ(c["mapColours"].size(), n) << c["mapColours"];  // [r, g, b, count], most first
  std::set<std::vector<int>> distinct;
  for (size_t k = 0; k < n; ++k) {
    const nlohmann::json& item = c["legend"][k];
    EXPECT_EQ(item["session"], k);
    const std::string text = item["text"].get<std::string>();
    EXPECT_NE(text.find(names[k]), std::string::npos) << text;
    EXPECT_EQ(text.substr(text.rfind(' ') + 1), std::to_string(entries[k])) << text;
    const auto rgb = c["sessionColours"][k].get<std::vector<int>>();
    ASSERT_EQ(rgb.size(), 3u);
    distinct.insert(rgb);
    EXPECT_EQ(item["swatch"], "rgb(" + std::to_string(rgb[0]) + ", " + std::to_string(rgb[1]) +
                                  ", " + std::to_string(rgb[2]) + ")");
    size_t drawn = 0;  // the map's points in this session's colour
    for (const nlohmann::json& m : c["mapColours"])
      if (std::vector<int>{m[0].get<int>(), m[1].get<int>(), m[2].get<int>()} == rgb)
        drawn = m[3].get<size_t>();
    EXPECT_EQ(drawn, entries[k] * points_per_entry) << "session " << k << ": " << c["mapColours"];
    EXPECT_GT(c["pixels"][k].get<int>(), 20) << "session " << k << " is not on the canvas";
  }
  EXPECT_EQ(distinct.size(), n) << c["sessionColours"];
}

TEST(ViewerPage, ColouredBySessionEachSessionHasItsColourItsLegendEntryAndItsTrajectory) {
  const std::string missing = browserMissing();
  if (!missing.empty()) GTEST_SKIP() << missing;
  TempDir tmp;
  TargetMap map = twoSessionMap();
  const std::filesystem::path map_path = tmp.path() / "s02.map", page = tmp.path() / "s02.html";
  saveTargetMap(map_path, map);
  const Result v =
      semsegmap("view --map " + map_path.string() + " --out " + page.string(), tmp.path());
  ASSERT_EQ(v.code, 0) << v.err;
  const std::string html = readFile(page);
  for (const MapSession& s : map.sessions)
    EXPECT_NE(html.find("\"" + s.name + "\""), std::string::npos) << s.name;
  std::filesystem::create_directories(kScreenshots);
  const std::filesystem::path png = kScreenshots / "viewer_sessions.png";
  const nlohmann::json j = openInBrowser(page, png, 0, tmp.path(), "session");
  ASSERT_FALSE(j.contains("failed")) << j.dump();
  ASSERT_TRUE(j["error"].is_null()) << j["error"];
  EXPECT_EQ(j["pageErrors"].size(), 0u) << j["pageErrors"];
  ASSERT_NO_FATAL_FAILURE(
      expectSessionColouring(j, {map.sessions[0].name, map.sessions[1].name}, {24, 16}, 8));
  // S0 defines the map's frame and has no trajectory: S2's alone is drawn.
  EXPECT_EQ(j["colouring"]["sessionTrajectories"], 1);
  EXPECT_GT(screenshotContent(png).first, 0.002) << png;
  std::cout << "screenshot " << png.string() << "\n";

  // The map of one run: one session, "this run", all its entries in one colour.
  map.sessions.clear();
  for (MapSegment& s : map.segments) s.session = 0;
  saveTargetMap(map_path, map);
  const Result one =
      semsegmap("view --map " + map_path.string() + " --out " + page.string(), tmp.path());
  ASSERT_EQ(one.code, 0) << one.err;
  const nlohmann::json single =
      openInBrowser(page, tmp.path() / "one.png", 0, tmp.path(), "session");
  ASSERT_FALSE(single.contains("failed")) << single.dump();
  ASSERT_TRUE(single["error"].is_null()) << single["error"];
  ASSERT_NO_FATAL_FAILURE(expectSessionColouring(single, {"this run"}, {40}, 8));
  EXPECT_EQ(single["colouring"]["sessionTrajectories"], 0);
}

// A map the size of a city: 100k segments over 1.6 x 1.6 km, with `points` stored points each.
TargetMap largeMap(size_t points) {
  std::mt19937 rng(17);
  std::uniform_real_distribution<float> across(-800, 800), up(0, 8), offset(-1.5f, 1.5f);
  const ClassId classes[] = {cls::kBuilding, cls::kVegetation,  cls::kTrunk, cls::kPole,
                             cls::kFence,    cls::kTrafficSign, cls::kCar,   cls::kRoof};
  TargetMap map;
  map.descriptor = "eigen";
  map.segments.resize(100000);
  for (size_t i = 0; i < map.segments.size(); ++i) {
    MapSegment& s = map.segments[i];
    s.centroid = {across(rng), across(rng), up(rng)};
    s.n_points = 50 + rng() % 3000;
    s.majority_class = classes[rng() % 8];
    for (size_t k = 0; k < points; ++k)
      s.points.push_back(s.centroid + Eigen::Vector3f(offset(rng), offset(rng), offset(rng)));
  }
  map.descriptors = Eigen::MatrixXf::Zero(static_cast<Eigen::Index>(map.size()), 7);
  return map;
}

// Loaded and turned for 3 s: the numbers the README gives, printed and kept as test properties.
void expectLargeMapUsable(size_t points, const std::string& name) {
  TempDir tmp;
  const std::filesystem::path map = tmp.path() / (name + ".map"),
                              page = tmp.path() / (name + ".html");
  saveTargetMap(map, largeMap(points));
  const auto start = std::chrono::steady_clock::now();
  const Result v = semsegmap("view --map " + map.string() + " --out " + page.string(), tmp.path());
  ASSERT_EQ(v.code, 0) << v.err;
  const double write_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::filesystem::create_directories(kScreenshots);
  const nlohmann::json j =
      openInBrowser(page, kScreenshots / ("viewer_" + name + ".png"), 3000, tmp.path());
  ASSERT_FALSE(j.contains("failed")) << j.dump();
  ASSERT_TRUE(j["error"].is_null()) << j["error"];
  EXPECT_EQ(j["stats"]["segments"], 100000);
  EXPECT_EQ(j["stats"]["mapPoints"], 100000 * points);
  EXPECT_EQ(j["foreignRequests"].size(), 0u);
  EXPECT_GT(j["canvas"]["nonBackground"].get<double>(), 0.02);
  EXPECT_LT(j["loadMs"].get<double>(), 60000.0);
  EXPECT_GT(j["rotation"]["frames"].get<int>(), 2);
  const double mb = static_cast<double>(std::filesystem::file_size(page)) / 1e6;
  std::printf(
      "%s: page %.1f MB written in %.1f s; Chromium (software WebGL): ready %.0f ms after "
      "the start of loading (%.0f ms building), turning at %.1f frames/s\n",
      name.c_str(), mb, write_s, j["loadMs"].get<double>(), j["buildMs"].get<double>(),
      j["rotation"]["fps"].get<double>());
  ::testing::Test::RecordProperty("page_mb", std::to_string(mb));
  ::testing::Test::RecordProperty("load_ms", std::to_string(j["loadMs"].get<double>()));
  ::testing::Test::RecordProperty("fps", std::to_string(j["rotation"]["fps"].get<double>()));
}

TEST(ViewerPage, HundredThousandSegmentsLoadAndTurn) {
  const std::string missing = browserMissing();
  if (!missing.empty()) GTEST_SKIP() << missing;
  expectLargeMapUsable(0, "100k_centroids");
}

TEST(ViewerPage, HundredThousandSegmentsWithSixteenPointsEachLoadAndTurn) {
  const std::string missing = browserMissing();
  if (!missing.empty()) GTEST_SKIP() << missing;
  expectLargeMapUsable(16, "100k_points");
}

}  // namespace
}  // namespace semsegmap
