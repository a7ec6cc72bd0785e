#include "semsegmap/localize/localizer.h"

#include <stdexcept>

namespace semsegmap {

Localizer::Localizer(std::shared_ptr<const TargetMap> map, const LocalizerConfig& config)
    : map_(std::move(map)), config_(config), index_(config.index) {
  if (!map_) throw std::invalid_argument("Localizer: no target map");
  if (map_->descriptors.rows() > 0) index_.build(map_->descriptors);
}

Localizer::Localizer(TargetMap map, const LocalizerConfig& config)
    : Localizer(std::make_shared<const TargetMap>(std::move(map)), config) {}

TargetMap& Localizer::ownMap() {
  if (!own_) {
    own_ = std::make_shared<TargetMap>(*map_);
    map_ = own_;
  }
  return *own_;
}

void Localizer::append(const std::vector<MapSegment>& segments,
                       const Eigen::MatrixXf& descriptors) {
  if (static_cast<size_t>(descriptors.rows()) != segments.size())
    throw std::invalid_argument("Localizer::append: one descriptor per segment expected");
  if (segments.empty()) return;
  TargetMap& map = ownMap();
  if (map.size() > 0 && descriptors.cols() != map.dimension())
    throw std::invalid_argument("Localizer::append: descriptors of dimension " +
                                std::to_string(descriptors.cols()) + ", the map's are " +
                                std::to_string(map.dimension()));
  const Eigen::Index n = static_cast<Eigen::Index>(map.size());
  map.segments.insert(map.segments.end(), segments.begin(), segments.end());
  map.descriptors.conservativeResize(n + descriptors.rows(), descriptors.cols());
  map.descriptors.bottomRows(descriptors.rows()) = descriptors;
  // An exact index takes the rows as they come; one that grows past the exact search's limit is
  // rebuilt once as IVF, whose trained lists then take further rows.
  const bool becomes_approximate = !index_.approximate() && map.size() >= config_.index.exact_below;
  if (index_.size() == 0 || becomes_approximate)
    index_.build(map.descriptors);
  else
    index_.add(descriptors);
}

void Localizer::setCentroid(size_t i, const Eigen::Vector3f& centroid) {
  ownMap().segments.at(i).centroid = centroid;
}

std::optional<Localization> Localizer::localize(const std::vector<Eigen::Vector3f>& centroids,
                                                const Eigen::MatrixXf& descriptors,
                                                const std::vector<bool>* usable) const {
  if (static_cast<size_t>(descriptors.rows()) != centroids.size())
    throw std::invalid_argument("localize: one descriptor per centroid expected");
  if (centroids.size() < config_.min_local_segments || map_->size() == 0) return std::nullopt;
  // With a mask, ask for more neighbours so that masked-out ones do not crowd out the rest.
  const int k = config_.index.k;
  const int k_search = usable ? std::min<int>(4 * k, static_cast<int>(map_->size())) : k;
  const Neighbours nn = index_.search(descriptors, k_search);
  std::vector<Correspondence> candidates;
  for (size_t q = 0; q < centroids.size(); ++q) {
    int kept = 0;
    for (int j = 0; j < nn.k && kept < k; ++j) {
      const int64_t id = nn.ids[q * static_cast<size_t>(nn.k) + static_cast<size_t>(j)];
      if (id < 0) break;
      if (usable && !(*usable)[static_cast<size_t>(id)]) continue;
      ++kept;
      Correspondence c;
      c.local = centroids[q].cast<double>();
      c.target = map_->segments[static_cast<size_t>(id)].centroid.cast<double>();
      c.local_id = static_cast<int64_t>(q);
      c.target_id = id;
      c.descriptor_distance = nn.squared_distances[q * static_cast<size_t>(nn.k) + j];
      candidates.push_back(c);
    }
  }
  const VerificationResult v = verify(candidates, config_.verification);
  if (!v.found) return std::nullopt;
  return localizationOf(v, candidates);
}

Localization localizationOf(const VerificationResult& v,
                            const std::vector<Correspondence>& candidates) {
  Localization l;
  l.T_map_local = v.T_target_local;
  l.inliers = static_cast<int>(v.inliers.size());
  l.candidates = candidates.size();
  for (int i : v.inliers) {
    const Correspondence& c = candidates[static_cast<size_t>(i)];
    l.matches.emplace_back(static_cast<size_t>(c.local_id), static_cast<size_t>(c.target_id));
  }
  return l;
}

}  // namespace semsegmap
