#include "semsegmap/learn/trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "semsegmap/learn/training_state.h"

namespace semsegmap {

namespace {

void checkConfig(const TrainConfig& c) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("training: " + what); };
  if (c.net.kind != DescriptorKind::kSemSegMapNet && c.net.kind != DescriptorKind::kSegMapCnn)
    fail("descriptor '" + descriptorName(c.net.kind) +
         "' is not learned (expected semsegmap-net or segmap-cnn)");
  validateNetConfig(c.net);
  if (c.epochs < 1) fail("epochs must be at least 1");
  if (c.batch_size < 1) fail("batch size must be at least 1");
  if (c.reconstruction_anchors < 0) fail("reconstruction anchors must not be negative");
  if (!(c.learning_rate > 0)) fail("learning rate must be positive");
  if (!(c.learning_rate_decay > 0)) fail("learning rate decay must be positive");
  if (c.threads < 1) fail("threads must be at least 1");
  if (c.warmup_epochs < 0) fail("warm-up epochs must not be negative");
  if (c.hard_negative_candidates < 1) fail("hard-negative candidates must be at least 1");
  if (!(c.validation_fraction >= 0 && c.validation_fraction < 1))
    fail("validation fraction must be in [0, 1)");
  if (!(c.max_sigma > 0)) fail("max sigma must be positive");
  if (!(c.distillation_weight >= 0 && std::isfinite(c.distillation_weight)))
    fail("distillation weight must be finite and not negative");
}

}  // namespace

// A teacher must describe in the student's space: the same kind of network and descriptor size.
// With start_from_teacher the student takes its weights, so they must match by name and shape
// (the modalities a network sees change its input, not its weights).
void checkTeacher(const TrainConfig& c, DescriptorNetImpl& teacher) {
  const NetConfig& t = teacher.config();
  auto fail = [](const std::string& what) { throw std::invalid_argument("teacher: " + what); };
  if (t.kind != c.net.kind)
    fail("a " + descriptorName(t.kind) + " cannot teach a " + descriptorName(c.net.kind));
  if (t.descriptor_dim != c.net.descriptor_dim)
    fail("descriptor size " + std::to_string(t.descriptor_dim) + ", the student's is " +
         std::to_string(c.net.descriptor_dim));
}

