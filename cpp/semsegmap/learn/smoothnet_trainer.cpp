#include "semsegmap/learn/smoothnet_trainer.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <optional>
#include <stdexcept>

#include <opencv2/core.hpp>

#include "semsegmap/describe/smoothnet_input.h"
#include "semsegmap/learn/training_state.h"

namespace semsegmap {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

void checkSmoothNetConfig(const SmoothNetTrainConfig& c) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("training: " + what); };
  if (c.net.kind != DescriptorKind::kSmoothNetBow) fail("the config is not a 3dsmoothnet one");
  validateNetConfig(c.net);
  if (c.epochs < 1) fail("epochs must be at least 1");
  if (c.steps_per_epoch < 1) fail("steps per epoch must be at least 1");
  if (c.batch_pairs < 2) fail("a batch needs at least 2 pairs (the others are its negatives)");
  if (!(c.learning_rate > 0)) fail("learning rate must be positive");
  if (!(c.correspondence_m > 0)) fail("the correspondence distance must be positive");
  if (c.threads < 1) fail("threads must be at least 1");
  if (!(c.validation_fraction >= 0 && c.validation_fraction < 1))
    fail("validation fraction must be in [0, 1)");
}

std::vector<Eigen::Vector3f> positionsOf(const TrainingObservation& o) {
  std::vector<Eigen::Vector3f> out(o.size());
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = Eigen::Vector3f(o.xyzhsv[6 * i], o.xyzhsv[6 * i + 1], o.xyzhsv[6 * i + 2]);
  return out;
}

// One keypoint of an observation and its counterpart in another observation of the same object,
// with the points of both (map frame), which their grids are made of.
struct KeypointPair {
  Eigen::Vector3f a = Eigen::Vector3f::Zero(), p = Eigen::Vector3f::Zero();
  std::vector<Eigen::Vector3f> anchor_points, positive_points;
  uint64_t object = 0;
};

class PairMaker {
 public:
  PairMaker(const TrainingSet& data, const std::vector<size_t>& subset,
            const SmoothNetTrainConfig& config)
      : data_(data), sampler_(data, subset), keys_(objectKeys(data)), config_(config) {}

  bool empty() const { return sampler_.anchors().empty(); }
  size_t anchors() const { return sampler_.anchors().size(); }

  // A pair of observations of one object and a keypoint with its counterpart, or nothing after a
  // few tries. The positive is taken from another segment (a revisit, another run) when the
  // object has one: two observations of one segment share most of the local map's points, which
  // makes the pair trivially alike.
  std::optional<KeypointPair> make(std::mt19937& rng) const {
    for (int attempt = 0; attempt < 8; ++attempt) {
      const auto& anchors = sampler_.anchors();
      const size_t anchor =
          anchors[std::uniform_int_distribution<size_t>(0, anchors.size() - 1)(rng)];
      size_t positive = sampler_.positive(anchor, rng);
      for (int other = 0; other < 4 && sameSegment(anchor, positive); ++other)
        positive = sampler_.positive(anchor, rng);
      KeypointPair pair;
      pair.anchor_points = positionsOf(data_.observations[anchor]);
      pair.positive_points = positionsOf(data_.observations[positive]);
      const auto& a = pair.anchor_points;
      pair.a = a[std::uniform_int_distribution<size_t>(0, a.size() - 1)(rng)];
      float best = std::numeric_limits<float>::infinity();
      for (const Eigen::Vector3f& q : pair.positive_points)
        if ((q - pair.a).squaredNorm() < best) best = (q - pair.a).squaredNorm(), pair.p = q;
      if (best > config_.correspondence_m * config_.correspondence_m) continue;
      pair.object = keys_[anchor];
      return pair;
    }
    return std::nullopt;
  }

 private:
  bool sameSegment(size_t a, size_t b) const {
    const TrainingObservation &x = data_.observations[a], &y = data_.observations[b];
    return x.source == y.source && x.segment == y.segment;
  }

  const TrainingSet& data_;
  PairSampler sampler_;
  std::vector<uint64_t> keys_;
  const SmoothNetTrainConfig& config_;
};

std::vector<KeypointPair> makePairs(const PairMaker& maker, size_t count, std::mt19937& rng) {
  std::vector<KeypointPair> pairs;
  for (size_t tries = 0; pairs.size() < count && tries < 20 * count; ++tries)
    if (std::optional<KeypointPair> pair = maker.make(rng)) pairs.push_back(std::move(*pair));
  return pairs;
}

