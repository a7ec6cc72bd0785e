// The semantics stage: class maps (shipped and hand-made), the segmentation network on ONNX
// networks whose behaviour is known by construction (scripts/make_onnx_models.py: colour4
// classifies pixels by their strongest channel, or as dark), preprocessing and resizing back,
// the rate at which it runs, label sets, and the one-line errors of each.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <set>
#include <thread>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/dataset_specs.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/datasets/semantic_sources.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/label_set.h"
#include "semsegmap/pipeline/pipeline.h"
#include "semsegmap/semantics/frame_labeler.h"
#include "semsegmap/semantics/live_labeler.h"
#include "semsegmap/settings/class_map_file.h"
#include "semsegmap/settings/config.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

using test_support::TempDir;
namespace fs = std::filesystem;

const fs::path kOnnx = SEMSEGMAP_ONNX_DIR;
const fs::path kClassMaps = fs::path(SEMSEGMAP_SOURCE_DIR) / "config" / "class_maps";

// Whether `f` throws a std::exception whose message contains every one of `parts`.
template <typename F>
::testing::AssertionResult throwsWith(F f, std::initializer_list<std::string> parts) {
  try {
    f();
  } catch (const std::exception& e) {
    const std::string what = e.what();
    for (const std::string& p : parts)
      if (what.find(p) == std::string::npos)
        return ::testing::AssertionFailure() << "'" << what << "' lacks '" << p << "'";
    if (what.find('\n') != std::string::npos)
      return ::testing::AssertionFailure() << "not one line: '" << what << "'";
    return ::testing::AssertionSuccess();
  }
  return ::testing::AssertionFailure() << "nothing thrown";
}

// colour4's classes: 0 red, 1 green, 2 blue, 3 dark -> building, vegetation, sky, road.
ClassMap colourMap(int classes = 4) {
  const ClassId to[4] = {cls::kBuilding, cls::kVegetation, cls::kSky, cls::kRoad};
  const char* names[4] = {"red", "green", "blue", "dark"};
  std::vector<ClassMapEntry> entries;
  for (int c = 0; c < classes; ++c) entries.push_back({c, names[c], to[c]});
  return ClassMap("colour4", entries);
}

// A picture of four quadrants: red, green (top), blue, black (bottom).
Image quadrants(int w, int h) {
  Image img(w, h, 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int q = (y >= h / 2) * 2 + (x >= w / 2);
      if (q < 3) img.at(x, y)[q] = 255;
    }
  return img;
}

SemanticsConfig plainConfig(const std::string& model = "colour4.onnx") {
  SemanticsConfig c;
  c.model = (kOnnx / model).string();
  c.mean = {0, 0, 0};  // colour4 is built on pixel values in [0, 1]
  c.std = {1, 1, 1};
  c.threads = 1;
  return c;
}

std::unique_ptr<SegmentationNetwork> network(const SemanticsConfig& c, ClassMap map = colourMap()) {
  return std::make_unique<SegmentationNetwork>(c, readFileBytes(c.model), std::move(map), c.model);
}

// The class at the centre of each quadrant.
std::vector<ClassId> quadrantClasses(const Image& labels) {
  const int w = labels.width, h = labels.height;
  return {*labels.at(w / 4, h / 4), *labels.at(3 * w / 4, h / 4), *labels.at(w / 4, 3 * h / 4),
          *labels.at(3 * w / 4, 3 * h / 4)};
}

const std::vector<ClassId> kExpected = {cls::kBuilding, cls::kVegetation, cls::kSky, cls::kRoad};

TEST(ClassMap, MapsListedIdsAndNamesThePixelOfOneItLacks) {
  const ClassMap map = colourMap(3);
  EXPECT_EQ(map.find(2), cls::kSky);
  EXPECT_FALSE(map.find(3));
  EXPECT_EQ(map.firstMissing(3), std::nullopt);
  EXPECT_EQ(map.firstMissing(5), 3);
  Image source(4, 2, 1, 1);
  EXPECT_EQ(mapLabelImage(source, map, "x.png").data, std::vector<uint8_t>(8, cls::kVegetation));
  *source.at(3, 1) = 3;
  EXPECT_TRUE(throwsWith([&] { mapLabelImage(source, map, "x.png"); },
                         {"x.png: pixel (3, 1) has class id 3", "colour4"}));
  EXPECT_THROW(ClassMap("twice", {{1, "a", cls::kRoad}, {1, "b", cls::kSky}}),
               std::invalid_argument);
  const ClassMap identity = ClassMap::Identity(ClassTable::Default());
  EXPECT_EQ(identity.find(cls::kPole), cls::kPole);
  EXPECT_FALSE(identity.find(15));
}

