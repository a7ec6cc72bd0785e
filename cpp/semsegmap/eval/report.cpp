#include "semsegmap/eval/report.h"

#include <sys/utsname.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <thread>

#include "semsegmap/pipeline/modes.h"

namespace semsegmap {

namespace {

std::string commandOutput(const char* command) {
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command, "r"), pclose);
  if (!pipe) return "";
  std::string out;
  char buffer[256];
  while (std::fgets(buffer, sizeof(buffer), pipe.get())) out += buffer;
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out;
}

std::string fixed(double v, int digits) {
  char s[64];
  std::snprintf(s, sizeof(s), "%.*f", digits, v);
  return s;
}

// One sentence per query run: ours against the baseline, next to the paper's ratio.
std::string localizationVerdict(const LocalizationExperiment& e) {
  std::ostringstream t;
  for (const std::string& run : e.config.query_runs) {
    const LocalizationResult *sem = nullptr, *seg = nullptr;
    for (const LocalizationResult& r : e.results) {
      if (r.run != run) continue;
      (r.config.find("semsegmap") != std::string::npos ? sem : seg) = &r;
    }
    if (!sem || !seg) continue;
    const auto paper = paperLocalizations(run, e.config.preset);
    t << "- " << run << ": " << sem->config << " localized " << sem->summary.localizations
      << " times (" << countText(sem->summary.below_1m) << " within 1 m, " << sem->wrong
      << " wrong), " << seg->config << " " << seg->summary.localizations << " ("
      << countText(seg->summary.below_1m) << ", " << seg->wrong << " wrong)";
    if (seg->summary.localizations > 0)
      t << ": "
        << fixed(static_cast<double>(sem->summary.localizations) /
                     static_cast<double>(seg->summary.localizations),
                 2)
        << " times as many";
    if (paper.first > 0)
      t << " (the paper, on its own world: " << paper.first << " -> " << paper.second << ", "
        << fixed(static_cast<double>(paper.second) / paper.first, 2) << " times)";
    t << ". Recall along the trajectory " << fixed(sem->recall, 2) << " against "
      << fixed(seg->recall, 2) << ".\n";
  }
  return t.str();
}

}  // namespace

std::string sourceCommit() {
  const std::string commit = commandOutput("git rev-parse --short=12 HEAD 2>/dev/null");
  if (commit.empty()) return "unknown";
  const std::string changes =
      commandOutput("git status --porcelain --untracked-files=no 2>/dev/null");
  return changes.empty() ? commit : commit + "+changes";
}

std::string machineDescription() {
  std::string cpu = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  double mem_gib = 0.0;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);)
    if (line.rfind("MemTotal:", 0) == 0) mem_gib = std::stod(line.substr(9)) / (1024.0 * 1024.0);
  utsname u{};
  uname(&u);
  std::ostringstream m;
  m << cpu << ", " << std::thread::hardware_concurrency() << " cores, " << fixed(mem_gib, 0)
    << " GiB, " << u.sysname << " " << u.release;
  return m.str();
}