// The SDV grids of the pairs' anchors and positives, [N, 1, G, G, G] each.
std::pair<torch::Tensor, torch::Tensor> pairGrids(const std::vector<KeypointPair>& pairs,
                                                  const NetConfig& c) {
  const int64_t n = static_cast<int64_t>(pairs.size()), g = c.smoothnet_voxels;
  torch::Tensor a = torch::empty({n, 1, g, g, g}), p = torch::empty({n, 1, g, g, g});
  at::parallel_for(0, n, 1, [&](int64_t begin, int64_t end) {
    for (int64_t i = begin; i < end; ++i) {
      const KeypointPair& pair = pairs[static_cast<size_t>(i)];
      for (const auto& [out, points, at] : {std::tuple(&a, &pair.anchor_points, pair.a),
                                            std::tuple(&p, &pair.positive_points, pair.p)}) {
        const std::vector<float> grid =
            keypointGrid(*points, at, c.smoothnet_radius, c.smoothnet_voxels);
        std::copy(grid.begin(), grid.end(), out->data_ptr<float>() + i * g * g * g);
      }
    }
  });
  return {a, p};
}

// Each pair's keypoints must find each other among the batch's: a softmax over the negative
// distances of a row (and of a column), its own pair the class to predict. Keypoints of one object
// closer than the support's diameter see overlapping points and are left out of each other's
// row. (3DSmoothNet's batch-hard margin loss collapsed here: every descriptor one and the same, the
// loss at the margin and keypoint top-1 0.003 after three epochs on S1; this one cannot rest there,
// where every row is uniform.)
torch::Tensor keypointLoss(const torch::Tensor& a, const torch::Tensor& p,
                           const std::vector<KeypointPair>& pairs, double temperature,
                           double radius) {
  const size_t n = pairs.size();
  std::vector<uint8_t> alike(n * n, 0);
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j)
      alike[i * n + j] = i != j && pairs[i].object == pairs[j].object &&
                         (pairs[i].a - pairs[j].a).norm() < 2.0 * radius;
  const int64_t rows = static_cast<int64_t>(n);
  const torch::Tensor mask =
      torch::from_blob(alike.data(), {rows, rows}, torch::kUInt8).to(torch::kBool);
  const torch::Tensor logits = (-torch::cdist(a, p) / temperature).masked_fill(mask, -1e4);
  const torch::Tensor own = torch::arange(rows, torch::kLong);
  return 0.5 * (torch::nn::functional::cross_entropy(logits, own) +
                torch::nn::functional::cross_entropy(logits.t(), own));
}

RetrievalAccuracy keypointRetrieval(SmoothNetImpl& net, const torch::Tensor& a,
                                    const torch::Tensor& p) {
  const bool was_training = net.is_training();
  net.eval();
  torch::NoGradGuard no_grad;
  auto rows = [&](const torch::Tensor& x) {
    const torch::Tensor d = net.local(x).contiguous();
    return Eigen::MatrixXf(Eigen::Map<const Eigen::Matrix<float, -1, -1, Eigen::RowMajor>>(
        d.data_ptr<float>(), d.size(0), d.size(1)));
  };
  std::vector<int> labels(static_cast<size_t>(a.size(0)));
  for (size_t i = 0; i < labels.size(); ++i) labels[i] = static_cast<int>(i);
  const RetrievalAccuracy out = retrievalAccuracy(rows(a), labels, rows(p), labels);
  if (was_training) net.train();
  return out;
}

}  // namespace

SmoothNetTrainConfig defaultSmoothNetTrainConfig() {
  SmoothNetTrainConfig c;
  c.net.kind = DescriptorKind::kSmoothNetBow;
  c.net.descriptor_dim = 16;  // the paper's best k
  return c;
}

size_t fitVisualWords(SmoothNetImpl& net, const TrainingSet& data, const std::vector<size_t>& which,
                      uint64_t seed) {
  const NetConfig& c = net.config();
  net.eval();
  torch::NoGradGuard no_grad;
  std::vector<torch::Tensor> parts;
  for (size_t start = 0; start < which.size(); start += 32) {
    std::vector<EnrichedCloud> clouds;
    for (size_t i = start; i < std::min(which.size(), start + 32); ++i)
      clouds.push_back(data.observations.at(which[i]).cloud());
    std::vector<const EnrichedCloud*> ptrs;
    for (const EnrichedCloud& cloud : clouds) ptrs.push_back(&cloud);
    parts.push_back(net.local(makeNetInput(c, ptrs, std::vector<uint64_t>(ptrs.size(), seed)).sdv));
  }
  const torch::Tensor local = torch::cat(parts).contiguous();
  if (local.size(0) < c.descriptor_dim)
    throw std::runtime_error("3dsmoothnet: " + std::to_string(local.size(0)) + " keypoints for " +
                             std::to_string(c.descriptor_dim) + " words");
  const cv::Mat samples(static_cast<int>(local.size(0)), static_cast<int>(local.size(1)), CV_32F,
                        local.data_ptr<float>());
  cv::Mat labels, centres;
  cv::theRNG().state = seed;  // k-means++ draws from OpenCV's thread RNG: the same words each run
  cv::kmeans(samples, c.descriptor_dim, labels,
             cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 100, 1e-5), 3,
             cv::KMEANS_PP_CENTERS, centres);
  net.setWords(torch::from_blob(centres.ptr<float>(), {centres.rows, centres.cols}).clone());
  return static_cast<size_t>(local.size(0));
}

