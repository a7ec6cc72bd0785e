#include "semsegmap/eval/fleet_experiment.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <numeric>
#include <set>
#include <stdexcept>

#include "semsegmap/artefacts/map_file.h"
#include "semsegmap/artefacts/model_file.h"
#include "semsegmap/core/atomic_file.h"
#include "semsegmap/datasets/open_dataset.h"
#include "semsegmap/pipeline/session_merge.h"
#include "semsegmap/settings/config.h"
#include "semsegmap/viz/trajectory_png.h"

namespace semsegmap {

namespace {

// Passes frames on and keeps each one's true pose: the experiment's truth, recorded as the runs
// read their frames rather than by reading (rendering) them again.
class TruthRecorder : public FrameSource {
 public:
  explicit TruthRecorder(std::unique_ptr<FrameSource> source) : source_(std::move(source)) {}
  const DatasetInfo& info() const override { return source_->info(); }
  size_t size() const override { return source_->size(); }
  Frame frame(size_t i) override {
    Frame f = source_->frame(i);
    if (!f.T_world_base) throw std::runtime_error("fleet experiment: a frame without ground truth");
    if (truth_.size() <= i) truth_.resize(i + 1, Pose::Identity());
    truth_[i] = *f.T_world_base;
    return f;
  }
  const std::vector<Pose>& truth() const { return truth_; }

