#include "semsegmap/io/ros_tf.h"

#include <algorithm>
#include <stdexcept>

#include "semsegmap/io/ros_decode.h"

namespace semsegmap::rosmsg {

std::string tfFrameName(const std::string& frame_id) {
  return !frame_id.empty() && frame_id[0] == '/' ? frame_id.substr(1) : frame_id;
}

void TfBuffer::add(const TransformStamped& t, bool is_static) {
  const std::string parent = tfFrameName(t.header.frame_id);
  const std::string child = tfFrameName(t.child_frame_id);
  if (parent == child) throw std::invalid_argument("transform of frame '" + child + "' to itself");
  const Pose T = poseOf(t.transform);
  Edge& e = edges_[child];
  if (e.parent != parent || e.is_static != is_static) {
    e = Edge{};
    e.parent = parent;
    e.is_static = is_static;
  }
  if (is_static) {
    e.T_parent_child = T;
    return;
  }
  // Bags are in receive order, which is nearly stamp order: insert in place.
  const StampedPose sample{t.header.stamp_s, T};
  auto later = std::upper_bound(e.samples.begin(), e.samples.end(), sample.timestamp_s,
                                [](double s, const StampedPose& p) { return s < p.timestamp_s; });
  e.samples.insert(later, sample);
}

bool TfBuffer::hasFrame(const std::string& frame) const {
  const std::string name = tfFrameName(frame);
  if (edges_.count(name)) return true;
  for (const auto& [child, e] : edges_)
    if (e.parent == name) return true;
  return false;
}

std::vector<std::string> TfBuffer::chainToRoot(const std::string& frame) const {
  std::vector<std::string> chain{frame};
  // A cycle (a broken recording) must not loop forever: a chain visits each edge at most once.
  while (chain.size() <= edges_.size()) {
    auto it = edges_.find(chain.back());
    if (it == edges_.end()) break;
    chain.push_back(it->second.parent);
  }
  return chain;
}

std::optional<Pose> TfBuffer::edgePose(const std::string& child, const Edge& e, double t,
                                       std::string* why) const {
  if (e.is_static) return e.T_parent_child;
  const auto& s = e.samples;
  if (!s.empty() && t < s.front().timestamp_s && s.front().timestamp_s - t <= max_extrapolation_s_)
    return s.front().T;
  if (!s.empty() && t > s.back().timestamp_s && t - s.back().timestamp_s <= max_extrapolation_s_)
    return s.back().T;
  if (auto T = poseAt(s, t, max_gap_s_)) return T;
  if (why)
    *why = "transform '" + e.parent + "' -> '" + child +
           "' has no sample around t = " + std::to_string(t) + " s (" + std::to_string(s.size()) +
           " samples" +
           (s.empty() ? std::string()
                      : ", from " + std::to_string(s.front().timestamp_s) + " to " +
                            std::to_string(s.back().timestamp_s) + " s") +
           ")";
  return std::nullopt;
}

std::optional<Pose> TfBuffer::poseInAncestor(const std::vector<std::string>& chain, size_t ancestor,
                                             double t, std::string* why) const {
  Pose T_ancestor_frame = Pose::Identity();
  for (size_t i = ancestor; i-- > 0;) {
    const auto T = edgePose(chain[i], edges_.at(chain[i]), t, why);
    if (!T) return std::nullopt;
    T_ancestor_frame = T_ancestor_frame * *T;
  }
  return T_ancestor_frame;
}

std::optional<TfBuffer::Path> TfBuffer::path(const std::string& target,
                                             const std::string& source) const {
  Path p;
  p.up_source = chainToRoot(tfFrameName(source));
  p.up_target = chainToRoot(tfFrameName(target));
  for (p.source_steps = 0; p.source_steps < p.up_source.size(); ++p.source_steps) {
    auto j = std::find(p.up_target.begin(), p.up_target.end(), p.up_source[p.source_steps]);
    if (j == p.up_target.end()) continue;
    // up_source[source_steps] is the nearest common ancestor.
    p.target_steps = static_cast<size_t>(j - p.up_target.begin());
    return p;
  }
  return std::nullopt;
}

std::optional<Pose> TfBuffer::lookup(const std::string& target, const std::string& source, double t,
                                     std::string* why) const {
  if (const auto p = path(target, source)) {
    const auto T_anc_source = poseInAncestor(p->up_source, p->source_steps, t, why);
    const auto T_anc_target = poseInAncestor(p->up_target, p->target_steps, t, why);
    if (!T_anc_source || !T_anc_target) return std::nullopt;
    return T_anc_target->inverse() * *T_anc_source;
  }
  if (why) {
    std::string missing;
    for (const std::string* f : {&source, &target})
      if (!hasFrame(*f)) missing += (missing.empty() ? "'" : ", '") + tfFrameName(*f) + "'";
    *why = "no transform between '" + tfFrameName(target) + "' and '" + tfFrameName(source) +
           "' in /tf_static and /tf (" +
           (missing.empty() ? "they are not connected)" : "not in the tree: " + missing + ")");
  }
  return std::nullopt;
}

bool TfBuffer::isStatic(const std::string& target, const std::string& source) const {
  const auto p = path(target, source);
  if (!p) return false;
  // Only the edges below the common ancestor matter: those above it cancel.
  for (size_t i = 0; i < p->source_steps; ++i)
    if (!edges_.at(p->up_source[i]).is_static) return false;
  for (size_t i = 0; i < p->target_steps; ++i)
    if (!edges_.at(p->up_target[i]).is_static) return false;
  return true;
}

}  // namespace semsegmap::rosmsg
