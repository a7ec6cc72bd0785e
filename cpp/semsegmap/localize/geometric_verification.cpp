#include "semsegmap/localize/geometric_verification.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace semsegmap {
namespace {

using Graph = std::vector<std::vector<int>>;
using Bits = std::vector<uint64_t>;
using Cell = std::pair<int64_t, int64_t>;

// A correspondence as the partition reads it: sorted by cell and contiguous.
struct Entry {
  Eigen::Vector3d target, local;
  int64_t local_id, target_id;
  int index;
  Cell cell;
};

Graph consistencyGraph(const std::vector<Correspondence>& c, double resolution) {
  Graph g(c.size());
  std::vector<Entry> e;
  for (size_t i = 0; i < c.size(); ++i)
    if (c[i].local.allFinite() && c[i].target.allFinite())
      e.push_back(
          {c[i].target, c[i].local, c[i].local_id, c[i].target_id, static_cast<int>(i), {}});
  if (e.size() < 2) return g;
  // No two local centroids are further apart than twice their radius about the mean, so targets
  // further apart (plus the tolerance) cannot be consistent: in cells of that size (SegMap
  // partitioned the map likewise) only pairs in the same or adjacent cells need a test.
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Entry& x : e) mean += x.local;
  mean /= static_cast<double>(e.size());
  double radius = 0;
  for (const Entry& x : e) radius = std::max(radius, (x.local - mean).norm());
  const double reach = std::max(2 * radius + resolution, 1e-3);
  auto index = [&](double v) {
    return static_cast<int64_t>(std::clamp(std::floor(v / reach), -1e15, 1e15));
  };
  for (Entry& x : e) x.cell = {index(x.target.x()), index(x.target.y())};
  std::sort(e.begin(), e.end(), [](const Entry& a, const Entry& b) {
    return std::tie(a.cell, a.index) < std::tie(b.cell, b.index);
  });
  auto connect = [&](const Entry& a, const Entry& b) {
    // One segment per clique on either side; id -1 is no segment in particular.
    if ((a.local_id >= 0 && a.local_id == b.local_id) ||
        (a.target_id >= 0 && a.target_id == b.target_id))
      return;
    const double dt2 = (a.target - b.target).squaredNorm();
    if (dt2 > reach * reach) return;  // before any square root
    if (std::abs((a.local - b.local).norm() - std::sqrt(dt2)) > resolution) return;
    g[a.index].push_back(b.index);
    g[b.index].push_back(a.index);
  };
  auto cellRange = [&](const Cell& key) {
    auto begin = std::lower_bound(e.begin(), e.end(), key,
                                  [](const Entry& x, const Cell& k) { return x.cell < k; });
    auto end = begin;
    while (end != e.end() && end->cell == key) ++end;
    return std::make_pair(begin, end);
  };
  // Each pair once: its own cell, then the four neighbours that follow it in the sort order.
  for (auto first = e.begin(); first != e.end();) {
    const auto [begin, end] = cellRange(first->cell);
    for (auto a = begin; a != end; ++a)
      for (auto b = a + 1; b != end; ++b) connect(*a, *b);
    for (const auto& [dx, dy] : {Cell{0, 1}, Cell{1, -1}, Cell{1, 0}, Cell{1, 1}}) {
      const auto [nb, ne] = cellRange({first->cell.first + dx, first->cell.second + dy});
      for (auto a = begin; a != end; ++a)
        for (auto b = nb; b != ne; ++b) connect(*a, *b);
    }
    first = end;
  }
  return g;
}

// Batagelj-Zaversnik core decomposition: a vertex has at most core[v] neighbours after it in
// `order`, and no clique through v is larger than core[v] + 1.
struct Degeneracy {
  std::vector<int> order, position, core;
};

Degeneracy degeneracy(const Graph& g) {
  const int n = static_cast<int>(g.size());
  Degeneracy d{std::vector<int>(n), std::vector<int>(n), std::vector<int>(n)};
  size_t max_degree = 0;
  for (int v = 0; v < n; ++v) max_degree = std::max(max_degree, g[v].size());
  // bin[k]: where the vertices of current degree k begin in `order`.
  std::vector<int> bin(max_degree + 1, 0);
  for (int v = 0; v < n; ++v) ++bin[d.core[v] = static_cast<int>(g[v].size())];
  std::exclusive_scan(bin.begin(), bin.end(), bin.begin(), 0);
  std::vector<int> fill = bin;
  for (int v = 0; v < n; ++v) d.order[d.position[v] = fill[d.core[v]]++] = v;
  for (int i = 0; i < n; ++i) {
    const int v = d.order[i];
    for (int u : g[v]) {
      if (d.core[u] <= d.core[v]) continue;
      // Move u to the front of its bin, then shrink the bin past it: u's degree drops by one.
      const int du = d.core[u], pu = d.position[u], pw = bin[du];
      std::swap(d.position[u], d.position[d.order[pw]]);
      std::swap(d.order[pu], d.order[pw]);
      ++bin[du], --d.core[u];
    }
  }
  return d;
}