 private:
  std::unique_ptr<FrameSource> source_;
  std::vector<Pose> truth_;
};

struct Setup {
  PipelineConfig config;
  DatasetOptions options;
  std::shared_ptr<Describer> describer;
};

// "S0,traffic=7" -> sim:world=..,run=S0,preset=..,traffic=7, on LiDAR odometry.
std::unique_ptr<TruthRecorder> openRun(const FleetExperimentConfig& c, const Setup& s,
                                       const std::string& run) {
  const size_t comma = run.find(',');
  const std::string spec =
      simulatedRunSpec(c.world_seed, run.substr(0, comma), c.preset, c.max_frames, 0,
                       comma == std::string::npos ? "" : run.substr(comma + 1));
  return std::make_unique<TruthRecorder>(openDataset(spec, s.options));
}

RunOptions runOptions(const FleetExperimentConfig& c, const std::string& stage) {
  RunOptions o;
  o.stop = c.stop;
  if (c.progress)
    o.progress = [&c, stage](size_t done, size_t total) { c.progress(stage, done, total); };
  return o;
}

double meanDistance(const std::vector<Pose>& estimate, const std::vector<Pose>& truth,
                    const Pose& T_world_map) {
  double sum = 0.0;
  const size_t n = std::min(estimate.size(), truth.size());
  for (size_t i = 0; i < n; ++i)
    sum += ((T_world_map * estimate[i]).translation() - truth[i].translation()).norm();
  return n ? sum / static_cast<double>(n) : 0.0;
}

// Per entry of the merged map, its centroid where its session's frame truly was; `frames` and
// `truth` per merged session: the poses in the map and the true ones.
std::vector<Eigen::Vector3d> trueCentroids(const TargetMap& map,
                                           const std::vector<std::vector<Pose>>& frames,
                                           const std::vector<std::vector<Pose>>& truth) {
  std::vector<Eigen::Vector3d> out;
  for (const MapSegment& s : map.segments) {
    const Pose& T_map_base = frames.at(s.session).at(s.keyframe);
    const Pose& T_world_base = truth.at(s.session).at(s.keyframe);
    out.push_back(T_world_base * (T_map_base.inverse() * s.centroid.cast<double>()));
  }
  return out;
}

// The one rigid alignment of the whole merged map to the world, its entries' distances after it
// into the sessions' rows, and the mean and median.
void judgeCentroids(FleetExperiment& e, const std::vector<size_t>& row_of_session,
                    const std::vector<std::vector<Pose>>& frames,
                    const std::vector<std::vector<Pose>>& truth) {
  const std::vector<Eigen::Vector3d> real = trueCentroids(e.merged, frames, truth);
  const auto n = static_cast<Eigen::Index>(real.size());
  if (n < 3) throw std::runtime_error("fleet experiment: a merged map of fewer than 3 entries");
  Eigen::Matrix3Xd src(3, n), dst(3, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    src.col(i) = e.merged.segments[static_cast<size_t>(i)].centroid.cast<double>();
    dst.col(i) = real[static_cast<size_t>(i)];
  }
  e.T_world_map.matrix() = Eigen::umeyama(src, dst, /*with_scaling=*/false);
  std::vector<double> d(static_cast<size_t>(n));
  std::vector<double> sum(e.sessions.size(), 0.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    d[static_cast<size_t>(i)] = (e.T_world_map * src.col(i) - dst.col(i)).norm();
    sum[row_of_session[e.merged.segments[static_cast<size_t>(i)].session]] +=
        d[static_cast<size_t>(i)];
  }
  for (size_t r = 0; r < e.sessions.size(); ++r)
    if (e.sessions[r].entries) e.sessions[r].centroid_error_m = sum[r] / e.sessions[r].entries;
  e.centroid_mean_m = std::accumulate(d.begin(), d.end(), 0.0) / static_cast<double>(n);
  std::nth_element(d.begin(), d.begin() + n / 2, d.end());
  e.centroid_median_m = d[static_cast<size_t>(n / 2)];
}

void countLocalizations(const LocalizationRun& run, const Pose& T_world_map, double wrong_m,
                        size_t& localizations, size_t& within_1m, size_t& wrong) {
  localizations = run.localizations.size();
  within_1m = wrong = 0;
  for (const LocalizationRecord& r : run.localizations) {
    if (!r.T_world_base) continue;
    const double error =
        ((T_world_map * r.T_map_base).translation() - r.T_world_base->translation()).norm();
    within_1m += error <= 1.0;
    wrong += error > wrong_m;
  }
}

}  // namespace

namespace {

// Session rows and the merged map; `frames`, `truth`, `row_of_session` per merged session.
void mergeSessions(FleetExperiment& e, const Setup& s, std::vector<std::vector<Pose>>& frames,
                   std::vector<std::vector<Pose>>& truth, std::vector<size_t>& row_of_session,
                   TargetMap& first) {
  const FleetExperimentConfig& c = e.config;
  for (size_t k = 0; k < c.sessions.size() && !e.interrupted; ++k) {
    const std::string& run = c.sessions[k];
    auto source = openRun(c, s, run);
    FleetSession row;
    row.run = run;
    if (k == 0) {
      MappingRun m = runMapping(*source, s.config, PoseSource::kOdometry, s.describer,
                                runOptions(c, "map " + run));
      e.interrupted = m.stats.interrupted;
      row.aligned = true;
      row.frames = m.stats.frames;
      row.entries = m.map.size();
      // The first session's trajectory is kept, so that its entries' frames are known too.
      m.map.sessions = {{run, 0, m.trajectory}};
      for (MapSegment& seg : m.map.segments) seg.session = 0;
      first = m.map;
      e.merged = std::move(m.map);
      frames.push_back(m.trajectory);
    } else {
      const MergedSession m = runSessionMerge(
          *source, s.config, std::make_shared<const TargetMap>(e.merged), s.describer, run,
          static_cast<int64_t>(k), PoseSource::kOdometry, runOptions(c, "join " + run));
      e.interrupted = m.mapping.stats.interrupted;
      row.aligned = m.aligned;
      row.frames = m.mapping.stats.frames;
      row.ties = m.ties.size();
      row.entries = m.entries;
      row.same_segments = m.same_segments;
      row.tie_residual_m = m.mean_tie_residual_m;
      if (m.aligned) {
        e.merged = m.map;
        frames.push_back(e.merged.sessions.back().trajectory);
      }
    }
    if (row.aligned) {
      truth.push_back(source->truth());
      row_of_session.push_back(e.sessions.size());
    }
    e.sessions.push_back(row);
  }
}

}  // namespace

FleetExperiment runFleetExperiment(const FleetExperimentConfig& config) {
  if (config.sessions.empty()) throw std::invalid_argument("fleet experiment: no sessions");
  FleetExperiment e;
  e.config = config;
  Setup s;
  s.config = loadNamedConfig(config.config).config;
  s.options.odometry = "lidar";
  s.options.lidar_odometry = loadOdometryConfig(config.config);
  s.describer = makeDescriber(s.config.descriptor);
  std::vector<std::vector<Pose>> frames, truth;
  std::vector<size_t> row_of_session;
  TargetMap first;
  mergeSessions(e, s, frames, truth, row_of_session, first);
  e.entries = e.merged.size();
  std::set<uint32_t> ids;
  for (const MapSegment& seg : e.merged.segments) ids.insert(seg.segment);
  e.segments = ids.size();
  judgeCentroids(e, row_of_session, frames, truth);
  e.trajectories = frames;
  e.truths = truth;
  for (size_t r = 0; r < row_of_session.size(); ++r)
    e.sessions[row_of_session[r]].trajectory_error_m =
        meanDistance(frames[r], truth[r], e.T_world_map);
  const auto merged = std::make_shared<const TargetMap>(e.merged);
  const auto alone = std::make_shared<const TargetMap>(std::move(first));
  for (const std::string& run : config.queries) {
    if (e.interrupted) break;
    FleetQuery q;
    q.run = run;
    for (const bool against_merged : {true, false}) {
      auto source = openRun(config, s, run);
      const LocalizationRun l = runLocalization(
          *source, s.config, against_merged ? merged : alone, s.describer,
          runOptions(config, "localize " + run +
                                 (against_merged ? " in the merged map" : " in the first map")));
      e.interrupted = e.interrupted || l.stats.interrupted;
      q.frames = l.stats.frames;
      if (against_merged)
        countLocalizations(l, e.T_world_map, config.wrong_m, q.localizations_merged,
                           q.within_1m_merged, q.wrong_merged);
      else
        countLocalizations(l, e.T_world_map, config.wrong_m, q.localizations_first,
                           q.within_1m_first, q.wrong_first);
    }
    e.queries.push_back(q);
  }
  return e;
}

std::string fleetTable(const FleetExperiment& e) {
  std::string t =
      "| session | frames | aligned | localizations | entries | of segments held | tie residual "
      "| trajectory error | centroid error |\n| --- | ---: | --- | ---: | ---: | ---: | ---: | "
      "---: | ---: |\n";
  char line[512];
  for (const FleetSession& s : e.sessions) {
    std::snprintf(line, sizeof line,
                  "| %s | %zu | %s | %zu | %zu | %zu | %.2f m | %.2f m | %.2f m |\n", s.run.c_str(),
                  s.frames, s.aligned ? (s.ties ? "yes" : "map frame") : "no", s.ties, s.entries,
                  s.same_segments, s.tie_residual_m, s.trajectory_error_m, s.centroid_error_m);
    t += line;
  }
  std::snprintf(line, sizeof line,
                "\nMerged map: %zu entries of %zu segments; centroids %.2f m from the truth on "
                "average (median %.2f m) after one rigid alignment to the world.\n",
                e.entries, e.segments, e.centroid_mean_m, e.centroid_median_m);
  t += line;
  if (e.queries.empty()) return t;
  t += "\n| run | frames | against | localizations | within 1 m | wrong (> " +
       std::to_string(static_cast<int>(e.config.wrong_m)) +
       " m) |\n| --- | ---: | --- | ---: | "
       "---: | ---: |\n";
  for (const FleetQuery& q : e.queries) {
    std::snprintf(line, sizeof line,
                  "| %s | %zu | merged map | %zu | %zu | %zu |\n| %s | %zu | %s alone | %zu | %zu "
                  "| %zu |\n",
                  q.run.c_str(), q.frames, q.localizations_merged, q.within_1m_merged,
                  q.wrong_merged, q.run.c_str(), q.frames, e.config.sessions.front().c_str(),
                  q.localizations_first, q.within_1m_first, q.wrong_first);
    t += line;
  }
  return t + (e.interrupted ? partialNote() : "");
}

nlohmann::ordered_json toJson(const FleetExperiment& e) {
  nlohmann::ordered_json j;
  j["world_seed"] = e.config.world_seed;
  j["preset"] = e.config.preset;
  j["interrupted"] = e.interrupted;
  for (const FleetSession& s : e.sessions)
    j["sessions"].push_back({{"run", s.run},
                             {"aligned", s.aligned},
                             {"frames", s.frames},
                             {"localizations", s.ties},
                             {"entries", s.entries},
                             {"same_segments", s.same_segments},
                             {"tie_residual_m", s.tie_residual_m},
                             {"trajectory_error_m", s.trajectory_error_m},
                             {"centroid_error_m", s.centroid_error_m}});
  j["entries"] = e.entries;
  j["segments"] = e.segments;
  j["centroid_mean_m"] = e.centroid_mean_m;
  j["centroid_median_m"] = e.centroid_median_m;
  j["queries"] = nlohmann::ordered_json::array();
  for (const FleetQuery& q : e.queries)
    j["queries"].push_back({{"run", q.run},
                            {"frames", q.frames},
                            {"merged",
                             {{"localizations", q.localizations_merged},
                              {"within_1m", q.within_1m_merged},
                              {"wrong", q.wrong_merged}}},
                            {"first",
                             {{"localizations", q.localizations_first},
                              {"within_1m", q.within_1m_first},
                              {"wrong", q.wrong_first}}}});
  return j;
}

namespace {

// The sessions where the merge put them (through the one alignment) over where they were.
void writeFleetPng(const FleetExperiment& e, const std::filesystem::path& png) {
  static const uint8_t kColours[][3] = {{86, 180, 233}, {230, 159, 0}, {0, 158, 115},
                                        {240, 228, 66}, {213, 94, 0},  {204, 121, 167}};
  std::vector<viz::TrajectoryCurve> curves;
  for (size_t k = 0; k < e.truths.size(); ++k)
    curves.push_back({k == 0 ? "ground truth" : "", 110, 110, 110, e.truths[k]});
  size_t k = 0;
  for (const FleetSession& s : e.sessions) {
    if (!s.aligned) continue;
    const uint8_t* c = kColours[k % 6];
    viz::TrajectoryCurve curve{s.run + " in the merged map", c[0], c[1], c[2], {}};
    for (const Pose& T : e.trajectories[k]) curve.poses.push_back(e.T_world_map * T);
    curves.push_back(std::move(curve));
    ++k;
  }
  viz::writeTrajectoriesPng(png, "fleet: sessions merged into one map, against the truth", curves,
                            {});
}

}  // namespace

void writeFleetExperiment(const FleetExperiment& e, const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir);
  writeFleetPng(e, dir / "fleet.png");
  saveTargetMap(dir / "fleet.map", e.merged);
  writeBytesAtomically(dir / "fleet.json", toJson(e).dump(2) + "\n");
  writeBytesAtomically(dir / "fleet.md", fleetTable(e));
}

}  // namespace semsegmap
