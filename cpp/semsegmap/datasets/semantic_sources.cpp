#include "semsegmap/datasets/semantic_sources.h"

#include <stdexcept>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/io/label_set.h"
#include "semsegmap/settings/class_map_file.h"

namespace semsegmap {

namespace {

// A source that passes frames through and changes their label images.
// `labels` says where the label images come from now (DatasetOrigin::label_images).
class RelabelledSource : public FrameSource {
 public:
  RelabelledSource(std::unique_ptr<FrameSource> source, const std::string& labels)
      : source_(std::move(source)), info_(source_->info()) {
    info_.origin.label_images = labels;
  }
  const DatasetInfo& info() const override { return info_; }
  size_t size() const override { return source_->size(); }
  double frameTime(size_t index) override { return source_->frameTime(index); }
  std::optional<size_t> frameNumber(size_t index) override { return source_->frameNumber(index); }

 protected:
  std::unique_ptr<FrameSource> source_;
  DatasetInfo info_;
};

class LabelSetSource : public RelabelledSource {
 public:
  LabelSetSource(std::unique_ptr<FrameSource> source, std::filesystem::path dir, ClassMap map)
      : RelabelledSource(std::move(source), "label set " + dir.string()),
        dir_(std::move(dir)),
        map_(std::move(map)) {}

  Frame frame(size_t index) override {
    Frame f = source_->frame(index);
    for (size_t k = 0; k < f.cameras.size(); ++k) {
      CameraFrame& camera = f.cameras[k];
      if (camera.rgb.empty()) continue;
      const std::filesystem::path path = labelSetImage(dir_, k, index);
      if (!std::filesystem::exists(path))
        throw std::runtime_error(path.string() +
                                 ": missing: the label set has no labels for "
                                 "camera " +
                                 std::to_string(k) + "'s picture of frame " +
                                 std::to_string(index));
      const Image labels = readPng(path);
      if (labels.width != camera.rgb.width || labels.height != camera.rgb.height)
        throw std::runtime_error(path.string() + ": " + std::to_string(labels.width) + "x" +
                                 std::to_string(labels.height) + " labels for a " +
                                 std::to_string(camera.rgb.width) + "x" +
                                 std::to_string(camera.rgb.height) + " picture");
      camera.label = mapLabelImage(labels, map_, path.string());
    }
    return f;
  }

 private:
  std::filesystem::path dir_;
  ClassMap map_;
};

class NetworkSource : public RelabelledSource {
 public:
  NetworkSource(std::unique_ptr<FrameSource> source, std::shared_ptr<SegmentationNetwork> network)
      : RelabelledSource(std::move(source), "the semantics: network"),
        labeler_(std::move(network), source_->info().rig.T_base_lidar) {
    // The network labels the pictures that have no label image of their own.
    const std::string& own = source_->info().origin.label_images;
    if (!own.empty()) info_.origin.label_images = own + ", else the semantics: network";
  }

  Frame frame(size_t index) override {
    Frame f = source_->frame(index);
    labeler_.label(f, "frame " + std::to_string(index));
    return f;
  }
  const FrameLabeler& labeler() const { return labeler_; }

 private:
  ReplayLabeler labeler_;
};

}  // namespace

namespace {

// A set made from another dataset, or one that lacks frames the run reads, is refused before
// the run: it would fail at its first unlabelled frame, or label frames with another's pictures.
void checkLabelSetFrames(const LabelSetInfo& set, const std::filesystem::path& dir,
                         size_t dataset_frames, size_t frames_needed) {
  const std::string yaml = (dir / "labels.yaml").string();
  // Older sets record no dataset_frames: they can only be checked to fit.
  const bool other_dataset =
      set.dataset_frames > 0 ? set.dataset_frames != dataset_frames : set.frames > dataset_frames;
  if (other_dataset)
    throw std::runtime_error(
        yaml + ": labels a dataset of " +
        std::to_string(set.dataset_frames > 0 ? set.dataset_frames : set.frames) +
        " frames, this one has " + std::to_string(dataset_frames));
  if (set.frames < frames_needed)
    throw std::runtime_error(dir.string() + ": the label set labels frames 0 to " +
                             std::to_string(set.frames - 1) + " only, this run reads " +
                             std::to_string(frames_needed) + " frames (label them all, or give " +
                             optionText("max-frames", std::to_string(set.frames)) + ")" +
                             (set.interrupted ? "; its labelling was interrupted" : ""));
}

}  // namespace

std::unique_ptr<FrameSource> withLabelSet(std::unique_ptr<FrameSource> source,
                                          const std::filesystem::path& dir,
                                          const std::filesystem::path& class_maps_dir,
                                          size_t max_frames) {
  const LabelSetInfo set = readLabelSetInfo(dir);
  const std::string yaml = (dir / "labels.yaml").string();
  checkLabelSetFrames(set, dir, source->size(), framesToRead(*source, max_frames));
  const size_t cameras = source->info().rig.cameras.size();
  if (set.cameras != cameras)
    throw std::runtime_error(yaml + ": labels " + std::to_string(set.cameras) +
                             " cameras, the dataset's rig has " + std::to_string(cameras));
  ClassMap map;
  try {
    map = resolveClassMap(set.class_map, dir, class_maps_dir, source->info().classes);
  } catch (const std::exception& e) {
    throw std::runtime_error(yaml + ": class_map: " + e.what());
  }
  return std::make_unique<LabelSetSource>(std::move(source), dir, std::move(map));
}

std::shared_ptr<SegmentationNetwork> loadSegmentationNetwork(
    const SemanticsConfig& config, const DatasetInfo& info,
    const std::filesystem::path& class_maps_dir) {
  ClassMap map = resolveClassMap(config.class_map, std::filesystem::current_path(), class_maps_dir,
                                 info.classes);
  auto network = std::make_shared<SegmentationNetwork>(config, readFileBytes(config.model),
                                                       std::move(map), config.model);
  for (const Camera& camera : info.rig.cameras) network->check(camera.width, camera.height);
  return network;
}

std::unique_ptr<FrameSource> withSegmentationNetwork(std::unique_ptr<FrameSource> source,
                                                     std::shared_ptr<SegmentationNetwork> network) {
  return std::make_unique<NetworkSource>(std::move(source), std::move(network));
}

const FrameLabeler* labelerOf(const FrameSource& source) {
  const auto* s = dynamic_cast<const NetworkSource*>(&source);
  return s ? &s->labeler() : nullptr;
}

}  // namespace semsegmap
