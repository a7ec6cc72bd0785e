#include "semsegmap/localize/relocalizer.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace semsegmap {

namespace {

// The map's x-y extent on a grid of cell_m: a dense array of votes, because a relocalization
// casts ~10^5-10^6 votes (local segments x k x the cells of a place's disc) and an array
// increment is several times cheaper than a hash-set insertion. A map too large for it at cell_m
// gets coarser cells.
class PlaceGrid {
 public:
  PlaceGrid(const TargetMap& map, double cell_m) {
    Eigen::Vector2f lo = Eigen::Vector2f::Constant(0), hi = lo;
    if (map.size() > 0) lo = hi = map.segments[0].centroid.head<2>();
    for (const MapSegment& s : map.segments) {
      lo = lo.cwiseMin(s.centroid.head<2>());
      hi = hi.cwiseMax(s.centroid.head<2>());
    }
    constexpr double kMaxCells = 4e6;
    const Eigen::Vector2d extent = (hi - lo).cast<double>();
    cell_ = std::max(cell_m, std::sqrt(extent.x() * extent.y() / kMaxCells));
    origin_ = lo.cast<double>();
    nx_ = static_cast<int>(extent.x() / cell_) + 1;
    ny_ = static_cast<int>(extent.y() / cell_) + 1;
    votes_.assign(static_cast<size_t>(nx_) * static_cast<size_t>(ny_), 0);
    stamp_.assign(votes_.size(), -1);
  }

  // Local segment q votes once for every cell whose centre lies within radius_m of `target`,
  // with `weight`; its first vote for a cell counts (its nearest candidate there).
  void vote(int q, const Eigen::Vector3f& target, double radius_m, double weight) {
    const Eigen::Vector2d t = target.head<2>().cast<double>();
    const int r = static_cast<int>(std::ceil(radius_m / cell_));
    const int cx = cellOf(t.x() - origin_.x()), cy = cellOf(t.y() - origin_.y());
    for (int x = std::max(0, cx - r); x <= std::min(nx_ - 1, cx + r); ++x)
      for (int y = std::max(0, cy - r); y <= std::min(ny_ - 1, cy + r); ++y) {
        const size_t i = static_cast<size_t>(x) * static_cast<size_t>(ny_) + static_cast<size_t>(y);
        if (stamp_[i] == q || (centre(x, y) - t).norm() > radius_m) continue;
        stamp_[i] = q;
        votes_[i] += weight;
      }
  }

  struct Place {
    Eigen::Vector2d centre;
    double votes = 0;
  };
  // The best voted cells, each at least `apart_m` from the better ones taken, within the prior.
  std::vector<Place> best(size_t n, double min_votes, double apart_m,
                          const std::optional<RelocalizationPrior>& prior) const {
    // Only the cells with enough votes are sorted: a few hundred of a grid of up to 4e6.
    std::vector<size_t> order;
    for (size_t i = 0; i < votes_.size(); ++i)
      if (votes_[i] >= min_votes) order.push_back(i);
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return votes_[a] > votes_[b]; });
    std::vector<Place> out;
    for (size_t i : order) {
      if (out.size() >= n) break;
      const Place p{centre(static_cast<int>(i / static_cast<size_t>(ny_)),
                           static_cast<int>(i % static_cast<size_t>(ny_))),
                    votes_[i]};
      if (prior && (p.centre - prior->position.head<2>()).norm() > prior->radius_m) continue;
      const bool near_taken = std::any_of(out.begin(), out.end(), [&](const Place& o) {
        return (o.centre - p.centre).norm() < apart_m;
      });
      if (!near_taken) out.push_back(p);
    }
    return out;
  }

 private:
  int cellOf(double offset) const { return static_cast<int>(std::floor(offset / cell_)); }
  Eigen::Vector2d centre(int x, int y) const {
    return origin_ + cell_ * Eigen::Vector2d(x + 0.5, y + 0.5);
  }
  double cell_ = 1.0;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  int nx_ = 0, ny_ = 0;
  std::vector<double> votes_;
  std::vector<int> stamp_;  // the last local segment that voted for a cell
};