// Maximum clique, ties broken by the smaller summed descriptor distance. Cliques smaller than
// min_inliers are of no interest, which prunes most of a graph of random outliers at once.
class CliqueSearch {
 public:
  CliqueSearch(const Graph& g, const std::vector<Correspondence>& c,
               const GeometricVerificationConfig& cfg)
      : g_(g), c_(c), cfg_(cfg), local_index_(g.size(), -1) {}

  void run() {
    const Degeneracy d = degeneracy(g_);
    // Edges towards later vertices only: each edge once, and at most core[v] of them.
    later_.resize(g_.size());
    for (size_t v = 0; v < g_.size(); ++v)
      for (int w : g_[v])
        if (d.position[w] > d.position[v]) later_[v].push_back(w);
    // Highest cores first: the large cliques lie there and raise the bound early.
    for (auto it = d.order.rbegin(); it != d.order.rend() && !stop_; ++it) searchFrom(*it, d);
  }

  std::vector<int> best;
  double best_distance = 0;
  bool complete = true;
  size_t nodes = 0;

 private:
  static bool anyBit(const Bits& b) {
    return std::any_of(b.begin(), b.end(), [](uint64_t w) { return w != 0; });
  }
  size_t need() const {
    return best.empty() ? static_cast<size_t>(std::max(cfg_.min_inliers, 1)) : best.size();
  }
  // A branch whose size bound equals the best size can only win the tie-break.
  bool prune(size_t bound, double distance) const {
    return bound < need() || (bound == need() && !best.empty() && distance >= best_distance);
  }

  // Cliques whose earliest vertex in the degeneracy order is v.
  void searchFrom(int v, const Degeneracy& d) {
    if (static_cast<size_t>(d.core[v]) + 1 < need()) return;
    members_.clear();
    for (int w : later_[v])
      if (static_cast<size_t>(d.core[w]) + 1 >= need()) members_.push_back(w);
    if (members_.size() + 1 < need()) return;
    // Greedy colouring visits vertices in this order; high degree first gives fewer colours.
    std::sort(members_.begin(), members_.end(), [&](int a, int b) {
      return g_[a].size() != g_[b].size() ? g_[a].size() > g_[b].size() : a < b;
    });
    const size_t m = members_.size();
    words_ = (m + 63) / 64;
    adjacency_.assign(m * words_, 0);
    for (size_t i = 0; i < m; ++i) local_index_[members_[i]] = static_cast<int>(i);
    for (size_t i = 0; i < m; ++i)
      for (int u : later_[members_[i]])
        if (const int j = local_index_[u]; j >= 0) {
          adjacency_[i * words_ + j / 64] |= 1ULL << (j % 64);
          adjacency_[j * words_ + i / 64] |= 1ULL << (i % 64);
        }
    for (int w : members_) local_index_[w] = -1;
    current_.assign(1, v);
    Bits candidates(words_, 0);
    for (size_t i = 0; i < m; ++i) candidates[i / 64] |= 1ULL << (i % 64);
    expand(candidates, c_[v].descriptor_distance);
  }

  // Tomita-style branch and bound: colour the candidates greedily (a colour class is an
  // independent set, so the number of colours bounds the clique they can add), then branch on
  // the vertices of the highest colours first.
  void expand(Bits candidates, double distance) {
    if (++nodes > cfg_.max_search_nodes) stop_ = true, complete = false;
    if (stop_) return;
    if (!anyBit(candidates)) {  // nothing can join: a maximal clique
      if (current_.size() >= need() &&
          (best.empty() || current_.size() > best.size() || distance < best_distance))
        best = current_, best_distance = distance;
      return;
    }
    std::vector<int> order, colour;
    Bits uncoloured = candidates, open(words_);
    for (int k = 1; anyBit(uncoloured); ++k) {
      open = uncoloured;
      for (size_t w = 0; w < words_; ++w) {
        while (open[w] != 0) {
          const int i = static_cast<int>(w * 64) + __builtin_ctzll(open[w]);
          uncoloured[w] &= ~(1ULL << (i % 64)), open[w] &= ~(1ULL << (i % 64));
          for (size_t x = w; x < words_; ++x) open[x] &= ~adjacency_[i * words_ + x];
          order.push_back(i);
          colour.push_back(k);
        }
      }
    }
    Bits next(words_);
    for (size_t n = order.size(); n-- > 0;) {
      if (prune(current_.size() + colour[n], distance)) return;
      const int i = order[n];
      const double d = distance + c_[members_[i]].descriptor_distance;
      current_.push_back(members_[i]);
      for (size_t w = 0; w < words_; ++w) next[w] = candidates[w] & adjacency_[i * words_ + w];
      expand(next, d);
      current_.pop_back();
      candidates[i / 64] &= ~(1ULL << (i % 64));
      if (stop_) return;
    }
  }

