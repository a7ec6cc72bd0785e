#include "semsegmap/learn/training_data.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <map>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "semsegmap/core/random.h"
#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/open_dataset.h"
#include "semsegmap/pipeline/pipeline.h"

namespace semsegmap {

EnrichedCloud TrainingObservation::cloud() const {
  EnrichedCloud out(size());
  for (size_t i = 0; i < out.size(); ++i) {
    const float* f = &xyzhsv[6 * i];
    EnrichedPoint& p = out[i];
    p.x = f[0], p.y = f[1], p.z = f[2], p.h = f[3], p.s = f[4], p.v = f[5];
    p.class_id = classes[i];
    p.has_color = colored[i] != 0;
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
  t.colored.reserve(keep.size());
  for (uint32_t i : keep) {
    const EnrichedPoint& p = obs.points[i];
    t.xyzhsv.insert(t.xyzhsv.end(), {p.x, p.y, p.z, p.h, p.s, p.v});
    t.classes.push_back(p.class_id);
    t.colored.push_back(p.has_color ? 1 : 0);
  }
  return t;
}

void appendSegment(const Segment& s, uint16_t source, const ExtractionConfig& config,
                   TrainingSet& out) {
  for (size_t k = 0; k < s.observations.size(); ++k) {
    const SegmentObservation& obs = s.observations[k];
    if (obs.gt_instance == 0 || obs.gt_instance >= config.first_transient_instance ||
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
  const size_t n =
      config.max_frames > 0 ? std::min(source.size(), config.max_frames) : source.size();
  for (size_t i = 0; i < n; ++i) {
    FrameResult r = pipe.process(source.frame(i));
    for (const Segment& s : r.segmentation.finished) appendSegment(s, source_index, config, out);
    if (progress) progress(i + 1, n, source_index);
  }
  for (const Segment& s : pipe.finish()) appendSegment(s, source_index, config, out);
}

TrainingSet extractTrainingSet(const std::vector<std::string>& specs,
                               const PipelineConfig& pipeline, const ExtractionConfig& config,
                               const ExtractionProgress& progress) {
  if (specs.empty()) throw std::invalid_argument("no dataset to extract training data from");
  if (specs.size() > 0xffff) throw std::invalid_argument("too many datasets (at most 65535)");
  TrainingSet set;
  set.sources = specs;
  for (const auto& spec : specs) set.source_worlds.push_back(worldOf(spec));
  for (size_t i = 0; i < specs.size(); ++i) {
    auto source = openDataset(specs[i]);
    appendObservations(*source, static_cast<uint16_t>(i), pipeline, config, set, progress);
  }
  return set;
}

std::string worldOf(const std::string& spec) {
  if (spec.rfind("sim:", 0) != 0) return spec;
  // The defaults of openDataset: world 1, the full preset.
  std::string world = "1", preset = "full";
  std::stringstream ss(spec.substr(4));
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) continue;
    if (item.substr(0, eq) == "world") world = item.substr(eq + 1);
    if (item.substr(0, eq) == "preset") preset = item.substr(eq + 1);
  }
  return "sim:world=" + world + ",preset=" + preset;
}

std::vector<std::string> splitDatasetSpecs(const std::string& list) {
  auto isSimKey = [](const std::string& token) {
    const auto eq = token.find('=');
    return eq != std::string::npos && eq > 0 && token.find_first_of("/:") == std::string::npos;
  };
  std::vector<std::string> specs;
  size_t start = 0;
  while (start <= list.size()) {
    const size_t end = std::min(list.find(';', start), list.size());
    const std::string group = list.substr(start, end - start);
    bool in_sim = false;
    size_t token_start = 0;
    while (token_start <= group.size()) {
      const size_t token_end = std::min(group.find(',', token_start), group.size());
      const std::string token = group.substr(token_start, token_end - token_start);
      if (in_sim && isSimKey(token)) {
        specs.back() += "," + token;
      } else {
        if (token.empty())
          throw std::invalid_argument("dataset list '" + list + "': empty dataset spec");
        specs.push_back(token);
        in_sim = token.rfind("sim:", 0) == 0;
      }
      token_start = token_end + 1;
    }
    start = end + 1;
  }
  return specs;
}

// ---- Cache -------------------------------------------------------------------------------------

namespace {

// Layout (host byte order, little-endian on every platform we build for):
//   "SSMTRAIN" u32 version | str provenance | u32 n, n x (str source, str world) |
//   u64 n, n x observation |
//   u64 FNV-1a of every byte after the version
// str = u32 length + bytes; observation = u16 instance, u16 class, u16 source, i64 segment,
//   u32 n_points, f32 purity, 3 x f32 centroid, u32 count, count x 6 f32, count x u16 class,
//   count x u8 colored.
constexpr char kCacheMagic[8] = {'S', 'S', 'M', 'T', 'R', 'A', 'I', 'N'};
constexpr uint32_t kCacheVersion = 2;

struct Fnv {
  uint64_t h = 1469598103934665603ULL;
  void add(const void* data, size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ULL;
  }
};

class Writer {
 public:
  explicit Writer(std::ostream& out) : out_(out) {}
  void bytes(const void* data, size_t n) {
    fnv_.add(data, n);
    out_.write(static_cast<const char*>(data), static_cast<std::streamsize>(n));
  }
  template <typename T>
  void value(T v) {
    bytes(&v, sizeof v);
  }
  void str(const std::string& s) {
    value(static_cast<uint32_t>(s.size()));
    bytes(s.data(), s.size());
  }
  template <typename T>
  void array(const std::vector<T>& v) {
    bytes(v.data(), v.size() * sizeof(T));
  }
  uint64_t hash() const { return fnv_.h; }

 private:
  std::ostream& out_;
  Fnv fnv_;
};

class Reader {
 public:
  Reader(std::istream& in, const std::filesystem::path& path) : in_(in), path_(path) {}
  void bytes(void* data, size_t n) {
    if (!in_.read(static_cast<char*>(data), static_cast<std::streamsize>(n)))
      throw std::runtime_error(path_.string() + ": truncated training cache");
    fnv_.add(data, n);
  }
  template <typename T>
  T value() {
    T v;
    bytes(&v, sizeof v);
    return v;
  }
  // Sizes are checked against what is left of the file, so that a corrupt count fails cleanly
  // instead of allocating gigabytes.
  size_t count(size_t element_bytes) {
    const uint64_t n = value<uint64_t>();
    if (element_bytes > 0 && n > remaining() / element_bytes)
      throw std::runtime_error(path_.string() + ": corrupt training cache (bad count)");
    return static_cast<size_t>(n);
  }
  std::string str() {
    const uint32_t n = value<uint32_t>();
    if (n > remaining()) throw std::runtime_error(path_.string() + ": corrupt training cache");
    std::string s(n, '\0');
    bytes(s.data(), n);
    return s;
  }
  template <typename T>
  void array(std::vector<T>& v, size_t n) {
    v.resize(n);
    bytes(v.data(), n * sizeof(T));
  }
  uint64_t hash() const { return fnv_.h; }
  uint64_t remaining() {
    const auto here = in_.tellg();
    in_.seekg(0, std::ios::end);
    const auto end = in_.tellg();
    in_.seekg(here);
    return static_cast<uint64_t>(end - here);
  }

 private:
  std::istream& in_;
  std::filesystem::path path_;
  Fnv fnv_;
};

}  // namespace

void writeTrainingCache(const std::filesystem::path& path, const TrainingSet& set,
                        const std::string& provenance) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(kCacheMagic, sizeof kCacheMagic);
    out.write(reinterpret_cast<const char*>(&kCacheVersion), sizeof kCacheVersion);
    Writer w(out);
    w.str(provenance);
    w.value(static_cast<uint32_t>(set.sources.size()));
    for (size_t i = 0; i < set.sources.size(); ++i) {
      w.str(set.sources[i]);
      w.str(i < set.source_worlds.size() ? set.source_worlds[i] : set.sources[i]);
    }
    w.value(static_cast<uint64_t>(set.observations.size()));
    for (const TrainingObservation& o : set.observations) {
      w.value(o.instance);
      w.value(o.majority_class);
      w.value(o.source);
      w.value(o.segment);
      w.value(o.n_points);
      w.value(o.purity);
      for (int k = 0; k < 3; ++k) w.value(o.centroid[k]);
      w.value(static_cast<uint32_t>(o.size()));
      w.array(o.xyzhsv);
      w.array(o.classes);
      w.array(o.colored);
    }
    const uint64_t hash = w.hash();
    out.write(reinterpret_cast<const char*>(&hash), sizeof hash);
  });
}