TEST(ClassMap, ShippedMapsCoverTheirNetworksClasses) {
  const ClassTable table = ClassTable::Default();
  const ClassMap cityscapes = readClassMap(kClassMaps / "cityscapes.yaml", table);
  EXPECT_EQ(cityscapes.firstMissing(19), std::nullopt);
  EXPECT_EQ(cityscapes.find(0), cls::kRoad);  // not unknown, as reading the ids raw would give
  EXPECT_EQ(cityscapes.find(13), cls::kCar);
  EXPECT_EQ(cityscapes.find(255), cls::kUnknown);
  EXPECT_FALSE(cityscapes.find(19));
  const ClassMap ids = readClassMap(kClassMaps / "cityscapes-ids.yaml", table);
  EXPECT_EQ(ids.firstMissing(34), std::nullopt);
  EXPECT_EQ(ids.find(7), cls::kRoad);
  EXPECT_EQ(ids.find(26), cls::kCar);
  const ClassMap ade = readClassMap(kClassMaps / "ade20k.yaml", table);
  EXPECT_EQ(ade.firstMissing(150), std::nullopt);
  EXPECT_FALSE(ade.find(150));
  EXPECT_EQ(ade.find(2), cls::kSky);
  EXPECT_EQ(ade.find(20), cls::kCar);
  EXPECT_EQ(ade.find(6), cls::kRoad);
}

TEST(ClassMap, FileErrorsNameTheFileAndTheField) {
  TempDir tmp;
  const ClassTable table = ClassTable::Default();
  const fs::path file = tmp.path() / "map.yaml";
  auto write = [&](const std::string& text) { std::ofstream(file) << text; };
  write("name: m\nclasses:\n  - {id: 0, name: road, class: street}\n");
  EXPECT_TRUE(throwsWith([&] { readClassMap(file, table); },
                         {file.string(), "classes[0].class: 'street' is not a class"}));
  write("name: m\nclasses:\n  - {id: 0, name: a, class: road}\n  - {id: 0, name: b, class: sky}\n");
  EXPECT_TRUE(throwsWith([&] { readClassMap(file, table); }, {file.string(), "listed twice"}));
  write("name: m\nclases: []\n");
  EXPECT_TRUE(throwsWith([&] { readClassMap(file, table); }, {file.string(), "clases"}));
  EXPECT_TRUE(throwsWith([&] { readClassMap(tmp.path() / "none.yaml", table); }, {"none.yaml"}));
  // Names: the project's own ids, a shipped map, a file beside the referrer, an unknown name.
  EXPECT_EQ(resolveClassMap("semsegmap", tmp.path(), kClassMaps, table).find(4), cls::kBuilding);
  EXPECT_EQ(resolveClassMap("cityscapes", tmp.path(), kClassMaps, table).find(0), cls::kRoad);
  write("name: mine\nclasses:\n  - {id: 7, name: x, class: pole}\n");
  EXPECT_EQ(resolveClassMap("map.yaml", tmp.path(), kClassMaps, table).find(7), cls::kPole);
  EXPECT_TRUE(throwsWith([&] { resolveClassMap("mapillary", tmp.path(), kClassMaps, table); },
                         {"class map 'mapillary': not a shipped class map"}));
}

TEST(SegmentationNetwork, ClassifiesByColourAtThePicturesSize) {
  const Image picture = quadrants(64, 48);
  for (const char* model : {"colour4.onnx", "colour4_half.onnx"}) {  // full and half resolution
    for (int input : {0, 32}) {  // the picture's own size, and a smaller canvas
      SemanticsConfig c = plainConfig(model);
      c.input_width = input;
      c.input_height = input * 3 / 4;
      const Image labels = network(c)->label(picture, "picture");
      ASSERT_EQ(labels.width, 64);
      ASSERT_EQ(labels.height, 48);
      EXPECT_EQ(quadrantClasses(labels), kExpected) << model << " input " << input;
    }
  }
  SemanticsConfig argmax = plainConfig("colour4_argmax.onnx");
  argmax.output = NetworkOutput::kArgmax;
  EXPECT_EQ(quadrantClasses(network(argmax)->label(picture, "picture")), kExpected);
}

