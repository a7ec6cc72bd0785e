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

// The robot at `robot` under both poses within m metres, and the poses within deg degrees.
bool within(const Pose& a, const Pose& b, const Eigen::Vector3d& robot, double m, double deg) {
  return (a * robot - b * robot).norm() <= m && rotationErrorDeg(a, b) <= deg;
}

// The robot within the check's own tolerance in both: registration would take one to the other.
bool samePose(const Pose& a, const Pose& b, const Eigen::Vector3d& robot_local,
              const RegistrationCheckConfig& check) {
  return within(a, b, robot_local, check.max_correction_m, check.max_correction_deg);
}

// The proposals' registration checks. Proposals are queued in the order they were made, the
// scan context's last; a proposal that puts the robot where an earlier one did is not checked
// again (neighbouring places share segments, and a weaker one often verifies to the same pose).
// The checks then run side by side: each registers the scan on its own place's points, tens of
// milliseconds for a wrong place, and a lost frame checks ten or twenty.
class Checks {
 public:
  Checks(const std::vector<std::vector<Eigen::Vector3f>>& points,
         const Eigen::Vector3d& robot_local, const TargetMap& map,
         const RelocalizationConfig& relocalization, const std::optional<ScanContextQuery>& scan)
      : points_(points),
        robot_local_(robot_local),
        map_(map),
        relocalization_(relocalization),
        config_(relocalization.check),
        scan_(scan) {}

  // The scan context's pose is checked whatever was proposed before, and is no reason to skip a
  // place after it: a voted place's clique can start the registration metres off where the scan
  // context's starts within one, and the other way round.
  void propose(Relocalization r) {
    const Pose& T = r.match.T_map_local;
    if (!r.by_scan_context) {
      segment_proposals_.push_back(T);
      if (std::any_of(queued_.begin(), queued_.end(), [&](const Relocalization& q) {
            return !q.by_scan_context && samePose(q.match.T_map_local, T, robot_local_, config_);
          }))
        return;
    }
    queued_.push_back(std::move(r));
  }

  // Every queued proposal's check, then the verdicts in the order they were proposed, so that the
  // result does not depend on which thread finished first.
  void run() {
    const int n = static_cast<int>(queued_.size());
    std::vector<RegistrationCheck> checked(queued_.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (int i = 0; i < n; ++i)
      checked[static_cast<size_t>(i)] = checkRegistration(
          points_, robot_local_, map_, queued_[static_cast<size_t>(i)].match.T_map_local, config_);
    for (size_t i = 0; i < queued_.size(); ++i) judge(std::move(queued_[i]), std::move(checked[i]));
    queued_.clear();
    acceptWhereTheSegmentsAgree();
  }

  struct Registered {
    Pose T_map_local;
    double fitness = 0.0;
  };
  std::vector<Relocalization> accepted;
  std::vector<Registered> registered;  // every proposal checked, accepted or not

 private:
  void judge(Relocalization r, RegistrationCheck check) {
    r.check = std::move(check);
    // Only the segments' proposals: the scan context cannot corroborate its own, and its own has
    // the heading of its mapped scan.
    if (!r.by_scan_context) {
      corroborate(r.check, map_, scan_, relocalization_);
      refuseAContradictedHeading(r.check, map_, scan_, relocalization_);
    }
    registered.push_back({r.check.T_map_local, r.check.fitness});
    if (r.by_scan_context && !r.check.accepted && shortOfFitnessOnly(r.check))
      short_of_fitness_.push_back(r);
    if (!r.check.accepted) return;
    r.match.T_map_local = r.check.T_map_local;
    accepted.push_back(std::move(r));
  }

  // The scan context's proposals that registered short of min_fitness but at least
  // scan_context_min_fitness, accepted where the segments, the other kind of evidence, proposed
  // the same pose with a clique of their own (whatever that clique's own check said: its start
  // may lie metres off, where the check's cheap refusal stops it), or where no other place of
  // the map looks nearly as alike to the whole scan (scan_context_distinct_ratio): a straight
  // road or a row of alike houses puts the scan near many mapped scans, and is refused.
  void acceptWhereTheSegmentsAgree() {
    for (Relocalization& r : short_of_fitness_) {
      const bool agree = std::any_of(
          segment_proposals_.begin(), segment_proposals_.end(),
          [&](const Pose& T) { return samePose(T, r.check.T_map_local, robot_local_, config_); });
      // Distances of identical scan contexts come out a rounding error below 0.
      const bool distinct =
          std::max(0.0, r.scan_context_distance) <
          relocalization_.scan_context_distinct_ratio * std::max(0.0, r.scan_context_rival);
      if (!agree && !distinct) continue;
      r.check.accepted = true;
      r.check.reason.clear();
      r.match.T_map_local = r.check.T_map_local;
      accepted.push_back(r);
    }
  }

  bool shortOfFitnessOnly(const RegistrationCheck& c) const {
    return c.points > 0 && c.fitness >= relocalization_.scan_context_min_fitness &&
           c.correction_m <= config_.max_correction_m &&
           c.correction_deg <= config_.max_correction_deg;
  }
  std::vector<Relocalization> queued_;
  std::vector<Pose> segment_proposals_;  // every clique's pose, checked or not
  std::vector<Relocalization> short_of_fitness_;
  const std::vector<std::vector<Eigen::Vector3f>>& points_;
  Eigen::Vector3d robot_local_;
  const TargetMap& map_;
  const RelocalizationConfig& relocalization_;
  const RegistrationCheckConfig& config_;
  const std::optional<ScanContextQuery>& scan_;
};

// Steps 1 and 2 (relocalizer.h): the places the local segments vote for, each verified with the
// candidates in it. Returns the number of places verified.
size_t checkVotedPlaces(const Localizer& localizer, const std::vector<Eigen::Vector3f>& centroids,
                        const Eigen::MatrixXf& descriptors, const RelocalizationConfig& config,
                        const std::optional<RelocalizationPrior>& prior, Checks& checks) {
  const TargetMap& map = localizer.map();
  if (centroids.size() < static_cast<size_t>(config.verification.min_inliers)) return 0;
  const int k = std::min<int>(config.k, static_cast<int>(map.size()));
  const Neighbours nn = localizer.index().search(descriptors, k);
  PlaceGrid grid(map, config.cell_m);
  // A candidate's vote weighs less the further down its local segment's list it is: the right
  // place's candidates tend to be among the first, a look-alike place's anywhere.
  for (size_t q = 0; q < centroids.size(); ++q)
    for (int j = 0; j < nn.k && nn.id(q, j) >= 0; ++j)
      grid.vote(static_cast<int>(q), map.segments[static_cast<size_t>(nn.id(q, j))].centroid,
                config.place_radius_m, 1.0 / (1.0 + static_cast<double>(j) / config.k_in_place));
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
    r.votes = place.votes;
    checks.propose(std::move(r));
  }
  return verified;
}