namespace {

std::string segmentationSection(const SegmentationExperiment& e) {
  std::ostringstream r;
  r << "## Segmentation consistency (paper IV-B)\n\n"
    << "On " << e.config.run << " (world " << e.config.world_seed << ", " << e.config.preset
    << "), every segment seen where the robot had been before is compared with the segments "
       "of the earlier visit by convex hull IoU (exact, qhull); IoU >= "
    << e.config.consistent_iou << " is a consistent re-segmentation.\n\n"
    << segmentationTable(e) << "\n![segmentation](segmentation.png)\n\n";
  if (e.results.size() >= 2)
    r << "- " << e.results[0].config << " has " << fixed(e.consistent_change_pct, 1)
      << " % consistent and " << fixed(e.inconsistent_change_pct, 1)
      << " % inconsistent segments relative to " << e.results[1].config
      << " (the paper: +30.97 % and -24.24 %).\n\n";
  return r.str();
}

std::string descriptorSection(const DescriptorExperiment& e) {
  std::ostringstream r;
  r << "## Descriptor retrieval (paper IV-C)\n\n"
    << "On " << e.dataset << ": " << e.queries << " partial observations of " << e.segments
    << " segments, each ranked against the final observations of all segments.\n\n"
    << descriptorTable(e) << "\n![descriptors](descriptors.png)\n\n"
    << "Completeness estimated at run time from each segment's growth (its agreement with the "
       "simulator's per window), retrieval per estimated band, and on "
    << e.wake_ups << " one-scan wake-ups on " << e.wake_up_dataset << " (" << e.wake_up_queries
    << " segments):\n\n"
    << completenessTable(e) << "\n![completeness](completeness.png)\n\n";
  return r.str();
}

std::string localizationSection(const LocalizationExperiment& e) {
  std::ostringstream r;
  r << "## Localization (paper IV-D, Table I)\n\n"
    << "Target map from " << e.config.map_run << " on ground-truth poses; the query runs "
    << "localize on their own odometry every frame. Wrong: error > " << e.config.wrong_m
    << " m. Recall: the fraction of metres driven after which the robot had a localization "
       "within "
    << e.config.correct_m << " m in the last " << e.config.recall_window_m
    << " m. Hz: the whole pipeline per frame on this machine, rendering excluded; every "
       "configuration's pipeline (with each kind of camera labels) alternates on every frame "
       "next to the renderer, so this is below what one pipeline alone reaches (the README's "
       "benchmarks). Paper: the paper's Table I count for the same run and method.\n\n"
    << localizationTable(e) << "\n"
    << localizationVerdict(e) << "\n"
    << (e.results.empty() ? "" : "![accuracy](localization_accuracy.png)\n\n");
  for (const LocalizationResult& res : e.results)
    r << "![" << res.dir.string() << "](" << res.dir.string() << "/localization.png)\n";
  r << "\n";
  return r.str();
}

// Each configuration once, with the descriptor model its results came from when known.
std::string configurationsSection(const SegmentationExperiment* segmentation,
                                  const LocalizationExperiment* localization) {
  std::map<std::string, std::string> configs;
  if (segmentation)
    for (const NamedConfig& n : segmentation->config.configs) configs[n.path.string()] = "";
  if (localization)
    for (const LocalizationResult& res : localization->results)
      for (const NamedConfig& n : localization->config.configs)
        if (n.name == res.config)
          configs[n.path.string()] =
              ": descriptor " + res.descriptor +
              (n.config.descriptor.model.empty() ? ""
                                                 : ", model " + n.config.descriptor.model +
                                                       " (fingerprint " + res.fingerprint + ")");
  if (configs.empty()) return "";
  std::ostringstream r;
  r << "## Configurations and models\n\n";
  for (const auto& [path, what] : configs) r << "- " << path << what << "\n";
  r << "\nEvery number above is also in the JSON files beside this report.\n";
  return r.str();
}

}  // namespace

std::string paperReport(const ReportContext& c, const SegmentationExperiment* segmentation,
                        const DescriptorExperiment* descriptors,
                        const LocalizationExperiment* localization) {
  std::ostringstream r;
  r << "# " << c.title << "\n\n"
    << "Made by `" << c.command << "` in " << fixed(c.seconds / 60.0, 1) << " min, commit "
    << sourceCommit() << ", on " << machineDescription() << ".\n\n"
    << "The simulated world is not the paper's, so the paper's numbers are a reference for the "
       "direction and size of the differences, not for the counts themselves. SemSegMap and the "
       "SegMap baseline always run on the very same frames.\n\n";
  if (c.interrupted)
    r << "**Partial: interrupted (Ctrl-C).** The experiments below cover only the frames done "
         "before the interruption; an experiment that had not started is missing.\n\n";
  for (const std::string& p : c.pictures) r << "![" << p << "](" << p << ")\n\n";
  if (!c.view.empty())
    r << "In 3D: [" << c.view << "](" << c.view
      << "), one file to open in any browser, offline: the map's segments, the trajectory and "
         "every localization coloured by its error; click one to see its matched segments.\n\n";
  if (segmentation) r << segmentationSection(*segmentation);
  if (descriptors) r << descriptorSection(*descriptors);
  if (localization) r << localizationSection(*localization);
  r << configurationsSection(segmentation, localization);
  return r.str();
}

}  // namespace semsegmap
