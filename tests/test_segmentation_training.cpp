// The project's camera segmentation network: its training (learn/segmentation_trainer.h), its
// ONNX export against libtorch through OpenCV's DNN module, the shipped model on a simulator
// picture, the pixel scores of `eval labels`, and train-segmentation's one-line errors.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <opencv2/dnn.hpp>

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "command_result.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/eval/label_eval.h"
#include "semsegmap/learn/onnx_writer.h"
#include "semsegmap/learn/segmentation_trainer.h"
#include "semsegmap/settings/class_map_file.h"
#include "semsegmap/settings/config.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

const std::filesystem::path kSource = SEMSEGMAP_SOURCE_DIR;

// A few pictures of the tiny world 2 (never the evaluation world 1), shrunk to w x h.
std::vector<LabelledPicture> tinyWorldPictures(int w, int h, size_t frames) {
  auto source = openDataset("sim:world=2,run=S0,preset=tiny,frames=" + std::to_string(frames));
  std::vector<LabelledPicture> out;
  for (size_t i = 0; i < source->size(); ++i)
    for (const CameraFrame& cam : source->frame(i).cameras)
      out.push_back({shrinkPicture(cam.rgb, w, h), shrinkLabels(cam.label, w, h)});
  return out;
}

SegTrainConfig tinyConfig() {
  SegTrainConfig c;
  c.input_width = 64, c.input_height = 48;
  c.crop_width = 48, c.crop_height = 32;
  c.batch_size = 4;
  c.validation_fraction = 0.0;
  c.threads = 2;
  return c;
}

TEST(SegmentationTraining, ShrinksPicturesByAreaAndLabelsByNearest) {
  Image rgb(4, 2, 3), label(4, 2, 1);
  for (int x = 0; x < 4; ++x)
    for (int y = 0; y < 2; ++y) {
      rgb.at(x, y)[0] = static_cast<uint8_t>(x * 10 + y * 100);
      *label.at(x, y) = static_cast<uint8_t>(x);
    }
  const Image small = shrinkPicture(rgb, 2, 1), labels = shrinkLabels(label, 2, 1);
  EXPECT_EQ(small.at(0, 0)[0], 55);  // (0 + 10 + 100 + 110) / 4
  EXPECT_EQ(small.at(1, 0)[0], 75);
  EXPECT_EQ(*labels.at(0, 0), 1);  // the pixel at the centre of (0..1)
  EXPECT_EQ(*labels.at(1, 0), 3);
  EXPECT_THROW(shrinkPicture(rgb, 8, 2), std::invalid_argument);
}

TEST(SegmentationTraining, StepsLowerTheLoss) {
  const std::vector<LabelledPicture> pictures = tinyWorldPictures(64, 48, 2);
  SegTrainConfig c = tinyConfig();
  c.epochs = 8;  // 16 steps of 4 crops
  const SegTrainResult r = trainSegmentation(pictures, c);
  ASSERT_EQ(r.history.size(), 8u);
  EXPECT_LT(r.history.back().loss, 0.8 * r.history.front().loss)
      << r.history.front().loss << " -> " << r.history.back().loss;
  EXPECT_GT(r.class_weights[cls::kPole], r.class_weights[cls::kRoad]);  // thin classes weigh more
  EXPECT_EQ(r.class_weights[cls::kUnknown], 0.0);
}

TEST(SegmentationTraining, RejectsPicturesOfAnotherSize) {
  std::vector<LabelledPicture> pictures = {{Image(32, 48, 3), Image(32, 48, 1)}};
  EXPECT_THROW(trainSegmentation(pictures, tinyConfig()), std::invalid_argument);
  EXPECT_THROW(trainSegmentation({}, tinyConfig()), std::invalid_argument);
}

// OpenCV's blob of a picture, normalised as training does.
cv::Mat normalisedBlob(const Image& rgb, const SegTrainConfig& c) {
  const int sizes[] = {1, 3, rgb.height, rgb.width};
  cv::Mat blob(4, sizes, CV_32F);
  float* p = blob.ptr<float>();
  const size_t plane = static_cast<size_t>(rgb.width) * rgb.height;
  for (int y = 0; y < rgb.height; ++y)
    for (int x = 0; x < rgb.width; ++x)
      for (int k = 0; k < 3; ++k)
        p[k * plane + static_cast<size_t>(y) * rgb.width + x] =
            (rgb.at(x, y)[k] / 255.f - c.mean[k]) / c.std[k];
  return blob;
}