TEST(SegmentationNetwork, PreprocessingFollowsTheConfig) {
  const Image picture = quadrants(32, 32);
  SemanticsConfig bgr = plainConfig();
  bgr.bgr = true;  // red arrives in the blue channel
  EXPECT_EQ(quadrantClasses(network(bgr)->label(picture, "p"))[0], cls::kSky);
  // Grey 128: raw, all three channels (0.5) beat the dark logit (0.25), the first wins (red);
  // with the mean 0.5 subtracted they are 0 and dark wins.
  Image grey(8, 8, 3, 128);
  EXPECT_EQ(*network(plainConfig())->label(grey, "p").at(4, 4), cls::kBuilding);
  SemanticsConfig centred = plainConfig();
  centred.mean = {0.5f, 0.5f, 0.5f};
  EXPECT_EQ(*network(centred)->label(grey, "p").at(4, 4), cls::kRoad);
  // Divided by a std of 5, red's 1.0 becomes 0.2, below the dark logit's 0.25.
  SemanticsConfig scaled = plainConfig();
  scaled.std = {5.0f, 5.0f, 5.0f};
  EXPECT_EQ(quadrantClasses(network(scaled)->label(picture, "p"))[0], cls::kRoad);
}

TEST(SegmentationNetwork, LetterboxAndCropMapLabelsBackToThePicture) {
  const Image wide = quadrants(64, 32);
  SemanticsConfig letterbox = plainConfig();
  letterbox.input_width = letterbox.input_height = 32;  // the picture is 2:1, the canvas square
  letterbox.resize = ResizePolicy::kLetterbox;
  const Image boxed = network(letterbox)->label(wide, "p");
  EXPECT_EQ(quadrantClasses(boxed), kExpected);
  SemanticsConfig crop = letterbox;
  crop.resize = ResizePolicy::kCenterCrop;  // scaled to 64x32 (no change), the middle 32 kept
  const Image cropped = network(crop)->label(wide, "p");
  EXPECT_EQ(*cropped.at(2, 8), cls::kUnknown);   // cut off on the left
  EXPECT_EQ(*cropped.at(61, 8), cls::kUnknown);  // and on the right
  EXPECT_EQ(*cropped.at(24, 8), cls::kBuilding);
  EXPECT_EQ(*cropped.at(40, 8), cls::kVegetation);
  EXPECT_EQ(*cropped.at(24, 24), cls::kSky);
}

TEST(SegmentationNetwork, ErrorsComeInOneLineBeforeTheWork) {
  SemanticsConfig c = plainConfig();
  EXPECT_TRUE(throwsWith(
      [&] { SegmentationNetwork(c, std::string("not a model"), colourMap(), "bad.onnx"); },
      {"bad.onnx: not a readable ONNX model"}));
  SemanticsConfig fixed = plainConfig("fixed_input.onnx");
  EXPECT_TRUE(throwsWith([&] { network(fixed)->check(64, 48); },
                         {"fixed_input.onnx: refuses a 1x3x48x64 input", "input_width"}));
  fixed.input_width = fixed.input_height = 8;  // the size it was made for
  const auto ok = network(fixed);
  ok->check(64, 48);
  EXPECT_EQ(ok->outputClasses(), 4);
  EXPECT_TRUE(throwsWith([&] { network(c, colourMap(3))->check(16, 16); },
                         {"network class 3 (of 4) is not in class map colour4"}));
  SemanticsConfig argmax = plainConfig("colour4_argmax.onnx");
  argmax.output = NetworkOutput::kArgmax;
  EXPECT_TRUE(throwsWith([&] { network(argmax, colourMap(3))->label(quadrants(8, 8), "cam0"); },
                         {"cam0: pixel (4, 4) has network class 3"}));
  EXPECT_TRUE(throwsWith([&] { network(c)->check(0, 0); }, {"colour4.onnx"}));
  SemanticsConfig wrong_layout = plainConfig();
  wrong_layout.output = NetworkOutput::kArgmax;  // but the model gives 4 channels of logits
  EXPECT_TRUE(
      throwsWith([&] { network(wrong_layout)->check(8, 8); }, {"1x4x8x8 is not an argmax map"}));
}

Frame twoCameraFrame(double t) {
  Frame f;
  f.timestamp_s = t;
  f.cameras.resize(2);
  for (auto& camera : f.cameras) camera.rgb = quadrants(16, 16);
  f.cameras[1].label = Image(16, 16, 1, cls::kPole);  // the dataset's own labels
  return f;
}