namespace {

// The training observations whose keypoints the words are fitted to: a fixed random subset.
std::vector<size_t> wordSample(const std::vector<size_t>& train, size_t count, uint64_t seed) {
  std::vector<size_t> out = train;
  std::mt19937 rng(static_cast<uint32_t>(seed));
  std::shuffle(out.begin(), out.end(), rng);
  if (out.size() > count) out.resize(count);
  std::sort(out.begin(), out.end());
  return out;
}

EpochStats runEpoch(SmoothNetImpl& net, torch::optim::Adam& optimizer, const PairMaker& maker,
                    const SmoothNetTrainConfig& config, int epoch, std::mt19937& rng,
                    const TrainCallbacks& callbacks, bool* stopped) {
  const auto t0 = Clock::now();
  double sum = 0.0;
  for (size_t step = 0; step < config.steps_per_epoch; ++step) {
    if (callbacks.stop.stopRequested()) {
      *stopped = true;
      return {};
    }
    const std::vector<KeypointPair> pairs =
        makePairs(maker, static_cast<size_t>(config.batch_pairs), rng);
    if (pairs.size() < 2) throw std::runtime_error("3dsmoothnet: no corresponding keypoints");
    const auto [a, p] = pairGrids(pairs, config.net);
    const torch::Tensor loss = keypointLoss(net.local(a), net.local(p), pairs, config.temperature,
                                            config.net.smoothnet_radius);
    optimizer.zero_grad();
    loss.backward();
    optimizer.step();
    sum += loss.item<double>();
    if (callbacks.step) callbacks.step(epoch, step + 1, config.steps_per_epoch, sum / (step + 1));
  }
  EpochStats stats;
  stats.epoch = epoch;
  stats.loss = stats.triplet_loss = sum / static_cast<double>(config.steps_per_epoch);
  stats.learning_rate = config.learning_rate;
  stats.seconds = secondsSince(t0);
  return stats;
}

}  // namespace

SmoothNetTrainResult trainSmoothNet(const TrainingSet& data, const SmoothNetTrainConfig& config,
                                    const TrainCallbacks& callbacks) {
  checkSmoothNetConfig(config);
  const TorchThreadCount threads(config.threads);
  torch::manual_seed(config.seed);
  std::mt19937 rng(static_cast<uint32_t>(config.seed));

  SmoothNetTrainResult result;
  TrainResult& training = result.training;
  const TrainValSplit split = splitByInstance(data, config.validation_fraction, config.split_seed);
  const PairMaker train_pairs(data, split.train, config),
      validation_pairs(data, split.validation, config);
  training.train_observations = split.train.size();
  training.validation_observations = split.validation.size();
  training.anchors = train_pairs.anchors();
  if (train_pairs.empty())
    throw std::runtime_error(
        "training data has no instance observed twice: nothing to learn from (more frames?)");
  // The fixed validation pairs' grids, made once (their points are let go).
  const auto [val_a, val_p] = [&] {
    std::mt19937 validation_rng(static_cast<uint32_t>(config.seed + 1));
    return pairGrids(validation_pairs.empty()
                         ? std::vector<KeypointPair>{}
                         : makePairs(validation_pairs, config.validation_pairs, validation_rng),
                     config.net);
  }();

  auto net = std::make_shared<SmoothNetImpl>(config.net);
  net->train();
  torch::optim::Adam optimizer(net->parameters(), torch::optim::AdamOptions(config.learning_rate));
  WeightSnapshot best;
  double best_score = -std::numeric_limits<double>::infinity();
  for (int epoch = 1; epoch <= config.epochs; ++epoch) {
    bool stopped = false;
    EpochStats stats =
        runEpoch(*net, optimizer, train_pairs, config, epoch, rng, callbacks, &stopped);
    if (stopped) {
      training.interrupted = true;
      break;
    }
    if (val_a.size(0) > 0) stats.validation = keypointRetrieval(*net, val_a, val_p);
    const double score = stats.validation.queries > 0 ? stats.validation.top1 : -stats.loss;
    if (score > best_score) {
      best_score = score;
      best.take(*net);
      training.best_epoch = epoch;
      stats.best = true;
    }
    training.history.push_back(stats);
    if (callbacks.epoch) callbacks.epoch(stats);
  }
  if (training.history.empty()) return result;
  best.restore(*net);
  const auto t0 = Clock::now();
  result.word_keypoints = fitVisualWords(
      *net, data, wordSample(split.train, config.bow_observations, config.seed), config.seed);
  result.word_seconds = secondsSince(t0);
  if (!split.validation.empty())
    result.segments = validationAccuracy(*net, data, split.validation, config.seed,
                                         config.max_validation_queries);
  training.net = net;
  return result;
}

}  // namespace semsegmap