namespace {

// The student's initial weights: the teacher's, tensor by tensor.
void copyWeights(DescriptorNetImpl& from, DescriptorNetImpl& to) {
  auto tensors = [](DescriptorNetImpl& net) {
    std::vector<std::pair<std::string, torch::Tensor>> out;
    for (const auto& p : net.named_parameters()) out.emplace_back(p.key(), p.value());
    for (const auto& b : net.named_buffers()) out.emplace_back(b.key(), b.value());
    return out;
  };
  const auto source = tensors(from), target = tensors(to);
  if (source.size() != target.size())
    throw std::invalid_argument("teacher: its weights do not fit the student (" +
                                std::to_string(source.size()) + " tensors, the student has " +
                                std::to_string(target.size()) + ")");
  torch::NoGradGuard no_grad;
  for (size_t i = 0; i < source.size(); ++i) {
    if (source[i].first != target[i].first || source[i].second.sizes() != target[i].second.sizes())
      throw std::invalid_argument("teacher: its weights do not fit the student (" +
                                  source[i].first + " against " + target[i].first + ")");
    target[i].second.copy_(source[i].second);
  }
}

struct Mean {
  double sum = 0.0;
  size_t n = 0;
  void add(double v) { sum += v, ++n; }
  double value() const { return n ? sum / n : 0.0; }
};

struct BatchLoss {
  torch::Tensor triplet, reconstruction;
  torch::Tensor distillation;  // 0 without a teacher
  torch::Tensor descriptors;   // [3B, D]: anchors, positives, negatives
};

// The mean squared distance between the student's descriptors `d` and the teacher's of the same
// clouds, which the teacher sees with everything it was trained on (a LiDAR-only student's
// clouds still carry their colour and classes: only the student's input leaves them out).
torch::Tensor distillationLoss(DescriptorNetImpl& teacher, const std::vector<EnrichedCloud>& clouds,
                               const torch::Tensor& d, std::mt19937& rng) {
  std::vector<const EnrichedCloud*> all;
  for (const auto& c : clouds) all.push_back(&c);
  torch::Tensor target;
  {
    torch::NoGradGuard no_grad;
    target = teacher.encode(makeNetInput(teacher.config(), all, rng));
  }
  return (d - target).pow(2).sum(1).mean();
}

// The loss of one batch of triplets. Only (some of) the anchors are decoded: the decoder costs
// more than the encoder (twice as much for semsegmap-net, twenty times for segmap-cnn), and the
// loss reconstructs the anchor.
BatchLoss batchLoss(DescriptorNetImpl& net, const TrainingSet& data, const std::vector<Triplet>& t,
                    const TrainConfig& config, bool augmented, std::mt19937& rng,
                    DescriptorNetImpl* teacher = nullptr) {
  const size_t batch = t.size();
  std::vector<EnrichedCloud> clouds;
  clouds.reserve(3 * batch);
  std::vector<double> effective_points;
  for (size_t role = 0; role < 3; ++role)
    for (const Triplet& x : t) {
      const size_t i = role == 0 ? x.anchor : role == 1 ? x.positive : x.negative;
      const TrainingObservation& o = data.observations.at(i);
      clouds.push_back(augmented ? augment(o.cloud(), config.augmentation, rng) : o.cloud());
      // Points of the whole observation that survived the augmentation's cuts and drops.
      effective_points.push_back(static_cast<double>(o.n_points) *
                                 static_cast<double>(clouds.back().size()) /
                                 static_cast<double>(std::max<size_t>(1, o.size())));
    }
  std::vector<float> sigma(batch);
  for (size_t b = 0; b < batch; ++b)
    sigma[b] = static_cast<float>(std::min(
        config.max_sigma, effective_points[batch + b] / std::max(1.0, effective_points[b])));
  // Rows 0..B-1 anchors, B..2B-1 positives, 2B..3B-1 negatives; the first `decoded` go through
  // the decoder too.
  const size_t decoded = config.reconstruction_anchors > 0
                             ? std::min(batch, static_cast<size_t>(config.reconstruction_anchors))
                             : batch;
  std::vector<const EnrichedCloud*> with_decoder, without;
  for (size_t i = 0; i < clouds.size(); ++i)
    (i < decoded ? with_decoder : without).push_back(&clouds[i]);
  const NetInput decoded_input = makeNetInput(config.net, with_decoder, rng);
  const NetOutput decoded_output = net.forward(decoded_input);
  const torch::Tensor d =
      torch::cat({decoded_output.descriptor, net.encode(makeNetInput(config.net, without, rng))});
  const int64_t B = static_cast<int64_t>(batch);
  BatchLoss loss;
  loss.triplet =
      tripletLoss(d.slice(0, 0, B), d.slice(0, B, 2 * B), d.slice(0, 2 * B, 3 * B),
                  torch::from_blob(sigma.data(), {B}, torch::kFloat).clone(), config.margin);
  loss.reconstruction = torch::binary_cross_entropy_with_logits(decoded_output.reconstruction,
                                                                decoded_input.target_occupancy);
  loss.distillation = teacher ? distillationLoss(*teacher, clouds, d, rng) : torch::zeros({});
  loss.descriptors = d;
  return loss;
}

}  // namespace

TrainConfig defaultTrainConfig(DescriptorKind kind) {
  TrainConfig c;
  c.net.kind = kind;
  if (kind == DescriptorKind::kSegMapCnn) {
    // A step costs three times semsegmap-net's even with 8 of 32 anchors decoded: fewer epochs.
    c.reconstruction_anchors = 8;
    c.epochs = 8;
  }
  return c;
}