  const Graph& g_;
  const std::vector<Correspondence>& c_;
  const GeometricVerificationConfig& cfg_;
  std::vector<std::vector<int>> later_;
  std::vector<int> local_index_, members_, current_;
  Bits adjacency_;
  size_t words_ = 0;
  bool stop_ = false;
};

// Standard deviation of the local centroids across their main axis.
double lateralSpread(const std::vector<Correspondence>& c, const std::vector<int>& subset) {
  Eigen::Matrix3Xd p(3, subset.size());
  for (size_t i = 0; i < subset.size(); ++i)
    p.col(static_cast<Eigen::Index>(i)) = c[subset[i]].local;
  p.colwise() -= p.rowwise().mean();
  const Eigen::Matrix3d cov = p.lazyProduct(p.transpose()) / static_cast<double>(p.cols());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues()(1)));
}

}  // namespace

Pose rigidFit(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to) {
  if (from.size() != to.size()) throw std::invalid_argument("rigidFit: point sets differ in size");
  Pose T = Pose::Identity();
  if (from.empty()) return T;
  // A vector of Vector3d is a packed 3 x n matrix.
  const auto n = static_cast<Eigen::Index>(from.size());
  const Eigen::Map<const Eigen::Matrix3Xd> F(from[0].data(), 3, n), G(to[0].data(), 3, n);
  const Eigen::Vector3d mf = F.rowwise().mean(), mt = G.rowwise().mean();
  // lazyProduct: a 3 x 3 result needs no GEMM (which -fopenmp would make multi-threaded).
  const Eigen::Matrix3d H = (F.colwise() - mf).lazyProduct((G.colwise() - mt).transpose());
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // R = V U^T maximises trace(R H); when that is a reflection, flipping the axis of the
  // smallest singular value gives the best proper rotation.
  Eigen::Vector3d s(1, 1, 1);
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) s(2) = -1;
  T.linear() = svd.matrixV() * s.asDiagonal() * svd.matrixU().transpose();
  T.translation() = mt - T.linear() * mf;
  return T;
}

VerificationResult verify(const std::vector<Correspondence>& correspondences,
                          const GeometricVerificationConfig& config) {
  VerificationResult result;
  const Graph g = consistencyGraph(correspondences, config.resolution_m);
  CliqueSearch search(g, correspondences, config);
  search.run();
  result.clique_size = search.best.size();
  result.search_complete = search.complete;
  result.search_nodes = search.nodes;
  const auto min_inliers = static_cast<size_t>(std::max(config.min_inliers, 1));
  std::vector<int> inliers = search.best;
  if (inliers.size() < min_inliers) return result;
  std::sort(inliers.begin(), inliers.end());

  // Without refinement the clique's fit is final; with it, refit on the members that pass until
  // all do (the set shrinks every round, so this ends).
  auto fit = [&](const std::vector<int>& subset) {
    std::vector<Eigen::Vector3d> from, to;
    for (int i : subset)
      from.push_back(correspondences[i].local), to.push_back(correspondences[i].target);
    return rigidFit(from, to);
  };
  Pose T = fit(inliers);
  for (;;) {
    std::vector<int> kept;
    for (int i : inliers) {
      const Correspondence& c = correspondences[i];
      if ((T * c.local - c.target).norm() <= config.inlier_tolerance_m) kept.push_back(i);
    }
    if (kept.size() < min_inliers) return result;
    const bool settled = !config.refine || kept.size() == inliers.size();
    inliers = std::move(kept);
    if (settled) break;
    T = fit(inliers);
  }
  if (lateralSpread(correspondences, inliers) < config.min_spread_m) return result;
  result.found = true;
  result.T_target_local = T;
  result.inliers = std::move(inliers);
  return result;
}

}  // namespace semsegmap
