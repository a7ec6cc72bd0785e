#include "semsegmap/localize/target_map.h"

#include <map>
#include <stdexcept>

namespace semsegmap {

TargetMapBuilder::TargetMapBuilder(std::string descriptor, std::string fingerprint, int dimension,
                                   const TargetMapBuilderConfig& config)
    : descriptor_(std::move(descriptor)),
      fingerprint_(std::move(fingerprint)),
      dimension_(dimension),
      config_(config) {
  if (dimension_ < 1) throw std::invalid_argument("target map: descriptor dimension must be >= 1");
}

void TargetMapBuilder::add(const MapSegment& segment, const Eigen::VectorXf& descriptor) {
  if (descriptor.size() != dimension_)
    throw std::invalid_argument("target map: descriptor of dimension " +
                                std::to_string(descriptor.size()) + ", expected " +
                                std::to_string(dimension_));
  if (!segment.centroid.allFinite() || !descriptor.allFinite())
    throw std::invalid_argument("target map: segment with a non-finite centroid or descriptor");
  // Maps hold thousands of segments and a run adds them one by one: a linear scan is cheap
  // next to describing the segment.
  const float d2 = static_cast<float>(config_.duplicate_distance_m * config_.duplicate_distance_m);
  if (config_.duplicate_distance_m > 0)
    for (size_t i = 0; i < segments_.size(); ++i)
      if (alive_[i] && (segments_[i].centroid - segment.centroid).squaredNorm() < d2) {
        alive_[i] = false;
        ++duplicates_;
      }
  MapSegment kept = segment;
  kept.points = subsamplePoints(segment.points, config_.max_points_per_segment);
  segments_.push_back(std::move(kept));
  descriptors_.push_back(descriptor);
  alive_.push_back(true);
}

TargetMap TargetMapBuilder::build() const {
  TargetMap map;
  map.descriptor = descriptor_;
  map.fingerprint = fingerprint_;
  map.parameters = parameters_;
  map.scan_contexts = scans_;
  size_t n = 0;
  for (bool a : alive_) n += a;
  map.descriptors.resize(static_cast<Eigen::Index>(n), dimension_);
  map.segments.reserve(n);
  for (size_t i = 0; i < segments_.size(); ++i) {
    if (!alive_[i]) continue;
    map.descriptors.row(static_cast<Eigen::Index>(map.segments.size())) =
        descriptors_[i].transpose();
    map.segments.push_back(segments_[i]);
    map.segments.back().segment = static_cast<uint32_t>(map.segments.size() - 1);
  }
  return map;
}

std::vector<Eigen::Vector3f> subsamplePoints(const std::vector<Eigen::Vector3f>& points,
                                             size_t max_points) {
  if (max_points == 0 || points.empty()) return {};
  if (points.size() <= max_points) return points;
  std::vector<Eigen::Vector3f> out;
  out.reserve(max_points);
  // Evenly spaced indices: deterministic, and covers the whole segment.
  for (size_t i = 0; i < max_points; ++i) out.push_back(points[i * points.size() / max_points]);
  return out;
}

void checkMapCompatible(const std::string& map_name, const TargetMap& map,
                        const std::string& descriptor, const std::string& fingerprint,
                        int dimension) {
  const std::string where = map_name + ": ";
  if (map.descriptor != descriptor)
    throw std::runtime_error(where + "map built with " + map.descriptor +
                             " descriptors, the configuration uses " + descriptor);
  if (map.dimension() != dimension)
    throw std::runtime_error(where + "map descriptors have dimension " +
                             std::to_string(map.dimension()) + ", the describer gives " +
                             std::to_string(dimension));
  if (map.fingerprint != fingerprint)
    throw std::runtime_error(where + "map built with model " + map.fingerprint +
                             ", the configuration's model is " + fingerprint +
                             " (rebuild the map with this model)");
}

std::vector<MapParameterDifference> mapParameterDifferences(const MapParameters& map,
                                                            const MapParameters& config) {
  const std::string none = "(none)";
  const std::map<std::string, std::string> in_config(config.begin(), config.end());
  std::map<std::string, std::string> in_map(map.begin(), map.end());
  std::vector<MapParameterDifference> out;
  // In the configuration's order, which is the order the map was written in by this build.
  for (const auto& [key, value] : config) {
    const auto it = in_map.find(key);
    if (it == in_map.end())
      out.push_back({key, none, value});
    else if (it->second != value)
      out.push_back({key, it->second, value});
  }
  for (const auto& [key, value] : map)
    if (in_config.count(key) == 0) out.push_back({key, value, none});
  return out;
}

std::string describeDifference(const std::string& map_name, const MapParameterDifference& d) {
  return map_name + ": " + d.key + ": the map was built with " + d.map_value +
         ", the configuration has " + d.config_value;
}

}  // namespace semsegmap