Eigen::MatrixXf describeObservations(DescriptorNetImpl& net, const TrainingSet& data,
                                     const std::vector<size_t>& which, uint64_t seed,
                                     int batch_size) {
  const bool was_training = net.is_training();
  net.eval();
  torch::NoGradGuard no_grad;
  Eigen::MatrixXf out(static_cast<Eigen::Index>(which.size()), net.config().descriptor_dim);
  for (size_t start = 0; start < which.size(); start += static_cast<size_t>(batch_size)) {
    const size_t end = std::min(which.size(), start + static_cast<size_t>(batch_size));
    std::vector<EnrichedCloud> clouds;
    clouds.reserve(end - start);
    for (size_t i = start; i < end; ++i) clouds.push_back(data.observations.at(which[i]).cloud());
    std::vector<const EnrichedCloud*> ptrs;
    for (const auto& c : clouds) ptrs.push_back(&c);
    // One salt for all: an observation's input does not depend on the batch it is in.
    const std::vector<uint64_t> salts(ptrs.size(), seed);
    const torch::Tensor d =
        net.encode(makeNetInput(net.config(), ptrs, salts)).to(torch::kFloat).contiguous();
    const float* dp = d.data_ptr<float>();
    for (size_t i = start; i < end; ++i)
      out.row(static_cast<Eigen::Index>(i)) =
          Eigen::Map<const Eigen::RowVectorXf>(dp + (i - start) * out.cols(), out.cols());
  }
  if (was_training) net.train();
  return out;
}

RetrievalAccuracy validationAccuracy(DescriptorNetImpl& net, const TrainingSet& data,
                                     const std::vector<size_t>& which, uint64_t seed,
                                     size_t max_queries, double min_completeness) {
  const std::vector<int> labels = landmarkLabels(data);
  const std::vector<bool> final = finalObservations(data);
  std::map<std::pair<uint16_t, int64_t>, uint32_t> final_points;
  std::vector<size_t> queries, database;
  for (size_t i = 0; i < final.size(); ++i)
    if (final[i]) {
      database.push_back(i);
      const TrainingObservation& o = data.observations[i];
      final_points[{o.source, o.segment}] = o.n_points;
    }
  for (size_t i : which) {
    const TrainingObservation& o = data.observations.at(i);
    if (!final[i] && o.n_points >= min_completeness * final_points[{o.source, o.segment}])
      queries.push_back(i);
  }
  if (queries.size() > max_queries) {
    std::mt19937 pick(static_cast<uint32_t>(seed));
    std::shuffle(queries.begin(), queries.end(), pick);
    queries.resize(max_queries);
    std::sort(queries.begin(), queries.end());
  }
  auto labelsOf = [&](const std::vector<size_t>& idx) {
    std::vector<int> out;
    for (size_t i : idx) out.push_back(labels[i]);
    return out;
  };
  return retrievalAccuracy(describeObservations(net, data, queries, seed), labelsOf(queries),
                           describeObservations(net, data, database, seed), labelsOf(database));
}

double evaluateTriplets(DescriptorNetImpl& net, const TrainingSet& data,
                        const std::vector<Triplet>& triplets, const TrainConfig& config) {
  const bool was_training = net.is_training();
  net.eval();
  torch::NoGradGuard no_grad;
  std::mt19937 rng(static_cast<uint32_t>(config.seed));
  Mean mean;
  const size_t batch = static_cast<size_t>(std::max(1, config.batch_size));
  for (size_t start = 0; start < triplets.size(); start += batch) {
    const std::vector<Triplet> part(
        triplets.begin() + static_cast<std::ptrdiff_t>(start),
        triplets.begin() + static_cast<std::ptrdiff_t>(std::min(triplets.size(), start + batch)));
    const BatchLoss loss = batchLoss(net, data, part, config, false, rng);
    const double value =
        (loss.triplet + config.reconstruction_weight * loss.reconstruction).item<double>();
    for (size_t k = 0; k < part.size(); ++k) mean.add(value);  // weighted by batch size
  }
  if (was_training) net.train();
  return mean.value();
}

