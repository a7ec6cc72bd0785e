#include "semsegmap/pipeline/run_output.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "semsegmap/io/atomic_file.h"
#include "semsegmap/io/json.h"

namespace semsegmap {

void writeLocalizationsCsv(const std::filesystem::path& path, const LocalizationRun& run) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "frame,timestamp,x,y,z,qx,qy,qz,qw,inliers,translation_error_m,rotation_error_deg\n";
    char line[512];
    for (const LocalizationRecord& r : run.localizations) {
      const auto v = toXyzQuat(r.T_map_robot);
      std::snprintf(line, sizeof(line), "%zu,%.6f,%.4f,%.4f,%.4f,%.6f,%.6f,%.6f,%.6f,%d",
                    r.frame_index, r.timestamp_s, v[0], v[1], v[2], v[3], v[4], v[5], v[6],
                    r.inliers);
      out << line;
      if (r.T_map_robot_gt) {
        std::snprintf(line, sizeof(line), ",%.4f,%.4f", r.translation_error_m,
                      r.rotation_error_deg);
        out << line << '\n';
      } else {
        out << ",,\n";
      }
    }
  });
}

std::string localizationSummaryJson(const LocalizationRun& run, const SummaryContext& c) {
  const LocalizationSummary s = summarize(run.localizations);
  const StageTimes& t = run.stats.total;
  const double n = std::max<double>(1.0, static_cast<double>(run.stats.frames));
  std::ostringstream j;
  j << "{\n  \"dataset\": " << jsonQuoted(c.dataset) << ",\n  \"map\": " << jsonQuoted(c.map)
    << ",\n  \"config\": " << jsonQuoted(c.config)
    << ",\n  \"descriptor\": " << jsonQuoted(c.descriptor)
    << ",\n  \"frames\": " << run.stats.frames << ",\n  \"distance_m\": " << run.distance_m
    << ",\n  \"has_ground_truth\": " << (run.trajectory_gt.empty() ? "false" : "true")
    << ",\n  \"n_localizations\": " << s.localizations
    << ",\n  \"n_error_below_1m\": " << s.below_1m << ",\n  \"n_error_below_5m\": " << s.below_5m
    << ",\n  \"mean_translation_error_m\": " << s.mean_translation_error_m
    << ",\n  \"mean_rotation_error_deg\": " << s.mean_rotation_error_deg
    << ",\n  \"fps\": " << run.stats.fps() << ",\n  \"stage_ms\": {\"enrich\": " << t.enrich_ms / n
    << ", \"local_map\": " << t.local_map_ms / n << ", \"segment\": " << t.segment_ms / n
    << ", \"describe\": " << t.describe_ms / n << ", \"localize\": " << t.localize_ms / n
    << ", \"total\": " << t.total() / n << "},\n  \"map_segments\": " << c.map_segments
    << ",\n  \"map_bytes\": " << c.map_bytes << "\n}\n";
  return j.str();
}

}  // namespace semsegmap