// The candidates of one place: each local segment's neighbours that lie in it.
std::vector<Correspondence> candidatesIn(const Neighbours& nn, const TargetMap& map,
                                         const std::vector<Eigen::Vector3f>& centroids,
                                         const Eigen::Vector2d& centre,
                                         const RelocalizationConfig& config) {
  std::vector<Correspondence> out;
  for (size_t q = 0; q < centroids.size(); ++q)
    for (int j = 0, kept = 0; j < nn.k && kept < config.k_in_place; ++j) {
      const int64_t id = nn.id(q, j);
      if (id < 0) break;
      const Eigen::Vector3f& t = map.segments[static_cast<size_t>(id)].centroid;
      if ((t.head<2>().cast<double>() - centre).norm() > config.place_radius_m) continue;
      ++kept;
      Correspondence c;
      c.local = centroids[q].cast<double>();
      c.target = t.cast<double>();
      c.local_id = static_cast<int64_t>(q);
      c.target_id = id;
      c.descriptor_distance = nn.squaredDistance(q, j);
      out.push_back(c);
    }
  return out;
}

// The robot within the check's own tolerance in both: registration would take one to the other.
bool samePose(const Pose& a, const Pose& b, const Eigen::Vector3d& robot_local,
              const RegistrationCheckConfig& check) {
  return (a * robot_local - b * robot_local).norm() <= check.max_correction_m &&
         rotationErrorDeg(a, b) <= check.max_correction_deg;
}

}  // namespace

std::optional<Relocalization> relocalize(
    const Localizer& localizer, const std::vector<Eigen::Vector3f>& centroids,
    const Eigen::MatrixXf& descriptors,
    const std::vector<std::vector<Eigen::Vector3f>>& segment_points,
    const Eigen::Vector3d& robot_local, const RelocalizationConfig& config,
    const std::optional<RelocalizationPrior>& prior) {
  if (static_cast<size_t>(descriptors.rows()) != centroids.size() ||
      segment_points.size() != centroids.size())
    throw std::invalid_argument("relocalize: one descriptor and point set per centroid expected");
  const TargetMap& map = localizer.map();
  if (centroids.size() < static_cast<size_t>(config.verification.min_inliers) || map.size() == 0)
    return std::nullopt;
  const int k = std::min<int>(config.k, static_cast<int>(map.size()));
  const Neighbours nn = localizer.index().search(descriptors, k);
  PlaceGrid grid(map, config.cell_m);
  // A candidate's vote weighs less the further down its local segment's list it is: the right
  // place's candidates tend to be among the first, a look-alike place's anywhere.
  for (size_t q = 0; q < centroids.size(); ++q)
    for (int j = 0; j < nn.k && nn.id(q, j) >= 0; ++j)
      grid.vote(static_cast<int>(q), map.segments[static_cast<size_t>(nn.id(q, j))].centroid,
                config.place_radius_m, 1.0 / (1.0 + static_cast<double>(j) / config.k_in_place));
  std::vector<Relocalization> accepted;
  std::vector<Pose> checked;
  size_t verified = 0;
  // min_votes local segments, each voting with a candidate at k_in_place down its list (weight
  // 1/2), at the least.
  const double min_votes = static_cast<double>(config.min_votes) / 2.0;
  for (const auto& place : grid.best(config.max_places, min_votes, config.place_radius_m, prior)) {
    const std::vector<Correspondence> candidates =
        candidatesIn(nn, map, centroids, place.centre, config);
    const VerificationResult v = verify(candidates, config.verification);
    ++verified;
    if (!v.found) continue;
    Relocalization r;
    r.match = localizationOf(v, candidates);
    // Places closer than two radii share segments, and a weaker neighbour of a place often
    // verifies to the same pose: its check would repeat one already made.
    if (std::any_of(checked.begin(), checked.end(), [&](const Pose& T) {
          return samePose(T, r.match.T_map_local, robot_local, config.check);
        }))
      continue;
    checked.push_back(r.match.T_map_local);
    r.check =
        checkRegistration(segment_points, robot_local, map, r.match.T_map_local, config.check);
    r.votes = place.votes;
    if (!r.check.accepted) continue;
    r.match.T_map_local = r.check.T_map_local;
    accepted.push_back(std::move(r));
  }
  if (accepted.empty()) return std::nullopt;
  // Two places that both fit, far apart: the scan cannot tell them apart.
  const Eigen::Vector3d first = accepted[0].match.T_map_local * robot_local;
  for (const Relocalization& r : accepted)
    if ((r.match.T_map_local * robot_local - first).norm() > config.check.max_correction_m)
      return std::nullopt;
  Relocalization best = *std::max_element(accepted.begin(), accepted.end(),
                                          [](const Relocalization& a, const Relocalization& b) {
                                            return a.check.fitness < b.check.fitness;
                                          });
  best.places_verified = verified;
  return best;
}

}  // namespace semsegmap