namespace {

// Descriptors of the training observations as last computed (during training, so at most an
// epoch old and augmented): the hard-negative miner ranks candidates by them for free.
class DescriptorCache {
 public:
  DescriptorCache(size_t observations, int dim)
      : dim_(dim), rows_(static_cast<Eigen::Index>(observations), dim), cached_(observations, 0) {}
  bool has(size_t i) const { return cached_[i] != 0; }
  float distance(size_t a, size_t b) const {
    return has(b)
               ? (rows_.row(static_cast<Eigen::Index>(b)) - rows_.row(static_cast<Eigen::Index>(a)))
                     .squaredNorm()
               : std::numeric_limits<float>::infinity();
  }
  // `descriptors` [3B, D]: the anchors, positives and negatives of `triplets`.
  void store(const torch::Tensor& descriptors, const std::vector<Triplet>& triplets) {
    const torch::Tensor d = descriptors.detach().to(torch::kFloat).contiguous();
    const float* dp = d.data_ptr<float>();
    const size_t batch = triplets.size();
    for (size_t r = 0; r < 3 * batch; ++r) {
      const Triplet& t = triplets[r % batch];
      const size_t i = r < batch ? t.anchor : r < 2 * batch ? t.positive : t.negative;
      rows_.row(static_cast<Eigen::Index>(i)) =
          Eigen::Map<const Eigen::RowVectorXf>(dp + r * static_cast<size_t>(dim_), dim_);
      cached_[i] = 1;
    }
  }

 private:
  int dim_;
  Eigen::MatrixXf rows_;
  std::vector<char> cached_;
};

// One training run: the sampling of triplets, the steps of an epoch, and its validation.
class Training {
 public:
  Training(const TrainingSet& data, const TrainConfig& config, const TrainValSplit& split,
           const PairSampler& sampler, std::shared_ptr<DescriptorNetImpl> teacher)
      : data_(data),
        config_(config),
        split_(split),
        sampler_(sampler),
        rng_(static_cast<uint32_t>(config.seed)),
        net_(studentNet(config, teacher.get())),
        teacher_(std::move(teacher)),
        optimizer_(net_->parameters(), torch::optim::AdamOptions(config.learning_rate)),
        cache_(data.observations.size(), config.net.descriptor_dim),
        batch_(std::min<size_t>(static_cast<size_t>(config.batch_size), sampler.anchors().size())),
        learning_rate_(config.learning_rate) {
    net_->train();
    if (teacher_) teacher_->eval();
    const size_t anchors_per_epoch =
        config.anchors_per_epoch > 0 ? config.anchors_per_epoch : sampler.anchors().size();
    steps_ = std::max<size_t>(1, anchors_per_epoch / batch_);
  }

  // Nothing when the stop request came before the epoch's last step: an epoch half trained is
  // neither validated nor kept.
  std::optional<EpochStats> epoch(int epoch, const TrainCallbacks& callbacks) {
    const auto t0 = std::chrono::steady_clock::now();
    const bool mine = epoch > config_.warmup_epochs;
    Mean loss_mean, triplet_mean, recon_mean, distillation_mean;
    for (size_t step = 0; step < steps_; ++step) {
      if (callbacks.stop.stopRequested()) return std::nullopt;
      const std::vector<Triplet> triplets = sampleTriplets(mine);
      // A teacher of weight 0 only gave the starting weights: its descriptors are not needed.
      DescriptorNetImpl* teacher = config_.distillation_weight > 0 ? teacher_.get() : nullptr;
      const BatchLoss b =
          batchLoss(*net_, data_, triplets, config_, config_.augment, rng_, teacher);
      torch::Tensor loss = b.triplet + config_.reconstruction_weight * b.reconstruction;
      if (teacher) loss = loss + config_.distillation_weight * b.distillation;
      optimizer_.zero_grad();
      loss.backward();
      optimizer_.step();
      cache_.store(b.descriptors, triplets);
      loss_mean.add(loss.item<double>());
      triplet_mean.add(b.triplet.item<double>());
      recon_mean.add(b.reconstruction.item<double>());
      distillation_mean.add(b.distillation.item<double>());
      if (callbacks.step) callbacks.step(epoch, step + 1, steps_, loss_mean.value());
    }
    EpochStats stats;
    stats.epoch = epoch;
    stats.loss = loss_mean.value();
    stats.triplet_loss = triplet_mean.value();
    stats.reconstruction_loss = recon_mean.value();
    stats.distillation_loss = distillation_mean.value();
    stats.learning_rate = learning_rate_;
    stats.validation =
        validationAccuracy(*net_, data_, split_.validation, config_.seed,
                           config_.max_validation_queries, config_.validation_min_completeness);
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return stats;
  }