TEST(FrameLabeler, LabelsEveryCameraWithoutLabelsAndKeepsTheDatasets) {
  ReplayLabeler labeler(network(plainConfig()));
  Frame f = twoCameraFrame(0.0);
  labeler.label(f, "frame 0");
  EXPECT_EQ(quadrantClasses(f.cameras[0].label), kExpected);
  EXPECT_EQ(f.cameras[1].label, Image(16, 16, 1, cls::kPole));
  EXPECT_TRUE(f.camera_semantics);
  EXPECT_EQ(labeler.stats().network_runs, 1u);
  EXPECT_EQ(labeler.stats().kept, 1u);
  SemanticsConfig replace = plainConfig();
  replace.replace_dataset_labels = true;
  ReplayLabeler replacing(network(replace));
  Frame g = twoCameraFrame(0.0);
  replacing.label(g, "frame 0");
  EXPECT_EQ(quadrantClasses(g.cameras[1].label), kExpected);
  EXPECT_EQ(replacing.stats().network_runs, 2u);
}

// The robot drives 1 m along x between scans: an earlier picture's labels come with the motion.
Frame movingFrame(double t) {
  Frame f = twoCameraFrame(t);
  f.T_odom_base.translation() = Eigen::Vector3d(10.0 * t, 0.0, 0.0);
  return f;
}

TEST(FrameLabeler, RunsAtItsRateAndCarriesEarlierLabelsByOdometry) {
  SemanticsConfig c = plainConfig();
  c.rate_hz = 5.0;  // every 0.2 s; scans every 0.1 s
  c.tolerance_s = 0.15;
  ReplayLabeler labeler(network(c));
  for (double t : {0.0, 0.1, 0.2, 0.3, 0.4}) {
    Frame f = movingFrame(t);
    labeler.label(f, "frame");
    EXPECT_EQ(quadrantClasses(f.cameras[0].label), kExpected) << t;
    const bool own = t == 0.0 || t == 0.2 || t == 0.4;
    ASSERT_EQ(f.cameras[0].T_label_lidar.has_value(), !own) << t;
    // Labels of the picture 0.1 s before: the LiDAR then was 1 m behind, so a point now is
    // 1 m further ahead of it.
    if (!own) {
      EXPECT_NEAR(f.cameras[0].T_label_lidar->translation().x(), 1.0, 1e-9) << t;
    }
  }
  EXPECT_EQ(labeler.stats().network_runs, 3u);  // 0.0, 0.2, 0.4
  EXPECT_EQ(labeler.stats().reused, 2u);        // 0.1, 0.3
  // Labels older than the tolerance are not taken: that scan gets no classes from the camera.
  c.tolerance_s = 0.05;
  ReplayLabeler strict(network(c));
  for (double t : {0.0, 0.1, 0.2}) {
    Frame f = movingFrame(t);
    strict.label(f, "frame");
    EXPECT_EQ(f.cameras[0].label.empty(), t == 0.1) << t;
    EXPECT_TRUE(f.camera_semantics);
  }
  EXPECT_EQ(strict.stats().network_runs, 2u);
  EXPECT_EQ(strict.stats().unlabelled, 1u);
}

// Two cameras to label at 10 Hz, a network of 40 ms on one thread and a fifth of a core: the
// replay runs it every 0.2 s, alternating cameras, and each scan takes labels only once they
// are done (0.04 s after their picture).
TEST(FrameLabeler, ReplaysTheBudgetOnTheDatasClock) {
  SemanticsConfig c = plainConfig();
  c.budget_cores = 0.2;
  c.latency_s = 0.04;
  c.threads = 1;
  std::vector<std::pair<size_t, double>> runs;  // camera, picture time
  auto record = [&](const Image& rgb, const std::string& what) {
    runs.emplace_back(what.back() - '0', std::stod(what.substr(0, what.find(','))));
    return Image(rgb.width, rgb.height, 1, cls::kRoad);
  };
  ReplayLabeler labeler(c, record);
  std::vector<bool> camera0_labelled;
  for (int i = 0; i <= 100; ++i) {
    Frame f = movingFrame(0.1 * i);
    f.cameras[1].label = Image();  // both cameras need the network
    labeler.label(f, std::to_string(0.1 * i));
    camera0_labelled.push_back(!f.cameras[0].label.empty());
  }
  ASSERT_GE(runs.size(), 4u);
  EXPECT_EQ(runs[0], std::make_pair(size_t{0}, 0.0));
  EXPECT_EQ(runs[1].first, 1u);
  EXPECT_NEAR(runs[1].second, 0.2, 1e-9);
  EXPECT_EQ(runs[2].first, 0u);
  EXPECT_NEAR(runs[2].second, 0.4, 1e-9);
  EXPECT_EQ(runs.size(), 51u);  // every 0.2 s over 10 s
  EXPECT_NEAR(labeler.stats().share(), 0.2, 0.01);
  // Camera 0's labels of t = 0 are done at 0.04: the scan at 0 has none, the one at 0.1 has them.
  EXPECT_FALSE(camera0_labelled[0]);
  EXPECT_TRUE(camera0_labelled[1]);
  SemanticsConfig no_latency = c;  // a budget cannot be replayed without the network's time
  no_latency.latency_s = 0.0;
  EXPECT_THROW(ReplayLabeler(no_latency, record), std::invalid_argument);
  EXPECT_TRUE(throwsWith([&] { checkReplayable(no_latency, "c.yaml"); },
                         {"c.yaml: semantics.budget_cores", "latency_s"}));
}