// The nearest scan context of a mapped scan farther than kRivalM from `best`'s, among the
// `candidates` of nearest ring keys: how alike another place looks to the scan. 1 (nothing in
// common) when none is.
constexpr double kRivalM = 20.0;
double rivalDistance(const std::vector<ScanContextMatch>& nearest, const ScanContextMatch& best) {
  for (const ScanContextMatch& m : nearest)
    if ((m.T_world_candidate.translation() - best.T_world_candidate.translation()).norm() > kRivalM)
      return m.distance.distance;
  return 1.0;
}

// The mapped scan whose scan context is nearest the scan's, turned by their yaw.
void checkScanContext(const TargetMap& map, const ScanContextQuery& scan,
                      const Eigen::Vector3d& robot_local, const RelocalizationConfig& config,
                      const std::optional<RelocalizationPrior>& prior, Checks& checks) {
  // Five times the candidates compared in full: enough to find another place that looks alike.
  const size_t candidates = 5 * config.scan_context_candidates;
  const std::vector<ScanContextMatch> nearest =
      map.scan_contexts.nearest(scan.context, candidates, candidates);
  if (nearest.empty() || nearest.front().distance.distance >= config.scan_context_max_distance)
    return;
  const ScanContextMatch& m = nearest.front();
  Relocalization r;
  r.match.T_map_local = m.T_world_query() * scan.T_local_scan.inverse();
  r.by_scan_context = true;
  r.scan_context_distance = m.distance.distance;
  r.scan_context_rival = rivalDistance(nearest, m);
  if (prior && ((r.match.T_map_local * robot_local).head<2>() - prior->position.head<2>()).norm() >
                   prior->radius_m)
    return;
  checks.propose(std::move(r));
}

// The best place against the others: another accepted place far from it, or one that
// registered nearly as well, makes the pose ambiguous.
void judgeDistinctiveness(Relocalization& best, const Checks& checks,
                          const Eigen::Vector3d& robot_local, const RelocalizationConfig& config) {
  const Eigen::Vector3d at = best.match.T_map_local * robot_local;
  const auto elsewhere = [&](const Pose& T) {
    return (T * robot_local - at).norm() > config.check.max_correction_m;
  };
  for (const Relocalization& r : checks.accepted)
    if (elsewhere(r.match.T_map_local)) best.ambiguous = true;
  for (const Checks::Registered& r : checks.registered)
    if (elsewhere(r.T_map_local))
      best.runner_up_fitness = std::max(best.runner_up_fitness, r.fitness);
  if (best.runner_up_fitness >= config.ambiguity_ratio * best.check.fitness) best.ambiguous = true;
}

}  // namespace