std::optional<TrainingSet> readTrainingCache(const std::filesystem::path& path,
                                             const std::string& provenance) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  char magic[sizeof kCacheMagic];
  uint32_t version = 0;
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kCacheMagic, sizeof magic) != 0)
    throw std::runtime_error(path.string() + ": not a training cache (bad magic)");
  if (!in.read(reinterpret_cast<char*>(&version), sizeof version))
    throw std::runtime_error(path.string() + ": truncated training cache");
  // An older layout is not an error: the data is simply extracted again.
  if (version != kCacheVersion) return std::nullopt;
  Reader r(in, path);
  if (r.str() != provenance) return std::nullopt;
  TrainingSet set;
  const uint32_t n_sources = r.value<uint32_t>();
  if (n_sources > r.remaining() / 8)
    throw std::runtime_error(path.string() + ": corrupt training cache (bad source count)");
  for (uint32_t i = 0; i < n_sources; ++i) {
    set.sources.push_back(r.str());
    set.source_worlds.push_back(r.str());
  }
  set.observations.resize(r.count(38));  // 38: the fixed part of an observation
  for (TrainingObservation& o : set.observations) {
    o.instance = r.value<uint16_t>();
    o.majority_class = r.value<ClassId>();
    o.source = r.value<uint16_t>();
    o.segment = r.value<int64_t>();
    o.n_points = r.value<uint32_t>();
    o.purity = r.value<float>();
    for (int k = 0; k < 3; ++k) o.centroid[k] = r.value<float>();
    const uint32_t n = r.value<uint32_t>();
    if (n > r.remaining() / 27)
      throw std::runtime_error(path.string() + ": corrupt training cache");
    r.array(o.xyzhsv, 6 * size_t{n});
    r.array(o.classes, n);
    r.array(o.colored, n);
    if (o.source >= set.sources.size())
      throw std::runtime_error(path.string() + ": corrupt training cache (bad source index)");
  }
  const uint64_t expected = r.hash();
  uint64_t stored = 0;
  if (!in.read(reinterpret_cast<char*>(&stored), sizeof stored))
    throw std::runtime_error(path.string() + ": truncated training cache");
  if (stored != expected)
    throw std::runtime_error(path.string() + ": corrupt training cache (checksum mismatch)");
  return set;
}

// ---- Pairs, negatives and the validation split -------------------------------------------------

std::vector<uint64_t> objectKeys(const TrainingSet& set) {
  std::vector<uint64_t> world(set.sources.size());
  for (size_t s = 0; s < world.size(); ++s) {
    const std::string& name = s < set.source_worlds.size() ? set.source_worlds[s] : set.sources[s];
    Fnv fnv;
    fnv.add(name.data(), name.size());
    world[s] = fnv.h;
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