// On a robot the network runs beside the scans: one slowed down to 0.3 s a picture does not
// slow the scan loop, and its labels reach the scans once done.
TEST(LiveLabeler, ASlowNetworkNeverBlocksTheScans) {
  SemanticsConfig c = plainConfig();
  c.tolerance_s = 100.0;
  std::atomic<int> runs{0};
  auto slow = [&](const Image& rgb, const std::string&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    ++runs;
    return Image(rgb.width, rgb.height, 1, cls::kRoad);
  };
  LiveLabeler labeler(c, slow, Pose::Identity());
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 20; ++i) {
    Frame f = movingFrame(0.1 * i);
    labeler.label(f, "frame");
    EXPECT_TRUE(f.cameras[0].label.empty()) << "labels before the network finished: " << i;
  }
  const double loop_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(loop_s, 0.3) << "the scans waited for the network";
  labeler.waitIdle();
  Frame later = movingFrame(2.0);
  labeler.label(later, "frame");
  ASSERT_FALSE(later.cameras[0].label.empty());
  EXPECT_EQ(*later.cameras[0].label.at(0, 0), cls::kRoad);
  EXPECT_TRUE(later.cameras[0].T_label_lidar.has_value());
  EXPECT_LE(runs.load(), 3);  // it took the newest pictures, not every one
}

// The worker keeps to budget_cores of the wall clock: a network of 20 ms a picture on one
// thread, a quarter of a core, scans every 5 ms for a second.
TEST(LiveLabeler, KeepsToItsShareOfTheCores) {
  SemanticsConfig c = plainConfig();
  c.budget_cores = 0.25;
  c.threads = 1;
  auto work = [](const Image& rgb, const std::string&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    return Image(rgb.width, rgb.height, 1, cls::kRoad);
  };
  LiveLabeler labeler(c, work, Pose::Identity());
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; std::chrono::steady_clock::now() - start < std::chrono::seconds(1); ++i) {
    Frame f = movingFrame(0.005 * i);
    labeler.label(f, "frame");
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const LabelingStats s = labeler.stats();
  EXPECT_LE(s.share(), 0.25 * 1.1) << s.network_runs << " runs in " << s.span_s << " s";
  EXPECT_GE(s.share(), 0.1) << "the worker did not use its budget";
  EXPECT_GE(s.network_runs, 5u);
}

// Frames held in memory: two of a one-camera rig.
class MemorySource : public FrameSource {
 public:
  MemorySource() {
    info_.name = "memory";
    Camera camera;
    camera.name = "cam";
    camera.width = 16;
    camera.height = 16;
    info_.rig.cameras = {camera};
  }
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return 2; }
  Frame frame(size_t index) override {
    Frame f;
    f.index = index;
    f.cameras.resize(1);
    f.cameras[0].rgb = quadrants(16, 16);
    return f;
  }

 private:
  DatasetInfo info_;
};

void writeLabelSet(const fs::path& dir, const std::string& class_map, uint8_t id) {
  LabelSetInfo set;
  set.class_map = class_map;
  set.frames = 2;
  set.cameras = 1;
  writeLabelSetInfo(dir, set);
  fs::create_directories(dir / "cam0");
  for (size_t i = 0; i < 2; ++i) writePng(labelSetImage(dir, 0, i), Image(16, 16, 1, id));
}