TEST(SegmentationTraining, OnnxExportMatchesLibtorchInOpenCv) {
  const std::vector<LabelledPicture> pictures = tinyWorldPictures(64, 48, 1);
  SegTrainConfig c = tinyConfig();
  c.epochs = 2;  // a few steps: the batch norms' running statistics are not the initial ones
  const SegTrainResult r = trainSegmentation(pictures, c);
  cv::dnn::Net net = cv::dnn::readNetFromONNX(r.onnx.data(), r.onnx.size());
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  for (const Image& rgb : {pictures[0].rgb, shrinkPicture(pictures[1].rgb, 40, 32)}) {
    net.setInput(normalisedBlob(rgb, c));
    const cv::Mat out = net.forward();
    int h = 0, w = 0;
    const std::vector<float> expected = r.torch_logits(rgb, h, w);
    ASSERT_EQ(out.dims, 4);
    ASSERT_EQ(out.size[1], kSegmentationClasses);
    ASSERT_EQ(out.size[2], h);
    ASSERT_EQ(out.size[3], w);
    ASSERT_EQ(out.total(), expected.size());
    double worst = 0, largest = 0;
    for (size_t i = 0; i < expected.size(); ++i) {
      worst = std::max(worst, std::abs(static_cast<double>(out.ptr<float>()[i]) - expected[i]));
      largest = std::max(largest, std::abs(static_cast<double>(expected[i])));
    }
    EXPECT_LT(worst, 1e-4 * std::max(1.0, largest)) << "largest logit " << largest;
  }
}

// A graph of every operator the writer has, with weights whose output is known: channel 0 is
// relu(2 r - 1) upsampled, channel 1 is g + b; both then doubled by adding the concatenation's
// halves.
TEST(OnnxWriter, WritesAGraphOpenCvRunsAsWritten) {
  test_support::TempDir dir;
  OnnxGraph g;
  OnnxConv c;
  c.in_channels = 3, c.out_channels = 2;
  c.weight = {2, 0, 0, 0, 1, 1};
  c.bias = {-1, 0};
  const std::string up = g.upsample2(g.relu(g.conv(g.input(), c)));
  const std::string both = g.concat({up, up});
  OnnxConv halves;  // 4 -> 2 channels: a + c, b + d
  halves.in_channels = 4, halves.out_channels = 2;
  halves.weight = {1, 0, 1, 0, 0, 1, 0, 1};
  halves.bias = {0, 0};
  const std::string out = g.add(g.conv(both, halves), g.conv(both, halves));
  EXPECT_THROW(g.conv(out, OnnxConv{}), std::invalid_argument);
  const std::filesystem::path file = dir.path() / "graph.onnx";
  g.write(file, out, 2, "test");
  cv::dnn::Net net = cv::dnn::readNetFromONNX(file.string());
  const int sizes[] = {1, 3, 2, 2};
  cv::Mat in(4, sizes, CV_32F, cv::Scalar(0.75f));
  net.setInput(in);
  const cv::Mat o = net.forward();
  ASSERT_EQ(o.size[2], 4);
  ASSERT_EQ(o.size[3], 4);
  EXPECT_NEAR(o.ptr<float>()[0], 4 * 0.5f, 1e-5);   // 2 * 2 * relu(2 * 0.75 - 1)
  EXPECT_NEAR(o.ptr<float>()[16], 4 * 1.5f, 1e-5);  // 2 * 2 * (0.75 + 0.75)
}

TEST(SegmentationTraining, ShippedClassMapIsTheIdentity) {
  const ClassTable table = ClassTable::Default();
  const ClassMap file = readClassMap(kSource / "config/class_maps/semsegmap.yaml", table);
  for (int id = 0; id <= cls::kSky; ++id) EXPECT_EQ(file.find(id), std::optional<ClassId>(id));
}