  void decayLearningRate() {
    learning_rate_ *= config_.learning_rate_decay;
    for (auto& group : optimizer_.param_groups())
      static_cast<torch::optim::AdamOptions&>(group.options()).lr(learning_rate_);
  }
  DescriptorNetImpl& net() { return *net_; }
  std::shared_ptr<DescriptorNetImpl> sharedNet() { return net_; }

 private:
  // A batch of triplets: random negatives during warm-up, then the hardest of a few candidates
  // by the cached descriptors.
  std::vector<Triplet> sampleTriplets(bool mine) {
    std::vector<Triplet> triplets(batch_);
    for (Triplet& t : triplets) {
      if (order_.empty()) {
        order_ = sampler_.anchors();
        std::shuffle(order_.begin(), order_.end(), rng_);
      }
      t.anchor = order_.back();
      order_.pop_back();
      t.positive = sampler_.positive(t.anchor, rng_);
      if (data_.observations[t.positive].n_points > data_.observations[t.anchor].n_points)
        std::swap(t.anchor, t.positive);
      t.negative = sampler_.negative(t.anchor, rng_);
      if (!mine || !cache_.has(t.anchor)) continue;
      float hardest = cache_.distance(t.anchor, t.negative);
      for (int k = 1; k < config_.hard_negative_candidates; ++k) {
        const size_t c = sampler_.negative(t.anchor, rng_);
        const float d = cache_.distance(t.anchor, c);
        if (d < hardest) hardest = d, t.negative = c;
      }
    }
    return triplets;
  }

  const TrainingSet& data_;
  const TrainConfig& config_;
  const TrainValSplit& split_;
  const PairSampler& sampler_;
  std::mt19937 rng_;
  // Fresh weights (torch's seeded RNG), or the teacher's to start from.
  static std::shared_ptr<DescriptorNetImpl> studentNet(const TrainConfig& config,
                                                       DescriptorNetImpl* teacher) {
    auto net = makeNet(config.net);
    if (teacher && config.start_from_teacher) copyWeights(*teacher, *net);
    return net;
  }

  std::shared_ptr<DescriptorNetImpl> net_;
  std::shared_ptr<DescriptorNetImpl> teacher_;  // null without distillation; never trained
  torch::optim::Adam optimizer_;
  DescriptorCache cache_;
  size_t batch_, steps_ = 1;
  std::vector<size_t> order_;  // anchors still to visit; refilled and shuffled when empty
  double learning_rate_;
};

}  // namespace

TrainResult trainDescriptor(const TrainingSet& data, const TrainConfig& config,
                            const TrainCallbacks& callbacks,
                            std::shared_ptr<DescriptorNetImpl> teacher) {
  checkConfig(config);
  if (teacher) checkTeacher(config, *teacher);
  const TorchThreadCount threads(config.threads);
  torch::manual_seed(config.seed);

  TrainResult result;
  const TrainValSplit split = splitByInstance(data, config.validation_fraction, config.split_seed);
  const PairSampler sampler(data, split.train);
  result.train_observations = split.train.size();
  result.validation_observations = split.validation.size();
  result.anchors = sampler.anchors().size();
  if (sampler.anchors().empty())
    throw std::runtime_error(
        "training data has no instance observed twice: nothing to learn from (more frames?)");

  Training training(data, config, split, sampler, std::move(teacher));
  WeightSnapshot best;
  double best_score = -std::numeric_limits<double>::infinity();
  for (int epoch = 1; epoch <= config.epochs; ++epoch) {
    std::optional<EpochStats> done = training.epoch(epoch, callbacks);
    if (!done) {
      result.interrupted = true;
      break;
    }
    EpochStats& stats = *done;
    // Without validation queries (tiny data), the training loss is all there is to go by.
    const double score = stats.validation.queries > 0 ? stats.validation.top1 : -stats.loss;
    if (score > best_score) {
      best_score = score;
      best.take(training.net());
      result.best_epoch = epoch;
      stats.best = true;
      if (callbacks.best) callbacks.best(training.net());
    }
    result.history.push_back(stats);
    if (callbacks.epoch) callbacks.epoch(stats);
    training.decayLearningRate();
  }
  if (result.history.empty()) return result;  // interrupted in the first epoch: no model
  best.restore(training.net());
  result.net = training.sharedNet();
  return result;
}

}  // namespace semsegmap