TEST(LabelSet, ForeignIdsGoThroughTheirClassMap) {
  TempDir tmp;
  writeLabelSet(tmp.path(), "cityscapes", 0);  // Cityscapes' road
  auto source = withLabelSet(std::make_unique<MemorySource>(), tmp.path(), kClassMaps);
  EXPECT_EQ(source->frame(1).cameras[0].label, Image(16, 16, 1, cls::kRoad));
  writeLabelSet(tmp.path(), "semsegmap", cls::kPole);  // the project's own ids, as label writes
  source = withLabelSet(std::make_unique<MemorySource>(), tmp.path(), kClassMaps);
  EXPECT_EQ(source->frame(0).cameras[0].label, Image(16, 16, 1, cls::kPole));
}

TEST(LabelSet, ErrorsNameTheFile) {
  TempDir tmp;
  const fs::path dir = tmp.path();
  EXPECT_TRUE(throwsWith([&] { withLabelSet(std::make_unique<MemorySource>(), dir, kClassMaps); },
                         {(dir / "labels.yaml").string(), "missing", "class_map"}));
  writeLabelSet(dir, "cityscapes", 19);  // one past Cityscapes' training ids
  auto source = withLabelSet(std::make_unique<MemorySource>(), dir, kClassMaps);
  EXPECT_TRUE(throwsWith([&] { source->frame(0); },
                         {"cam0/000000.png: pixel (0, 0) has class id 19", "cityscapes"}));
  writePng(labelSetImage(dir, 0, 1), Image(8, 16, 1, 0));
  EXPECT_TRUE(throwsWith([&] { source->frame(1); }, {"000001.png: 8x16 labels for a 16x16"}));
  fs::remove(labelSetImage(dir, 0, 1));
  EXPECT_TRUE(throwsWith([&] { source->frame(1); }, {"000001.png: missing"}));
  LabelSetInfo other;
  other.frames = 3;
  other.cameras = 1;
  writeLabelSetInfo(dir, other);
  EXPECT_TRUE(throwsWith([&] { withLabelSet(std::make_unique<MemorySource>(), dir, kClassMaps); },
                         {"labels a dataset of 3 frames, this one has 2"}));
}

// `label --max-frames 1` labels frame 0 of two: the set says so, and serves a run that reads
// frame 0 only; one that reads both is refused up front, naming the set's folder.
TEST(LabelSet, ASetOfFewerFramesServesOnlyRunsThatReadNoMore) {
  TempDir tmp;
  const fs::path dir = tmp.path() / "labels";
  fs::create_directories(dir);
  writeLabelSet(dir, "semsegmap", cls::kPole);
  fs::remove(labelSetImage(dir, 0, 1));
  LabelSetInfo set;
  set.frames = 1;
  set.dataset_frames = 2;
  set.cameras = 1;
  writeLabelSetInfo(dir, set);
  const LabelSetInfo read = readLabelSetInfo(dir);
  EXPECT_EQ(read.frames, 1u);
  EXPECT_EQ(read.dataset_frames, 2u);
  auto source = withLabelSet(std::make_unique<MemorySource>(), dir, kClassMaps, 1);
  EXPECT_EQ(source->frame(0).cameras[0].label, Image(16, 16, 1, cls::kPole));
  EXPECT_TRUE(throwsWith(
      [&] { withLabelSet(std::make_unique<MemorySource>(), dir, kClassMaps); },
      {dir.string() + ": the label set labels frames 0 to 0 only, this run reads 2 frames",
       "--max-frames 1"}));
  set.dataset_frames = 5;  // made from another dataset, though it labels the frames asked for
  writeLabelSetInfo(dir, set);
  EXPECT_TRUE(
      throwsWith([&] { withLabelSet(std::make_unique<MemorySource>(), dir, kClassMaps, 1); },
                 {"labels a dataset of 5 frames, this one has 2"}));
}

TEST(SemanticSources, TheNetworkIsCheckedOnEveryCameraBeforeAnyFrame) {
  SemanticsConfig c = plainConfig();
  c.class_map = (fs::path(SEMSEGMAP_SOURCE_DIR) / "config/class_maps/cityscapes.yaml").string();
  MemorySource memory;
  // colour4 has 4 classes, all in Cityscapes' map (road, sidewalk, building, wall).
  auto net = loadSegmentationNetwork(c, memory.info(), kClassMaps);
  auto source = withSegmentationNetwork(std::make_unique<MemorySource>(), net);
  const Frame f = source->frame(0);
  EXPECT_EQ(*f.cameras[0].label.at(2, 2), cls::kRoad);        // red -> 0 -> road
  EXPECT_EQ(*f.cameras[0].label.at(13, 13), cls::kBuilding);  // dark -> 3 (wall) -> building
  ASSERT_NE(labelerOf(*source), nullptr);
  EXPECT_EQ(labelerOf(*source)->stats().network_runs, 1u);
  SemanticsConfig fixed = plainConfig("fixed_input.onnx");
  fixed.class_map = "cityscapes";
  EXPECT_TRUE(throwsWith([&] { loadSegmentationNetwork(fixed, memory.info(), kClassMaps); },
                         {"refuses a 1x3x16x16 input"}));
  fixed.model = "/nonexistent.onnx";
  EXPECT_TRUE(throwsWith([&] { loadSegmentationNetwork(fixed, memory.info(), kClassMaps); },
                         {"/nonexistent.onnx"}));
}