bool jumpsFrom(const Pose& held, const Pose& given, const RelocalizationConfig& config) {
  return !within(held, given, Eigen::Vector3d::Zero(), config.jump_m, config.jump_deg);
}

namespace {

struct NearbyScan {
  double distance = 1.0;    // of its scan context to the scan's
  bool yaw_agrees = false;  // the pose's yaw within two sectors of the one their contexts give
};

// The mapped scans within 10 m of where T_map_local puts the scan.
std::vector<NearbyScan> mappedScansNear(const TargetMap& map, const ScanContextQuery& scan,
                                        const Pose& T_map_local) {
  constexpr double kNearM = 10.0;
  const Pose T_map_scan = T_map_local * scan.T_local_scan;
  const double sector = 2.0 * M_PI / static_cast<double>(map.scan_contexts.config().sectors);
  std::vector<NearbyScan> out;
  for (const ScanContextDatabase::MappedScan& m : map.scan_contexts.scans()) {
    if ((m.T_world_scan.translation() - T_map_scan.translation()).norm() > kNearM) continue;
    const ScanContextDistance d = scanContextDistance(scan.context, m.context);
    // The yaw the pose gives between the mapped scan's frame and the scan's, against theirs.
    const double yaw = yawOf(m.T_world_scan.inverse() * T_map_scan);
    out.push_back(
        {d.distance, std::abs(std::remainder(yaw - d.yaw_rad, 2.0 * M_PI)) <= 2.0 * sector});
  }
  return out;
}

}  // namespace

bool scanContextAgrees(const TargetMap& map, const ScanContextQuery& scan, const Pose& T_map_local,
                       const RelocalizationConfig& config) {
  const std::vector<NearbyScan> near = mappedScansNear(map, scan, T_map_local);
  return std::any_of(near.begin(), near.end(), [&](const NearbyScan& s) {
    return s.yaw_agrees && s.distance < config.scan_context_max_distance;
  });
}

bool headingContradicted(const TargetMap& map, const ScanContextQuery& scan,
                         const Pose& T_map_local) {
  const std::vector<NearbyScan> near = mappedScansNear(map, scan, T_map_local);
  return !near.empty() &&
         std::none_of(near.begin(), near.end(), [](const NearbyScan& s) { return s.yaw_agrees; });
}

void refuseAContradictedHeading(RegistrationCheck& check, const TargetMap& map,
                                const std::optional<ScanContextQuery>& scan,
                                const RelocalizationConfig& config) {
  if (!check.accepted || !scan || !config.scan_context) return;
  if (!headingContradicted(map, *scan, check.T_map_local)) return;
  check.accepted = false;
  check.reason = "the map's scans nearby contradict its heading";
}

void corroborate(RegistrationCheck& check, const TargetMap& map,
                 const std::optional<ScanContextQuery>& scan, const RelocalizationConfig& config) {
  if (check.accepted || !scan || !config.scan_context || check.points == 0) return;
  // Only a registration that ran to the end and kept to its bounds, short of the fitness.
  if (check.fitness < config.scan_context_min_fitness ||
      check.correction_m > config.check.max_correction_m ||
      check.correction_deg > config.check.max_correction_deg)
    return;
  if (!scanContextAgrees(map, *scan, check.T_map_local, config)) return;
  check.accepted = true;
  check.reason.clear();
}

std::optional<Relocalization> relocalize(
    const Localizer& localizer, const std::vector<Eigen::Vector3f>& centroids,
    const Eigen::MatrixXf& descriptors,
    const std::vector<std::vector<Eigen::Vector3f>>& segment_points,
    const Eigen::Vector3d& robot_local, const RelocalizationConfig& config,
    const std::optional<RelocalizationPrior>& prior, const std::optional<ScanContextQuery>& scan) {
  if (static_cast<size_t>(descriptors.rows()) != centroids.size() ||
      segment_points.size() != centroids.size())
    throw std::invalid_argument("relocalize: one descriptor and point set per centroid expected");
  const TargetMap& map = localizer.map();
  if (map.size() == 0) return std::nullopt;
  Checks checks(segment_points, robot_local, map, config, scan);
  const size_t verified =
      checkVotedPlaces(localizer, centroids, descriptors, config, prior, checks);
  if (scan && config.scan_context) checkScanContext(map, *scan, robot_local, config, prior, checks);
  checks.run();
  const std::vector<Relocalization>& accepted = checks.accepted;
  if (accepted.empty()) return std::nullopt;
  Relocalization best = *std::max_element(accepted.begin(), accepted.end(),
                                          [](const Relocalization& a, const Relocalization& b) {
                                            return a.check.fitness < b.check.fitness;
                                          });
  best.places_verified = verified;
  judgeDistinctiveness(best, checks, robot_local, config);
  return best;
}

}  // namespace semsegmap
