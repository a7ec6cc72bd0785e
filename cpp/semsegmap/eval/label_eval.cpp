#include "semsegmap/eval/label_eval.h"

#include <chrono>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/datasets/semantic_sources.h"

namespace semsegmap {

void LabelScores::add(const Image& truth, const Image& predicted) {
  if (truth.channels != 1 || predicted.channels != 1 || truth.width != predicted.width ||
      truth.height != predicted.height)
    throw std::invalid_argument("label images of " + std::to_string(truth.width) + "x" +
                                std::to_string(truth.height) + " and " +
                                std::to_string(predicted.width) + "x" +
                                std::to_string(predicted.height) + " cannot be compared");
  // Counted densely over the picture's 8-bit ids first, then folded into the sparse matrix.
  std::vector<size_t> counts(256 * 256, 0);
  for (size_t i = 0; i < truth.data.size(); ++i)
    if (truth.data[i] != cls::kUnknown) ++counts[truth.data[i] * 256 + predicted.data[i]];
  for (size_t k = 0; k < counts.size(); ++k)
    confusion_.add(static_cast<ClassId>(k / 256), static_cast<ClassId>(k % 256), counts[k]);
}

LabelScores& LabelScores::operator+=(const LabelScores& o) {
  confusion_ += o.confusion_;
  return *this;
}

size_t LabelScores::truthPixels(ClassId c) const {
  return confusion_.truthCount(c);
}

size_t LabelScores::labelledPixels() const {
  return confusion_.total();
}

double LabelScores::pixelAccuracy() const {
  const size_t all = labelledPixels();
  return all ? static_cast<double>(confusion_.correct()) / static_cast<double>(all) : 0.0;
}

double LabelScores::iou(ClassId c) const {
  return confusion_.iou(c);
}

std::vector<ClassId> LabelScores::truthClasses(bool with_sky) const {
  std::vector<ClassId> out;
  for (int c = 1; c < 256; ++c)
    if (truthPixels(static_cast<ClassId>(c)) > 0 && (with_sky || c != cls::kSky))
      out.push_back(static_cast<ClassId>(c));
  return out;
}

double LabelScores::meanIou(bool with_sky) const {
  const std::vector<ClassId> classes = truthClasses(with_sky);
  double sum = 0;
  for (ClassId c : classes) sum += iou(c);
  return classes.empty() ? 0.0 : sum / classes.size();
}

namespace {

// The frames' pictures that go into the sheet: `wanted` spread evenly over what is read.
bool isExample(size_t picture, size_t pictures, size_t wanted) {
  if (wanted == 0 || pictures == 0) return false;
  const size_t step = std::max<size_t>(1, pictures / wanted);
  return picture % step == step / 2 && picture / step < wanted;
}

void evaluateDataset(const std::string& spec, const LabelEvalConfig& c, size_t examples,
                     const LabelEvalProgress& progress, LabelEvaluation& e) {
  const std::unique_ptr<FrameSource> source = openDataset(spec);
  const DatasetInfo& info = source->info();
  if (info.rig.cameras.empty()) throw std::runtime_error(spec + ": no cameras to label");
  const auto network = loadSegmentationNetwork(c.semantics, info, c.class_maps_dir);
  const size_t frames = framesToRead(*source, c.max_frames);
  const size_t every = std::max<size_t>(1, c.every), total = (frames + every - 1) / every;
  LabelEvalDataset d{spec, 0, {}};
  for (size_t i = 0, n = 0; i < frames; i += every, ++n) {
    if (c.stop.stopRequested()) {
      e.interrupted = true;
      break;
    }
    const Frame frame = source->frame(i);
    for (size_t k = 0; k < frame.cameras.size(); ++k) {
      const CameraFrame& cam = frame.cameras[k];
      const std::string what =
          spec + " frame " + std::to_string(frame.index) + " camera " + info.rig.cameras[k].name;
      if (cam.rgb.empty() || cam.label.empty())
        throw std::runtime_error(what + ": no " +
                                 (cam.rgb.empty() ? "picture" : "label image to compare with"));
      const auto start = std::chrono::steady_clock::now();
      const Image predicted = network->label(cam.rgb, what);
      e.network_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      d.scores.add(cam.label, predicted);
      if (isExample(n * frame.cameras.size() + k, total * frame.cameras.size(), examples))
        e.examples.push_back({what, cam.rgb, cam.label, predicted});
      ++d.pictures;
    }
    if (progress) progress(spec, n + 1, total);
  }
  e.pictures += d.pictures;
  e.datasets.push_back(std::move(d));
}

}  // namespace

LabelEvaluation evaluateLabels(const std::vector<std::string>& specs, const LabelEvalConfig& config,
                               const LabelEvalProgress& progress) {
  LabelEvaluation e;
  e.model = config.semantics.model;
  for (size_t s = 0; s < specs.size() && !e.interrupted; ++s) {
    // The examples spread over the datasets: a share of them each.
    const size_t examples =
        (config.examples * (s + 1)) / specs.size() - config.examples * s / specs.size();
    evaluateDataset(specs[s], config, examples, progress, e);
  }
  for (const LabelEvalDataset& d : e.datasets) e.scores += d.scores;
  return e;
}

namespace {

nlohmann::ordered_json scoresJson(const LabelScores& s, const ClassTable& classes,
                                  size_t pictures) {
  nlohmann::ordered_json j;
  j["pictures"] = pictures;
  j["miou"] = s.meanIou(true);
  j["miou_without_sky"] = s.meanIou(false);
  j["pixel_accuracy"] = s.pixelAccuracy();
  nlohmann::ordered_json per_class = nlohmann::ordered_json::object();
  for (const SemanticClass& c : classes.classes()) {
    if (c.id == cls::kUnknown || s.truthPixels(c.id) == 0) continue;
    per_class[c.name] = {{"iou", s.iou(c.id)}, {"truth_pixels", s.truthPixels(c.id)}};
  }
  j["classes"] = per_class;
  return j;
}

}  // namespace

nlohmann::ordered_json toJson(const LabelEvaluation& e) {
  nlohmann::ordered_json j;
  j["model"] = e.model;
  j["miou_classes"] =
      "every class with ground-truth pixels but unknown (sky included); miou_without_sky leaves "
      "sky out";
  j["resolution"] = "the cameras' own (the labels upsampled from the network's output)";
  j["ms_per_picture"] = e.pictures ? 1000.0 * e.network_seconds / e.pictures : 0.0;
  j["all"] = scoresJson(e.scores, e.classes, e.pictures);
  nlohmann::ordered_json datasets = nlohmann::ordered_json::array();
  for (const LabelEvalDataset& d : e.datasets) {
    nlohmann::ordered_json dj = scoresJson(d.scores, e.classes, d.pictures);
    dj["dataset"] = d.spec;
    datasets.push_back(dj);
  }
  j["datasets"] = datasets;
  j["interrupted"] = e.interrupted;
  return j;
}

std::string labelsTable(const LabelEvaluation& e) {
  std::ostringstream out;
  char line[160];
  std::snprintf(line, sizeof line, "%-14s", "class");
  out << line;
  for (size_t d = 0; d < e.datasets.size(); ++d) out << "  dataset " << d + 1;
  out << "        all\n";
  for (const SemanticClass& c : e.classes.classes()) {
    if (c.id == cls::kUnknown || e.scores.truthPixels(c.id) == 0) continue;
    std::snprintf(line, sizeof line, "%-14s", c.name.c_str());
    out << line;
    for (const LabelEvalDataset& d : e.datasets) {
      std::snprintf(line, sizeof line, "  %9.3f", d.scores.iou(c.id));
      out << line;
    }
    std::snprintf(line, sizeof line, "  %9.3f\n", e.scores.iou(c.id));
    out << line;
  }
  auto row = [&](const char* name, auto value) {
    std::snprintf(line, sizeof line, "%-14s", name);
    out << line;
    for (const LabelEvalDataset& d : e.datasets) {
      std::snprintf(line, sizeof line, "  %9.3f", value(d.scores));
      out << line;
    }
    std::snprintf(line, sizeof line, "  %9.3f\n", value(e.scores));
    out << line;
  };
  row("mIoU", [](const LabelScores& s) { return s.meanIou(true); });
  row("mIoU no sky", [](const LabelScores& s) { return s.meanIou(false); });
  row("pixel acc.", [](const LabelScores& s) { return s.pixelAccuracy(); });
  for (size_t d = 0; d < e.datasets.size(); ++d)
    out << "dataset " << d + 1 << ": " << e.datasets[d].spec << " (" << e.datasets[d].pictures
        << " pictures)\n";
  std::snprintf(line, sizeof line, "%.1f ms per picture (network, %zu pictures)\n",
                e.pictures ? 1000.0 * e.network_seconds / e.pictures : 0.0, e.pictures);
  out << line;
  return out.str();
}

}  // namespace semsegmap