// The network and LiDAR odometry as stages of the pipeline (what code that embeds it gets) give
// what the frame source that wraps them gives the command line's experiments: the same labels,
// the same poses, the same segments; the caller's frame is left as it was.
TEST(FrontEndStages, APipelineLabelsAndRegistersItsFramesAsAWrappedSourceDoes) {
#if !SEMSEGMAP_WITH_SIM
  GTEST_SKIP() << "needs the simulator (SEMSEGMAP_WITH_SIM=ON)";
#endif
  DatasetOptions options;
  options.odometry = "lidar";
  options.semantics = plainConfig();
  options.semantics.class_map = (kClassMaps / "cityscapes.yaml").string();
  options.semantics.replace_dataset_labels = true;  // the simulator's frames come with labels
  options.class_maps_dir = kClassMaps;
  const std::string spec = "sim:world=1,run=S1,preset=tiny,frames=6";
  auto wrapped = openDataset(spec, options);
  DatasetWithStages own = openDatasetForPipeline(spec, options);
  ASSERT_TRUE(own.stages.network && own.stages.lidar_odometry);
  const PipelineConfig config;
  Pipeline by_source(config, wrapped->info(), PoseSource::kOdometry);
  Pipeline by_stages(config, own.source->info(), PoseSource::kOdometry, nullptr, own.stages);
  size_t relabelled = 0;
  for (size_t i = 0; i < wrapped->size(); ++i) {
    const Frame a = wrapped->frame(i), b = own.source->frame(i);
    const FrameResult ra = by_source.process(a), rb = by_stages.process(b);
    EXPECT_EQ(ra.T_local_base.matrix(), rb.T_local_base.matrix()) << "frame " << i;
    EXPECT_EQ(ra.colored_points, rb.colored_points);
    EXPECT_EQ(ra.segmentation.observed, rb.segmentation.observed);
    const Frame& labelled = by_stages.processedFrame(b);
    for (size_t k = 0; k < a.cameras.size(); ++k) {
      EXPECT_EQ(labelled.cameras[k].label.data, a.cameras[k].label.data) << i << " camera " << k;
      relabelled += b.cameras[k].label.data != labelled.cameras[k].label.data;
    }
  }
  EXPECT_GT(relabelled, 0u) << "the caller's frames kept the simulator's labels";
  ASSERT_TRUE(by_stages.labeling().has_value());
  EXPECT_EQ(by_stages.labeling()->network_runs,
            wrapped->size() * wrapped->info().rig.cameras.size());
}

// `train --config` with a semantics: section: the training runs are cut and described with the
// network's classes instead of the simulator's. colour4 read through the Cityscapes map gives
// four classes only, so no observation of its extraction holds a pole, a trunk or a tree.
TEST(TrainingExtraction, TheNetworkOfTheOptionsLabelsTheTrainingRuns) {
#if !SEMSEGMAP_WITH_SIM
  GTEST_SKIP() << "needs the simulator (SEMSEGMAP_WITH_SIM=ON)";
#endif
  DatasetOptions options;
  options.semantics = plainConfig();
  options.semantics.class_map = (kClassMaps / "cityscapes.yaml").string();
  options.semantics.replace_dataset_labels = true;
  options.class_maps_dir = kClassMaps;
  const ClassMap map = readClassMap(options.semantics.class_map, ClassTable::Default());
  std::set<ClassId> network_classes = {cls::kUnknown};
  for (int c = 0; c < 4; ++c) network_classes.insert(*map.find(c));
  const std::vector<std::string> spec = {"sim:world=1,run=S1,preset=tiny,frames=12"};
  ExtractionConfig extraction;
  extraction.min_purity = 0.0f;
  const TrainingSet perfect = extractTrainingSet(spec, PipelineConfig{}, extraction);
  const TrainingSet labelled = extractTrainingSet(spec, PipelineConfig{}, extraction, {}, options);
  auto classesOf = [](const TrainingSet& set) {
    std::set<ClassId> seen;
    for (const TrainingObservation& o : set.observations)
      seen.insert(o.classes.begin(), o.classes.end());
    return seen;
  };
  const std::set<ClassId> with_perfect = classesOf(perfect), with_network = classesOf(labelled);
  ASSERT_FALSE(labelled.observations.empty());
  EXPECT_TRUE(with_perfect.count(cls::kVegetation) || with_perfect.count(cls::kPole) ||
              with_perfect.count(cls::kTrunk))
      << "the simulator's labels of the run hold no thin objects or trees";
  for (const ClassId c : with_network)
    EXPECT_TRUE(network_classes.count(c)) << "class " << int(c) << " came from no network output";
  EXPECT_GT(with_network.size(), 1u) << "no point took a network class";
}