TEST(LabelScores, CountsIouAndAccuracyLeavingUnknownOut) {
  Image truth(4, 1, 1), predicted(4, 1, 1);
  truth.data = {cls::kRoad, cls::kRoad, cls::kSky, cls::kUnknown};
  predicted.data = {cls::kRoad, cls::kSky, cls::kSky, cls::kCar};
  LabelScores s;
  s.add(truth, predicted);
  EXPECT_EQ(s.labelledPixels(), 3u);
  EXPECT_DOUBLE_EQ(s.pixelAccuracy(), 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(s.iou(cls::kRoad), 0.5);
  EXPECT_DOUBLE_EQ(s.iou(cls::kSky), 0.5);
  EXPECT_DOUBLE_EQ(s.iou(cls::kCar), -1.0);  // predicted only where the truth is unknown
  EXPECT_DOUBLE_EQ(s.meanIou(true), 0.5);
  EXPECT_DOUBLE_EQ(s.meanIou(false), 0.5);
  EXPECT_THROW(s.add(truth, Image(3, 1, 1)), std::invalid_argument);
}

// The shipped network through the semantics stage, as config/semantics-sim-network.yaml sets it
// up, on a picture of the tiny evaluation world: mostly right, and the large classes found.
TEST(ShippedSegmentationNetwork, LabelsASimulatorPicture) {
  const SemanticsConfig config = loadSemanticsConfig(kSource / "config/semantics-sim-network.yaml");
  ASSERT_TRUE(std::filesystem::exists(config.model)) << config.model;
  const ClassTable table = ClassTable::Default();
  SegmentationNetwork network(
      config, readFileBytes(config.model),
      resolveClassMap(config.class_map, kSource / "config", kSource / "config/class_maps", table),
      config.model);
  auto source = openDataset("sim:world=1,run=S2,preset=tiny,frames=2");
  LabelScores scores;
  for (const CameraFrame& cam : source->frame(1).cameras)
    scores.add(cam.label, network.label(cam.rgb, "test picture"));
  EXPECT_EQ(network.outputClasses(), kSegmentationClasses);
  EXPECT_GT(scores.pixelAccuracy(), 0.8);
  for (ClassId c : {cls::kRoad, cls::kSky, cls::kBuilding}) {
    ASSERT_GT(scores.truthPixels(c), 1000u) << table.at(c).name;
    EXPECT_GT(scores.iou(c), 0.5) << table.at(c).name;
  }
}

test_support::Result runBinary(const std::string& args) {
  test_support::TempDir dir;
  const std::filesystem::path out = dir.path() / "out", err = dir.path() / "err";
  const std::string command = std::string("'") + SEMSEGMAP_BINARY + "' " + args + " > '" +
                              out.string() + "' 2> '" + err.string() + "' < /dev/null";
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, test_support::readFile(out),
          test_support::readFile(err)};
}

TEST(TrainSegmentationCli, SaysWhatIsWrongInOneLine) {
  const test_support::Result no_out =
      runBinary("train-segmentation --dataset sim:world=2,preset=tiny,frames=1");
  EXPECT_EQ(no_out.code, 2);
  EXPECT_NE(no_out.err.find("--out"), std::string::npos) << no_out.err;
  const test_support::Result bad_input = runBinary(
      "train-segmentation --dataset sim:world=2,preset=tiny,frames=1 --out x.onnx --input 100x7");
  EXPECT_EQ(bad_input.code, 2);
  EXPECT_NE(bad_input.err.find("--input"), std::string::npos) << bad_input.err;
  // A recording without label images (its pictures only): refused naming the dataset.
  test_support::TempDir dir;
  const std::string data = (dir.path() / "run").string();
  ASSERT_EQ(
      runBinary("simulate --world tiny --world-seed 2 --run S0 --max-frames 1 --out " + data).code,
      0);
  for (int k = 0; k < 3; ++k)
    for (const auto& f :
         std::filesystem::directory_iterator(data + "/cam" + std::to_string(k) + "_label"))
      std::filesystem::remove(f.path());
  const test_support::Result no_labels =
      runBinary("train-segmentation --dataset " + data + " --out " + data + "/x.onnx");
  EXPECT_EQ(no_labels.code, 1);
  EXPECT_NE(no_labels.err.find(data), std::string::npos) << no_labels.err;
  EXPECT_NE(no_labels.err.find("label"), std::string::npos) << no_labels.err;
  EXPECT_LE(std::count(no_labels.err.begin(), no_labels.err.end(), '\n'), 2) << no_labels.err;
  EXPECT_FALSE(std::filesystem::exists(data + "/x.onnx"));
}

}  // namespace
}  // namespace semsegmap
