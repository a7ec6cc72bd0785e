#include "semsegmap/semantics/frame_labeler.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace semsegmap {

namespace {

// The network on one picture, the run and its wall time counted in `stats`; `ms` is that time.
Image runNetwork(const LabelFunction& network, const Image& rgb, const std::string& what,
                 LabelingStats& stats, double& ms) {
  const auto clock = std::chrono::steady_clock::now();
  Image labels = network(rgb, what);
  ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - clock).count();
  stats.network_ms += ms;
  ++stats.network_runs;
  return labels;
}

}  // namespace

std::vector<size_t> camerasToLabel(const Frame& frame, const SemanticsConfig& config,
                                   LabelingStats& stats) {
  std::vector<size_t> cameras;
  for (size_t k = 0; k < frame.cameras.size(); ++k) {
    const CameraFrame& camera = frame.cameras[k];
    if (camera.rgb.empty()) continue;
    if (!camera.label.empty() && !config.replace_dataset_labels) {
      ++stats.kept;
      continue;
    }
    cameras.push_back(k);
  }
  return cameras;
}

bool labelsEveryPicture(const SemanticsConfig& config) {
  return config.rate_hz <= 0 && config.budget_cores <= 0 && config.latency_s <= 0;
}

void checkReplayable(const SemanticsConfig& config, const std::string& where) {
  if (config.budget_cores > 0 && config.latency_s <= 0)
    throw std::invalid_argument(where +
                                ": semantics.budget_cores: replaying a recording on a budget "
                                "needs semantics.latency_s, the network's time per picture "
                                "(BM_SegmentationNetwork measures it)");
}

LabelFunction networkFunction(std::shared_ptr<SegmentationNetwork> network) {
  return [network](const Image& rgb, const std::string& what) { return network->label(rgb, what); };
}

ReplayLabeler::ReplayLabeler(std::shared_ptr<SegmentationNetwork> network, const Pose& T_base_lidar)
    : ReplayLabeler(network->config(), networkFunction(network), T_base_lidar) {}

ReplayLabeler::ReplayLabeler(const SemanticsConfig& config, LabelFunction network,
                             const Pose& T_base_lidar)
    : config_(config),
      network_(std::move(network)),
      T_base_lidar_(T_base_lidar),
      schedule_(0, config.rate_hz, config.tolerance_s) {
  checkReplayable(config, "semantics");
}

void ReplayLabeler::restart() {
  schedule_ = LabelSchedule(schedule_.cameras(), config_.rate_hz, config_.tolerance_s);
  free_at_ = next_start_ = -std::numeric_limits<double>::infinity();
  started_ = false;
}

void ReplayLabeler::advance(double t, bool inclusive, const std::string& what) {
  // The worker's cycle: its time per picture, stretched so that its threads stay in the budget.
  const double threads = std::max(1, config_.threads);
  const double cycle =
      config_.budget_cores > 0
          ? std::max(config_.latency_s, config_.latency_s * threads / config_.budget_cores)
          : config_.latency_s;
  for (std::optional<size_t> k = schedule_.next(); k; k = schedule_.next()) {
    const double start = std::max({free_at_, next_start_, schedule_.pendingTime(*k)});
    if (inclusive ? start > t : start >= t) break;
    PendingPicture picture = schedule_.take(*k);
    double ms = 0.0;
    Image labels =
        runNetwork(network_, picture.rgb, what + ", camera " + std::to_string(*k), stats_, ms);
    stats_.busy_core_s += config_.latency_s * threads;  // replayed: the configured time counts
    free_at_ = start + config_.latency_s;
    next_start_ = start + cycle;
    schedule_.deliver(picture, std::move(labels), free_at_);
  }
}

void ReplayLabeler::labelEveryPicture(Frame& frame, const std::vector<size_t>& cameras,
                                      const std::string& what) {
  for (size_t k : cameras) {
    double ms = 0.0;
    frame.cameras[k].label = runNetwork(network_, frame.cameras[k].rgb,
                                        what + ", camera " + std::to_string(k), stats_, ms);
    frame.cameras[k].T_label_lidar.reset();
    // Not replayed: the share of the cores is what the network took here, against the data's time.
    stats_.busy_core_s += ms * 1e-3 * std::max(1, config_.threads);
    ++stats_.own;
  }
}

void ReplayLabeler::label(Frame& frame, const std::string& what) {
  const std::vector<size_t> cameras = camerasToLabel(frame, config_, stats_);
  if (cameras.empty()) return;
  frame.camera_semantics = true;
  const double t = frame.timestamp_s;
  // A source read again from its start (another experiment's pass) replays the budget anew.
  if (started_ && t < last_time_) restart();
  if (!started_) first_time_ = t;
  started_ = true;
  last_time_ = t;
  stats_.span_s = t - first_time_;
  if (labelsEveryPicture(config_)) return labelEveryPicture(frame, cameras, what);
  if (schedule_.cameras() < frame.cameras.size())
    schedule_ = LabelSchedule(frame.cameras.size(), config_.rate_hz, config_.tolerance_s);
  advance(t, false, what);  // runs that began before this scan's pictures came
  const Pose T_odom_lidar = frame.T_odom_base * T_base_lidar_;
  for (size_t k : cameras) schedule_.offer(k, t, frame.cameras[k].rgb, T_odom_lidar);
  advance(t, true, what);
  const AttachCounts counts = schedule_.attach(frame, cameras, T_odom_lidar, t);
  stats_.own += counts.own;
  stats_.reused += counts.earlier;
  stats_.unlabelled += counts.unlabelled;
}

}  // namespace semsegmap
