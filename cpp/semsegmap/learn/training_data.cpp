#include "semsegmap/learn/training_data.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "semsegmap/core/binary_io.h"
#include "semsegmap/core/random.h"
#include "semsegmap/pipeline/pipeline.h"

namespace semsegmap {

EnrichedCloud TrainingObservation::cloud() const {
  EnrichedCloud out(size());
  for (size_t i = 0; i < out.size(); ++i) {
    const float* f = &xyzhsv[6 * i];
    EnrichedPoint& p = out[i];
    p.x = f[0], p.y = f[1], p.z = f[2], p.h = f[3], p.s = f[4], p.v = f[5];
    p.class_id = classes[i];
    p.has_color = (modalities[i] & kHasColor) != 0;
    p.has_class = (modalities[i] & kHasClass) != 0;
    p.instance_id = instance;
  }
  return out;
}

namespace {

TrainingObservation compact(const SegmentObservation& obs, uint16_t source, SegmentId segment,
                            size_t max_points, uint64_t seed, size_t k) {
  TrainingObservation t;
  t.instance = obs.gt_instance;
  t.majority_class = obs.majority_class;
  t.source = source;
  t.segment = segment;
  t.n_points = static_cast<uint32_t>(obs.n_points);
  t.frame_index = static_cast<uint32_t>(obs.frame_index);
  t.purity = obs.gt_purity;
  t.centroid = obs.centroid.cast<float>();
  std::vector<uint32_t> keep(obs.points.size());
  std::iota(keep.begin(), keep.end(), 0u);
  if (max_points > 0 && keep.size() > max_points) {
    // Seeded by the observation itself, so that the subset does not depend on extraction order.
    std::mt19937 rng(static_cast<uint32_t>(
        hashKeys(seed, source, static_cast<uint64_t>(segment), static_cast<uint64_t>(k))));
    for (size_t i = 0; i < max_points; ++i) {
      std::uniform_int_distribution<size_t> pick(i, keep.size() - 1);
      std::swap(keep[i], keep[pick(rng)]);
    }
    keep.resize(max_points);
    std::sort(keep.begin(), keep.end());
  }
  t.xyzhsv.reserve(6 * keep.size());
  t.classes.reserve(keep.size());
  t.modalities.reserve(keep.size());
  for (uint32_t i : keep) {
    const EnrichedPoint& p = obs.points[i];
    t.xyzhsv.insert(t.xyzhsv.end(), {p.x, p.y, p.z, p.h, p.s, p.v});
    t.classes.push_back(p.class_id);
    t.modalities.push_back(
        static_cast<uint8_t>((p.has_color ? TrainingObservation::kHasColor : 0) |
                             (p.has_class ? TrainingObservation::kHasClass : 0)));
  }
  return t;
}

void appendSegment(const Segment& s, uint16_t source, const ExtractionConfig& config,
                   uint16_t first_transient, TrainingSet& out) {
  for (size_t k = 0; k < s.observations.size(); ++k) {
    const SegmentObservation& obs = s.observations[k];
    if (obs.gt_instance == 0 || (first_transient > 0 && obs.gt_instance >= first_transient) ||
        obs.gt_purity <= config.min_purity || obs.points.empty())
      continue;
    out.observations.push_back(
        compact(obs, source, s.id, config.max_points_per_observation, config.seed, k));
  }
}

}  // namespace

void appendObservations(FrameSource& source, uint16_t source_index, PipelineConfig pipeline,
                        const ExtractionConfig& config, TrainingSet& out,
                        const ExtractionProgress& progress) {
  const DatasetInfo& info = source.info();
  if (!info.has_ground_truth_poses)
    throw std::runtime_error("dataset '" + info.name +
                             "' has no ground-truth poses (training needs simulated ground truth)");
  if (!info.has_point_labels)
    throw std::runtime_error("dataset '" + info.name +
                             "' has no point instances (training needs simulated ground truth)");
  pipeline.segmentation.keep_all_observation_points = true;
  Pipeline pipe(pipeline, info, PoseSource::kGroundTruth);
  const size_t n = framesToRead(source, config.max_frames);
  for (size_t i = 0; i < n; ++i) {
    if (config.stop.stopRequested()) {
      out.interrupted = true;
      break;  // the segments of the frames done still finish below
    }
    FrameResult r = pipe.process(source.frame(i));
    for (const Segment& s : r.segmentation.finished)
      appendSegment(s, source_index, config, info.first_transient_instance, out);
    if (progress) progress(i + 1, n, source_index);
  }
  for (const Segment& s : pipe.finish())
    appendSegment(s, source_index, config, info.first_transient_instance, out);
}

// ---- Pairs, negatives and the validation split -------------------------------------------------

std::vector<uint64_t> objectKeys(const TrainingSet& set) {
  std::vector<uint64_t> world(set.sources.size());
  for (size_t s = 0; s < world.size(); ++s) {
    const std::string& name = s < set.source_worlds.size() ? set.source_worlds[s] : set.sources[s];
    world[s] = fnv1a64(name.data(), name.size(), kProjectFnvSeed);
  }
  std::vector<uint64_t> keys;
  keys.reserve(set.observations.size());
  for (const auto& o : set.observations) {
    if (o.source >= world.size())
      throw std::out_of_range("training data: observation of unknown source " +
                              std::to_string(o.source));
    keys.push_back(hashKeys(world[o.source], o.instance));
  }
  return keys;
}

std::vector<int> landmarkLabels(const TrainingSet& set) {
  const std::vector<uint64_t> objects = objectKeys(set);
  std::map<std::pair<uint64_t, ClassId>, int> ids;
  std::vector<int> labels;
  labels.reserve(set.observations.size());
  for (size_t i = 0; i < objects.size(); ++i) {
    auto it = ids.emplace(std::make_pair(objects[i], set.observations[i].majority_class),
                          static_cast<int>(ids.size()));
    labels.push_back(it.first->second);
  }
  return labels;
}

bool isValidationObject(uint64_t object_key, double validation_fraction, uint64_t seed) {
  return uniformFromHash(hashKeys(seed, object_key, 0x7a11da7e)) < validation_fraction;
}

TrainValSplit splitByInstance(const TrainingSet& set, double validation_fraction, uint64_t seed) {
  const std::vector<uint64_t> objects = objectKeys(set);
  TrainValSplit split;
  for (size_t i = 0; i < objects.size(); ++i)
    (isValidationObject(objects[i], validation_fraction, seed) ? split.validation : split.train)
        .push_back(i);
  return split;
}

PairSampler::PairSampler(const TrainingSet& set, std::vector<size_t> subset)
    : subset_(std::move(subset)), object_(objectKeys(set)), label_(landmarkLabels(set)) {
  const int n_labels = label_.empty() ? 0 : *std::max_element(label_.begin(), label_.end()) + 1;
  members_.resize(n_labels);
  for (size_t i : subset_) {
    if (i >= set.observations.size())
      throw std::out_of_range("PairSampler: observation index out of range");
    members_[label_[i]].push_back(i);
  }
  for (size_t i : subset_)
    if (members_[label_[i]].size() > 1) anchors_.push_back(i);
}

bool PairSampler::hasPositive(size_t anchor) const {
  return members_[label_[anchor]].size() > 1;
}

size_t PairSampler::positive(size_t anchor, std::mt19937& rng) const {
  const auto& m = members_[label_[anchor]];
  if (m.size() < 2) throw std::logic_error("PairSampler: anchor without a positive");
  // Uniform over the others: draw among size-1 and skip the anchor itself.
  std::uniform_int_distribution<size_t> pick(0, m.size() - 2);
  const size_t j = pick(rng);
  const auto self = std::find(m.begin(), m.end(), anchor) - m.begin();
  return m[j >= static_cast<size_t>(self) ? j + 1 : j];
}

size_t PairSampler::negative(size_t anchor, std::mt19937& rng) const {
  std::uniform_int_distribution<size_t> pick(0, subset_.size() - 1);
  // Nearly every draw is of another object; the bound only guards a degenerate set.
  for (int attempt = 0; attempt < 1000; ++attempt) {
    const size_t j = subset_[pick(rng)];
    if (isNegative(anchor, j)) return j;
  }
  for (size_t j : subset_)
    if (isNegative(anchor, j)) return j;
  throw std::runtime_error("training data has a single object: no negative to learn from");
}

// ---- Retrieval accuracy ------------------------------------------------------------------------

std::vector<bool> finalObservations(const TrainingSet& set) {
  std::map<std::pair<uint16_t, int64_t>, size_t> last;
  for (size_t i = 0; i < set.observations.size(); ++i)
    last[{set.observations[i].source, set.observations[i].segment}] = i;
  std::vector<bool> final(set.observations.size(), false);
  for (const auto& [segment, i] : last) final[i] = true;
  return final;
}

RetrievalAccuracy retrievalAccuracy(const Eigen::MatrixXf& queries,
                                    const std::vector<int>& query_labels,
                                    const Eigen::MatrixXf& database,
                                    const std::vector<int>& database_labels) {
  if (query_labels.size() != static_cast<size_t>(queries.rows()) ||
      database_labels.size() != static_cast<size_t>(database.rows()))
    throw std::invalid_argument("retrievalAccuracy: one label per descriptor");
  if (queries.rows() > 0 && database.rows() > 0 && queries.cols() != database.cols())
    throw std::invalid_argument("retrievalAccuracy: queries and database differ in dimension");
  const std::set<int> findable(database_labels.begin(), database_labels.end());
  const Eigen::VectorXf norms = database.rowwise().squaredNorm();
  RetrievalAccuracy acc;
  size_t hit1 = 0, hit5 = 0;
  std::vector<std::pair<float, Eigen::Index>> ranked(static_cast<size_t>(database.rows()));
  for (Eigen::Index q = 0; q < queries.rows(); ++q) {
    const int label = query_labels[static_cast<size_t>(q)];
    if (!findable.count(label)) continue;
    // |d - q|^2 up to the query's own norm, which does not change the ranking.
    const Eigen::VectorXf d2 = norms - 2.0f * (database * queries.row(q).transpose());
    for (Eigen::Index j = 0; j < database.rows(); ++j) ranked[static_cast<size_t>(j)] = {d2[j], j};
    const size_t k = std::min<size_t>(5, ranked.size());
    std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(k),
                      ranked.end());
    ++acc.queries;
    hit1 += database_labels[static_cast<size_t>(ranked[0].second)] == label;
    for (size_t r = 0; r < k; ++r)
      if (database_labels[static_cast<size_t>(ranked[r].second)] == label) {
        ++hit5;
        break;
      }
  }
  if (acc.queries > 0) {
    acc.top1 = static_cast<double>(hit1) / acc.queries;
    acc.top5 = static_cast<double>(hit5) / acc.queries;
  }
  return acc;
}

}  // namespace semsegmap