TEST(SemanticsConfig, ReadFromTheConfigRelativeToIt) {
  TempDir tmp;
  const fs::path file = tmp.path() / "c.yaml";
  std::ofstream(file) << "semantics:\n  model: nets/seg.onnx\n  class_map: maps/m.yaml\n"
                         "  input_width: 1024\n  input_height: 512\n  resize: letterbox\n"
                         "  mean: [0.5, 0.5, 0.5]\n  channel_order: bgr\n  output: argmax\n"
                         "  rate_hz: 2\n";
  const SemanticsConfig c = loadSemanticsConfig(file);
  EXPECT_EQ(c.model, (tmp.path() / "nets/seg.onnx").string());
  EXPECT_EQ(c.class_map, (tmp.path() / "maps/m.yaml").string());
  EXPECT_EQ(c.input_width, 1024);
  EXPECT_EQ(c.resize, ResizePolicy::kLetterbox);
  EXPECT_EQ(c.mean[1], 0.5f);
  EXPECT_FLOAT_EQ(c.std[0], 0.229f);
  EXPECT_TRUE(c.bgr);
  EXPECT_EQ(c.output, NetworkOutput::kArgmax);
  EXPECT_EQ(c.rate_hz, 2.0);
  std::ofstream(file) << "semantics:\n  class_map: ade20k\n";
  EXPECT_EQ(loadSemanticsConfig(file).class_map, "ade20k");  // a shipped name stays a name
  EXPECT_TRUE(loadSemanticsConfig(file).model.empty());
  std::ofstream(file) << "semantics:\n  resize: squash\n";
  EXPECT_TRUE(throwsWith([&] { loadSemanticsConfig(file); }, {"semantics.resize: expected"}));
  std::ofstream(file) << "semantics:\n  std: [1, 0, 1]\n";
  EXPECT_TRUE(throwsWith([&] { loadSemanticsConfig(file); }, {"semantics.std: must be positive"}));
  std::ofstream(file) << "semantics:\n  input_width: 64\n";
  EXPECT_TRUE(throwsWith([&] { loadPipelineConfig(file); }, {"input_width, input_height"}));
}

// A shipped config copied elsewhere (as a user starts their own) loses its ../models/: its
// models are then found by name among the shipped ones, and a model of the user's own that is
// missing keeps its path beside the config, for the model's loader to refuse by that name.
TEST(PipelineConfigFile, ACopiedConfigStillFindsItsShippedModels) {
  TempDir tmp;
  const fs::path source = fs::path(SEMSEGMAP_SOURCE_DIR);
  const fs::path copy = tmp.path() / "my-rig.yaml";
  fs::copy_file(source / "config" / "lidar-camera.yaml", copy);
  const PipelineConfig c = loadPipelineConfig(copy);
  ASSERT_TRUE(fs::exists(c.descriptor.model)) << c.descriptor.model;
  EXPECT_TRUE(
      fs::equivalent(c.descriptor.model, source / "models" / "semsegmap-net-3worlds.model"));
  EXPECT_TRUE(
      fs::equivalent(c.descriptor.model_lidar_only, source / "models" / "semsegmap-net.model"));
  // In place, the path beside the config is the one used.
  const PipelineConfig shipped = loadPipelineConfig(source / "config" / "lidar-camera.yaml");
  EXPECT_EQ(
      shipped.descriptor.model,
      (source / "config" / "../models/semsegmap-net-3worlds.model").lexically_normal().string());
  std::ofstream(copy) << "descriptor:\n  kind: semsegmap-net\n  model: mine/net.model\n";
  EXPECT_EQ(loadPipelineConfig(copy).descriptor.model, (tmp.path() / "mine/net.model").string());
}

}  // namespace
}  // namespace semsegmap
