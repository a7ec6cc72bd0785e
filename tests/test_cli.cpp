// The command line as a user types it, through the built binary (its path is the first argument,
// as for cli_eval.sh; run from the repository's root): --version, every command's own --help,
// `--opt=value`, the exit codes of usage errors (2) and runtime errors (1), and progress that
// stays free of '\r' when it goes to a file. A command the build leaves out (the SEMSEGMAP_WITH_*
// options, passed to this test by tests/CMakeLists.txt) is not listed and says why in one line.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <pty.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "command_result.h"
#include "doc_blocks.h"
#include "mini_kitti.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

using test_support::TempDir;

std::string g_binary;  // set by main

using test_support::readFile;
using test_support::Result;

// Runs `semsegmap ARGS` with stdout and stderr into files (so neither is a terminal).
Result run(const std::string& args) {
  static int counter = 0;
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::string stem =
      "semsegmap_cli_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  const std::filesystem::path out = dir / (stem + ".out"), err = dir / (stem + ".err");
  const std::string command = "'" + g_binary + "' " + args + " > '" + out.string() + "' 2> '" +
                              err.string() + "' < /dev/null";
  const int status = std::system(command.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = readFile(out);
  r.err = readFile(err);
  std::filesystem::remove(out);
  std::filesystem::remove(err);
  return r;
}

struct CommandOptions {
  std::string command;
  std::vector<std::string> options;  // exactly the options its help must list (besides --help)
  std::vector<std::string> foreign;  // options of other commands it must not list
};

const std::vector<CommandOptions> kAllCommands = {
    {"simulate",
     {"world-seed", "run", "condition", "traffic-seed", "max-frames", "world", "out", "no-cameras"},
     {"dataset", "config"}},
    {"simulate-overview",
     {"world-seed", "world", "out", "cameras", "run", "frame"},
     {"max-frames", "dataset"}},
    {"info",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "json"},
     {"out", "config", "max-frames"}},
    {"enrich",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "frame", "out",
      "width", "ply", "camera", "config"},
     {"max-frames", "map"}},
    {"label",
     {"dataset", "rig", "ground-truth", "kitti-calib", "labels", "config", "out", "max-frames"},
     {"odometry", "map"}},
    {"convert",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "out", "max-frames",
      "config"},
     {"world-seed", "map"}},
    {"segment",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "config", "out",
      "poses", "max-frames"},
     {"map", "float32"}},
    {"map",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "config", "out",
      "into", "poses", "max-frames", "points", "float32"},
     {"world-seed", "map"}},
    {"localize",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "config", "map", "out",
      "max-frames", "allow-config-mismatch", "relocalize", "prior", "follow", "follow-idle"},
     {"poses", "float32"}},
    {"slam",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "config", "out",
      "max-frames"},
     {"map", "poses"}},
    {"odometry",
     {"dataset", "rig", "ground-truth", "kitti-calib", "out", "config", "max-frames"},
     {"map", "poses", "odometry"}},
    {"train-segmentation",
     {"dataset", "out", "epochs", "threads", "input", "every", "max-frames", "seed", "history"},
     {"config", "descriptor", "batch"}},
    {"train",
     {"descriptor",
      "dataset",
      "out",
      "epochs",
      "batch",
      "threads",
      "config",
      "max-frames",
      "labels",
      "cache",
      "anchors-per-epoch",
      "lr",
      "seed",
      "confused-sections",
      "modality-dropout",
      "partial-coverage",
      "lidar-only",
      "teacher",
      "distillation-weight",
      "from-scratch",
      "points",
      "history",
      "words",
      "keypoints",
      "steps"},
     {"world-seed", "map"}},
    {"demo", {"out", "world-seed", "preset", "max-frames"}, {"configs", "dataset"}},
    {"eval segmentation",
     {"world-seed", "out", "preset", "max-frames", "configs", "segmentation-run"},
     {"map-run", "descriptors", "config"}},
    {"eval descriptors",
     {"world-seed", "out", "preset", "max-frames", "config", "models", "descriptors", "threads",
      "descriptor-run", "wake-up-every", "completeness-window"},
     {"configs", "map-run"}},
    {"eval localization",
     {"world-seed", "out", "preset", "max-frames", "configs", "map-run", "query-runs",
      "label-noise", "labels", "odometry", "rig"},
     {"descriptors", "segmentation-run"}},
    {"eval revisits",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "map-frames",
      "query-frames", "configs", "place-radius", "check-ground-truth", "wake-up", "scan-context",
      "out"},
     {"world-seed", "preset", "map-run"}},
    {"eval semantics",
     {"dataset", "rig", "odometry", "ground-truth", "kitti-calib", "labels", "config", "out",
      "max-frames"},
     {"world-seed", "configs", "map-frames"}},
    {"eval labels", {"dataset", "config", "out", "every", "max-frames"}, {"rig", "labels"}},
    {"maps list", {"store"}, {"map", "out"}},
    {"maps show", {"map"}, {"store", "out"}},
    {"maps export", {"map", "out"}, {"from"}},
    {"maps import", {"from", "map"}, {"out"}},
    {"maps drop", {"map", "session"}, {"out"}},
    {"eval fleet",
     {"world-seed", "out", "preset", "max-frames", "config", "sessions", "fifth-run"},
     {"configs", "dataset"}},
    {"eval paper",
     {"world-seed", "out", "preset", "max-frames", "configs", "segmentation-run", "config",
      "models", "descriptors", "threads", "descriptor-run", "wake-up-every", "completeness-window",
      "map-run", "query-runs"},
     {"dataset"}},
};

// Whether this build has a command: those of the simulator need SEMSEGMAP_WITH_SIM, train and
// train-segmentation need SEMSEGMAP_WITH_TORCH.
bool built(const std::string& command) {
  if (command == "train" || command == "train-segmentation") return SEMSEGMAP_WITH_TORCH;
  if (command.rfind("maps ", 0) == 0) return SEMSEGMAP_WITH_POSTGRES;
  if (command == "eval labels") return true;     // any dataset with label images
  if (command == "eval revisits") return true;   // any recording with ground truth
  if (command == "eval semantics") return true;  // any dataset with per-point ground truth
  if (command.rfind("simulate", 0) == 0 || command == "demo" || command.rfind("eval", 0) == 0)
    return SEMSEGMAP_WITH_SIM;
  return true;
}

std::vector<CommandOptions> builtCommands(bool wanted = true) {
  std::vector<CommandOptions> out;
  for (const CommandOptions& c : kAllCommands)
    if (built(c.command) == wanted) out.push_back(c);
  return out;
}

const std::vector<CommandOptions> kCommands = builtCommands();

// The option lines of a help text: "  --name PLACEHOLDER  help" -> {"name", "PLACEHOLDER"}.
std::vector<std::pair<std::string, std::string>> helpOptions(const std::string& help) {
  std::vector<std::pair<std::string, std::string>> out;
  std::istringstream in(help);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("  --", 0) != 0) continue;
    const std::string head = line.substr(4, line.find("  ", 4) - 4);
    const size_t space = head.find(' ');
    out.emplace_back(head.substr(0, space),
                     space == std::string::npos ? "" : head.substr(space + 1));
  }
  return out;
}

// `semsegmap COMMAND --help`, run once per command (each start of the binary takes a second).
// `semsegmap COMMAND --help`, kept in a folder named after this binary's path and time, so that
// the several tests that read every command's help (each its own process) start the binary once
// a command between them: starting it (libtorch and its libraries) takes about a second of CPU.
// A rebuilt binary has another time, hence another folder. Written under a temporary name and
// renamed, so that tests running side by side never read half a file.
Result helpOnDisk(const std::string& command) {
  const auto stamp = std::filesystem::last_write_time(g_binary).time_since_epoch().count();
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("semsegmap_help_" + std::to_string(std::hash<std::string>{}(g_binary)) + "_" +
       std::to_string(stamp));
  std::string name = command;
  std::replace(name.begin(), name.end(), ' ', '_');
  const std::filesystem::path file = dir / name;
  if (std::ifstream in{file}) {
    Result r;
    in >> r.code;
    in.ignore();
    std::string out_size;
    std::getline(in, out_size);
    const std::string rest{std::istreambuf_iterator<char>(in), {}};
    r.out = rest.substr(0, std::stoul(out_size));
    r.err = rest.substr(r.out.size());
    return r;
  }
  Result r = run(command + " --help");
  std::filesystem::create_directories(dir);
  const std::filesystem::path part = file.string() + "." + std::to_string(::getpid());
  std::ofstream(part) << r.code << "\n" << r.out.size() << "\n" << r.out << r.err;
  std::filesystem::rename(part, file);
  return r;
}

const Result& help(const std::string& command) {
  static std::map<std::string, Result> cache;
  auto it = cache.find(command);
  if (it == cache.end()) it = cache.emplace(command, helpOnDisk(command)).first;
  return it->second;
}

// `semsegmap --check-usage-lines` on `lines`: each line parsed as its command would, all in one
// process (a start of the binary costs about a second), one Result per line ("--- line N exit
// C", its output, "--- stderr", its errors).
std::vector<Result> checkUsageLines(const std::vector<std::string>& lines) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() /
      ("semsegmap_lines_" + std::to_string(::getpid()) + "_" +
       std::to_string(std::hash<std::string>{}(lines.empty() ? "" : lines.front())) + ".txt");
  {
    std::ofstream out(file);
    for (const std::string& line : lines) out << line << "\n";
  }
  const Result all = run("--check-usage-lines '" + file.string() + "'");
  std::filesystem::remove(file);
  std::vector<Result> results;
  std::istringstream printed(all.out);
  bool in_err = false;
  for (std::string line; std::getline(printed, line);) {
    int number = 0, code = 0;
    if (std::sscanf(line.c_str(), "--- line %d exit %d", &number, &code) == 2) {
      results.push_back({code, "", ""});
      in_err = false;
    } else if (line == "--- stderr") {
      in_err = true;
    } else if (!results.empty()) {
      (in_err ? results.back().err : results.back().out) += line + "\n";
    }
  }
  EXPECT_EQ(results.size(), lines.size()) << all.out << all.err;
  results.resize(lines.size());
  return results;
}

bool lists(const std::string& help, const std::string& option) {
  for (const auto& [name, placeholder] : helpOptions(help))
    if (name == option) return true;
  return false;
}

// "semsegmap MAJOR.MINOR.PATCH\n". Checked by hand: GCC 12 warns inside <regex> under the
// sanitizers, and warnings are errors.
bool isVersionLine(const std::string& line) {
  const std::string prefix = "semsegmap ";
  if (line.rfind(prefix, 0) != 0 || line.empty() || line.back() != '\n') return false;
  const std::string version = line.substr(prefix.size(), line.size() - prefix.size() - 1);
  int dots = 0;
  bool digit_before = false;
  for (const char c : version) {
    if (c == '.') {
      if (!digit_before) return false;
      ++dots;
      digit_before = false;
    } else if (c >= '0' && c <= '9') {
      digit_before = true;
    } else {
      return false;
    }
  }
  return dots == 2 && digit_before;
}

TEST(Cli, Version) {
  const Result r = run("--version");
  EXPECT_EQ(r.code, 0);
  EXPECT_TRUE(isVersionLine(r.out)) << r.out;
  EXPECT_EQ(r.err, "");
  const Result word = run("version");
  EXPECT_EQ(word.code, 0);
  EXPECT_EQ(word.out, r.out);
}

TEST(Cli, OverviewListsEveryCommand) {
  const Result r = run("--help");
  EXPECT_EQ(r.code, 0);
  for (const CommandOptions& c : kCommands)
    EXPECT_NE(r.out.find("\n  " + c.command + " "), std::string::npos) << c.command;
  // The commands the build leaves out are named after the list, not in it.
  const std::string listed = r.out.substr(0, r.out.find("not in this build:"));
  for (const CommandOptions& c : builtCommands(false)) {
    EXPECT_EQ(listed.find("\n  " + c.command + " "), std::string::npos) << c.command;
    EXPECT_NE(r.out.find("not in this build:"), std::string::npos);
  }
  const Result none = run("");
  EXPECT_EQ(none.code, 2);
  EXPECT_NE(none.err.find("usage: semsegmap <command>"), std::string::npos);
}

// A command this build leaves out: one line naming the option that would bring it, exit 1, and
// its --help says the same.
TEST(Cli, CommandsNotInThisBuildSayWhyInOneLine) {
  const std::vector<CommandOptions> absent = builtCommands(false);
  if (absent.empty()) GTEST_SKIP() << "this build has every command";
  for (const CommandOptions& c : absent) {
    SCOPED_TRACE(c.command);
    const std::string option = c.command.rfind("train", 0) == 0   ? "SEMSEGMAP_WITH_TORCH"
                               : c.command.rfind("maps ", 0) == 0 ? "SEMSEGMAP_WITH_POSTGRES"
                                                                  : "SEMSEGMAP_WITH_SIM";
    for (const std::string& args : {c.command + " --out o", c.command + " --help"}) {
      const Result r = run(args);
      EXPECT_EQ(r.code, 1) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_NE(r.err.find("this build has no"), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("reconfigure with -D" + option + "=ON"), std::string::npos) << r.err;
    }
  }
}

TEST(Cli, EveryCommandHasItsOwnHelp) {
  for (const CommandOptions& c : kCommands) {
    SCOPED_TRACE(c.command);
    const Result& r = help(c.command);
    EXPECT_EQ(r.code, 0);
    EXPECT_EQ(r.err, "");
    EXPECT_EQ(r.out.rfind("usage: semsegmap " + c.command + " ", 0), 0u) << r.out;
    for (const std::string& o : c.options) EXPECT_TRUE(lists(r.out, o)) << "--" << o;
    for (const std::string& o : c.foreign) EXPECT_FALSE(lists(r.out, o)) << "--" << o;
    EXPECT_TRUE(lists(r.out, "help"));
    EXPECT_EQ(helpOptions(r.out).size(), c.options.size() + 1) << r.out;
  }
  const Result eval = run("eval --help");
  EXPECT_EQ(eval.code, 0);
  for (const char* e : {"segmentation", "descriptors", "localization", "revisits", "paper"})
    EXPECT_EQ(eval.out.find("\n  eval " + std::string(e)) != std::string::npos,
              built("eval " + std::string(e)))
        << e << "\n"
        << eval.out;
}

TEST(Cli, HelpShowsDefaultsAndRequiredOptions) {
  const Result& map = help("map");
  EXPECT_NE(map.out.find("--points N"), std::string::npos);
  EXPECT_NE(map.out.find("(default: 0)"), std::string::npos);  // --max-frames
  EXPECT_NE(map.out.find("(required)"), std::string::npos);
  if (built("demo")) {
    EXPECT_NE(help("demo").out.find("(default: demo_out)"), std::string::npos);
  }
  if (built("simulate")) {
    EXPECT_NE(help("simulate").out.find("--world full|small|tiny"), std::string::npos);
  }
  if (built("train")) {
    EXPECT_NE(help("train").out.find("--epochs N"), std::string::npos);
  }
}

// An option whose help says its default in words ("(default: shipped)") gets no second one from
// the help generator: `eval paper --help` used to show both for --configs and --config.
TEST(Cli, HelpSaysEachDefaultOnce) {
  for (const CommandOptions& c : kCommands) {
    SCOPED_TRACE(c.command);
    // An option's entry: its "  --name" line and the wrapped lines under it.
    std::vector<std::string> entries;
    std::istringstream in(help(c.command).out);
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("  --", 0) == 0)
        entries.push_back(line);
      else if (!entries.empty() && line.rfind("      ", 0) == 0)
        entries.back() += line;
    }
    for (const std::string& entry : entries) {
      const size_t first = entry.find("(default: ");
      EXPECT_EQ(entry.find("(default: ", first == std::string::npos ? first : first + 1),
                std::string::npos)
          << entry;
    }
  }
  if (built("eval paper")) {
    const std::string paper = help("eval paper").out;
    EXPECT_NE(paper.find("(default: the shipped ones)"), std::string::npos) << paper;
    EXPECT_EQ(paper.find("(default: config/semsegmap.yaml"), std::string::npos) << paper;
  }
}

// Every option a help lists is accepted by the parser: given all of them (a value each) and then
// an unknown one, the only complaint is about the unknown one.
TEST(Cli, ParserAcceptsWhatTheHelpLists) {
  std::vector<std::string> lines;
  for (const CommandOptions& c : kCommands) {
    std::string args = c.command;
    for (const auto& [name, placeholder] : helpOptions(help(c.command).out)) {
      if (name == "help") continue;
      args += " --" + name;
      // A choice: its first value; anything else: "1" (a number, a name, a path).
      if (placeholder.find('|') != std::string::npos)
        args += " " + placeholder.substr(0, placeholder.find('|'));
      else if (!placeholder.empty())
        args += " 1";
    }
    lines.push_back(args + " --not-an-option");
  }
  // Parsed as each command would, in one process (the parse is the same with --check-usage).
  const std::vector<Result> results = checkUsageLines(lines);
  for (size_t i = 0; i < kCommands.size(); ++i) {
    SCOPED_TRACE(kCommands[i].command);
    EXPECT_EQ(results[i].code, 2) << results[i].err;
    EXPECT_NE(results[i].err.find("unknown option --not-an-option"), std::string::npos)
        << results[i].err;
  }
}

TEST(Cli, UsageErrorsExitTwoWithAHint) {
  const Result r = run("map --dataset d --config c --out o --world-seed 1");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err,
            "semsegmap map: usage error: unknown option --world-seed\n"
            "run 'semsegmap map --help' for its options\n");
  const Result command = run("frobnicate");
  EXPECT_EQ(command.code, 2);
  EXPECT_NE(command.err.find("semsegmap: usage error: unknown command 'frobnicate'"),
            std::string::npos);
  const Result missing = run("map --dataset d --out o");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("missing required option --config"), std::string::npos);
  const Result flag = run("map --dataset d --config c --out o --float32=yes");
  EXPECT_EQ(flag.code, 2);
  EXPECT_NE(flag.err.find("option --float32 takes no value"), std::string::npos);
  const Result count = run("convert --dataset d --out o --max-frames abc");
  EXPECT_EQ(count.code, 2);
  EXPECT_NE(count.err.find("--max-frames expects an integer, got 'abc'"), std::string::npos);
  const Result poses = run("segment --dataset d --config c --out o --poses nope");
  EXPECT_EQ(poses.code, 2);
  EXPECT_NE(poses.err.find("--poses expects "), std::string::npos) << poses.err;
  if (!built("simulate")) return;
  const Result number = run("simulate --run S2 --out o --world-seed abc");
  EXPECT_EQ(number.code, 2);
  EXPECT_NE(number.err.find("--world-seed expects an integer, got 'abc'"), std::string::npos);
  const Result choice = run("simulate --run S7 --out o");
  EXPECT_EQ(choice.code, 2);
  EXPECT_NE(choice.err.find("--run expects S0|S1|S2|S3, got 'S7'"), std::string::npos);
  const Result eval = run("eval nonsense --out o");
  EXPECT_EQ(eval.code, 2);
  EXPECT_NE(eval.err.find("semsegmap eval: usage error: unknown experiment 'nonsense'"),
            std::string::npos);
  EXPECT_NE(eval.err.find("run 'semsegmap eval --help'"), std::string::npos);
  const Result demo = run("demo --configs config/segmap.yaml");  // once accepted and ignored
  EXPECT_EQ(demo.code, 2);
  EXPECT_NE(demo.err.find("unknown option --configs"), std::string::npos);
  const Result sub = run("eval localization --out o --bogus 1");
  EXPECT_EQ(sub.code, 2);
  EXPECT_NE(sub.err.find("semsegmap eval localization: usage error: unknown option --bogus"),
            std::string::npos);
}

// A typo gets the nearest known name in its one line: a command, an option (also with one dash),
// an experiment, a choice; a word far from every name gets no guess.
// eval localization --labels: the network's spec is checked before any frame is rendered.
TEST(Cli, EvalLocalizationLabelsAreCheckedBeforeTheWork) {
  if (!built("eval localization")) GTEST_SKIP() << "no simulator in this build";
  const std::pair<const char*, const char*> usage[] = {
      {"netwrk", "--labels expects perfect or network"},
      {"network,rate=abc", "--labels: rate=abc needs a positive number"},
      {"network,rate=-1", "--labels: rate=-1 needs a positive number"},
      {"network,speed=2", "--labels: unknown key 'speed=2'"},
      {"perfect+netwrk", "--labels expects perfect or network"},
      {"network,ground=sideways", "--labels: unknown key 'ground=sideways'"},
      {"network,descriptor=mine", "--labels: unknown key 'descriptor=mine'"},
      {"perfect+network,every+perfect", "--labels: 'perfect' is given twice"},
      {"+", "--labels: no label pass given"},
  };
  for (const auto& [spec, message] : usage) {
    const Result r = run(std::string("eval localization --out o --labels ") + spec);
    EXPECT_EQ(r.code, 2) << spec << ": " << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
  }
  const Result both = run("eval localization --out o --labels network --label-noise 2");
  EXPECT_EQ(both.code, 2);
  EXPECT_NE(both.err.find("give one of them"), std::string::npos) << both.err;
  const Result missing = run("eval localization --out o --labels network,config=/nonexistent.yaml");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("/nonexistent.yaml"), std::string::npos) << missing.err;
}

TEST(Cli, UnknownNamesSuggestTheNearestKnownOne) {
  auto expectUsage = [](const std::string& args, const std::string& line) {
    const Result r = run(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(r.err.substr(0, r.err.find('\n')), line) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 2) << r.err;  // and the --help hint
  };
  expectUsage("localise --dataset d",
              "semsegmap: usage error: unknown command 'localise' (did you mean localize?)");
  expectUsage("lcoalize",
              "semsegmap: usage error: unknown command 'lcoalize' (did you mean "
              "localize?)");  // two letters swapped: one edit
  expectUsage("--verison",
              "semsegmap: usage error: unknown command '--verison' (did you mean "
              "--version?)");
  expectUsage("frobnicate", "semsegmap: usage error: unknown command 'frobnicate'");
  expectUsage("map --dataset d --config c --out o --odometrie x.txt",
              "semsegmap map: usage error: unknown option --odometrie (did you mean --odometry?)");
  expectUsage("map --dataset d --config c --out o --Max-Frame=2",
              "semsegmap map: usage error: unknown option --Max-Frame (did you mean "
              "--max-frames?)");
  expectUsage("map --dataset d --out o -config c",
              "semsegmap map: usage error: unexpected argument '-config' (did you mean --config?)");
  expectUsage("map --dataset d --config c --out o --zz 1",
              "semsegmap map: usage error: unknown option --zz");
  expectUsage("segment --dataset d --config c --out o --poses odmo",
              "semsegmap segment: usage error: option --poses expects gt|odom, got 'odmo' (did "
              "you mean odom?)");
  // eval revisits is in every build.
  expectUsage("eval revisit --out o",
              "semsegmap eval: usage error: unknown experiment 'revisit' (did you mean revisits?)");
  const Result far = run("eval nonsense --out o");
  EXPECT_NE(far.err.find("unknown experiment 'nonsense' (expected "), std::string::npos) << far.err;
}

TEST(Cli, NegativeMaxFramesIsAUsageErrorEverywhere) {
  std::vector<std::string> commands, lines;
  for (const CommandOptions& c : kCommands) {
    if (std::find(c.options.begin(), c.options.end(), "max-frames") == c.options.end()) continue;
    commands.push_back(c.command);
    lines.push_back(c.command + " --max-frames=-1");
  }
  const std::vector<Result> results = checkUsageLines(lines);  // one process, parsed alike
  for (size_t i = 0; i < commands.size(); ++i) {
    SCOPED_TRACE(commands[i]);
    EXPECT_EQ(results[i].code, 2) << results[i].err;
    EXPECT_EQ(results[i].err, "semsegmap " + commands[i] +
                                  ": usage error: option --max-frames must not be negative, got "
                                  "'-1'\nrun 'semsegmap " +
                                  commands[i] + " --help' for its options\n");
  }
  const Result spaced = run("map --dataset d --config c --out o --max-frames -1");
  EXPECT_EQ(spaced.code, 2);
  EXPECT_NE(spaced.err.find("--max-frames must not be negative"), std::string::npos);
}

// `--opt=value` works as `--opt value` does; the progress of a run into a file is plain lines.
TEST(Cli, EqualsFormAndProgressIntoAFile) {
  if (!built("simulate")) GTEST_SKIP() << "this build has no simulator (SEMSEGMAP_WITH_SIM=OFF)";
  TempDir tmp;
  const std::filesystem::path out = tmp.path() / "sim";
  const Result r =
      run("simulate --world-seed=1 --run=S2 --world=tiny --max-frames=3 --out=" + out.string() +
          " --no-cameras");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("wrote 3 frames"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::is_directory(out));
  EXPECT_EQ(r.err.find('\r'), std::string::npos);
  EXPECT_NE(r.err.find("simulate S2"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("3/3"), std::string::npos) << r.err;
  const auto lines = std::count(r.err.begin(), r.err.end(), '\n');
  EXPECT_GE(lines, 1);
  EXPECT_LE(lines, 11) << r.err;
}

// A path without a kind that is no dataset directory: the one-line error names it and says what
// to write instead, as far as the path's name and a look at its entries tell.
TEST(CliDatasetSpecs, APathWithoutAKindSaysWhatToWriteInstead) {
  TempDir tmp;
  namespace fs = std::filesystem;
  const std::string d = tmp.path().string();
  std::ofstream(d + "/run.bag") << "never read";
  fs::create_directories(d + "/drive/velodyne_points/data");
  fs::create_directories(d + "/date/2011_09_26_drive_0001_sync/velodyne_points/data");
  fs::create_directories(d + "/seq/velodyne");
  std::ofstream(d + "/seq/velodyne/000000.bin") << "";
  fs::create_directories(d + "/ros2");
  std::ofstream(d + "/ros2/metadata.yaml") << "";
  std::ofstream(d + "/ros2/ros2_0.db3") << "";
  fs::create_directories(d + "/scans");
  std::ofstream(d + "/scans/000000.pcd") << "";
  std::ofstream(d + "/notes.txt") << "x";
  auto expectLine = [&](const std::string& path, const std::string& message) {
    const Result r = run("convert --dataset " + path + " --out " + d + "/out");
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err, "semsegmap convert: error: " + path + ": " + message + "\n");
    EXPECT_FALSE(fs::exists(d + "/out")) << "a failed run left its folder";
  };
  const std::string folder = ", not a dataset directory of the project's format: write ";
  expectLine(d + "/run.bag",
             "a ROS 1 bag, not a dataset directory: write rosbag:" + d + "/run.bag");
  expectLine(d + "/ros2", "a ROS 2 bag folder" + folder + "rosbag:" + d + "/ros2");
  expectLine(d + "/drive", "a KITTI raw drive" + folder + "kitti-raw:" + d + "/drive");
  expectLine(d + "/date", "a folder holding a KITTI raw drive" + folder + "kitti-raw:" + d +
                              "/date/2011_09_26_drive_0001_sync");
  expectLine(d + "/seq/velodyne/000000.bin",
             "a scan of a SemanticKITTI or KITTI odometry sequence, not a dataset directory: "
             "write semantickitti:" +
                 d + "/seq");
  expectLine(d + "/scans/000000.pcd",
             "a scan, not a dataset directory: write folder:" + d + "/scans");
  expectLine(d + "/notes.txt",
             "a file, not a dataset directory (a dataset is a directory, or KIND:PATH with "
             "kitti-raw:, semantickitti:, nclt:, folder:, rosbag:)");
  expectLine(d + "/none", "no such dataset directory");
  const Result kind = run("convert --dataset rosbg:" + d + "/run.bag --out " + d + "/out");
  EXPECT_EQ(kind.code, 1);
  EXPECT_NE(kind.err.find("unknown kind 'rosbg' (did you mean rosbag:?)\n"), std::string::npos)
      << kind.err;
}

// A dataset or descriptor the build left out: one line naming the option, exit 1.
TEST(Cli, PartsNotInThisBuildSayWhyInOneLine) {
  if (SEMSEGMAP_WITH_SIM && SEMSEGMAP_WITH_TORCH && SEMSEGMAP_WITH_PCL)
    GTEST_SKIP() << "this build has every part";
  TempDir tmp;
  auto expectOneLine = [](const Result& r, const std::string& command, const std::string& why) {
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err.rfind("semsegmap " + command + ": error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  };
  const std::string out = " --out " + (tmp.path() / "out").string();
  if (!SEMSEGMAP_WITH_SIM)
    expectOneLine(run("segment --dataset sim:world=1,run=S2 --config config/segmap.yaml" + out),
                  "segment",
                  "this build has no simulator (built without Embree, reconfigure with "
                  "-DSEMSEGMAP_WITH_SIM=ON)");
  if (!SEMSEGMAP_WITH_TORCH)
    expectOneLine(run("map --dataset missing --config config/semsegmap.yaml" + out), "map",
                  "descriptor.kind semsegmap-net: this build has no learned descriptors (built "
                  "without libtorch, reconfigure with -DSEMSEGMAP_WITH_TORCH=ON)");
  if (!SEMSEGMAP_WITH_PCL) {
    const std::filesystem::path config = tmp.path() / "fpfh.yaml";
    std::ofstream(config) << "descriptor:\n  kind: fpfh\n";
    expectOneLine(run("map --dataset missing --config " + config.string() + out), "map",
                  "descriptor.kind fpfh: this build has no FPFH (built without PCL, reconfigure "
                  "with -DSEMSEGMAP_WITH_PCL=ON)");
  }
}

TEST(Cli, RuntimeErrorsExitOne) {
  TempDir tmp;
  const std::string missing = (tmp.path() / "missing.map").string();
  const Result r =
      run("localize --dataset sim:world=1,run=S2,preset=tiny,frames=2 --config "
          "config/semsegmap.yaml --map " +
          missing + " --out " + (tmp.path() / "loc").string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_EQ(r.err.rfind("semsegmap localize: error: ", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("missing.map"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("usage error"), std::string::npos);
}

// `map --into`: a drive on its own odometry joins a map as a new session; one that never
// localizes against it is written beside --out, in its own frame, and says so (exit 3); --out is
// never written with it. Joining by SLAM poses is a usage error.
TEST(CliMapInto, ARunJoinsAMapAsASessionOrIsWrittenBeside) {
  if (!SEMSEGMAP_WITH_SIM || !SEMSEGMAP_WITH_TORCH)
    GTEST_SKIP() << "needs the simulator and libtorch (the shipped configuration's model)";
  TempDir tmp;
  const std::string a = (tmp.path() / "a.map").string(), ab = (tmp.path() / "ab.map").string();
  const std::string config = " --config config/semsegmap.yaml";
  const Result m =
      run("map --dataset sim:world=1,run=S0,preset=tiny,frames=60" + config + " --out " + a);
  ASSERT_EQ(m.code, 0) << m.err;
  const Result into = run("map --dataset sim:world=1,run=S0,preset=tiny,frames=60,traffic=7" +
                          config + " --poses odom --into " + a + " --out " + ab);
  ASSERT_EQ(into.code, 0) << into.err;
  EXPECT_NE(into.out.find("map 2 sessions"), std::string::npos) << into.out;
  EXPECT_NE(into.out.find("localized "), std::string::npos) << into.out;
  EXPECT_TRUE(std::filesystem::exists(ab));

  const std::string abc = (tmp.path() / "abc.map").string();
  const Result elsewhere = run("map --dataset sim:world=2,run=S0,preset=tiny,frames=30" + config +
                               " --poses odom --into " + ab + " --out " + abc);
  EXPECT_EQ(elsewhere.code, 3) << elsewhere.err;
  EXPECT_FALSE(std::filesystem::exists(abc));
  const std::string beside = (tmp.path() / "abc.unaligned.map").string();
  EXPECT_TRUE(std::filesystem::exists(beside));
  EXPECT_NE(elsewhere.err.find("not merged; its own map, in its own frame, written to " + beside),
            std::string::npos)
      << elsewhere.err;

  const Result slam = run("map --dataset sim:world=1,run=S0,preset=tiny,frames=3" + config +
                          " --poses slam --into " + a + " --out " + abc);
  EXPECT_EQ(slam.code, 2) << slam.err;
  EXPECT_NE(slam.err.find("--into joins a run by localizing it"), std::string::npos) << slam.err;
  const Result missing = run("map --dataset sim:world=1,run=S0,preset=tiny,frames=3" + config +
                             " --into " + (tmp.path() / "none.map").string() + " --out " + abc);
  EXPECT_EQ(missing.code, 1) << missing.err;
  EXPECT_NE(missing.err.find("none.map"), std::string::npos) << missing.err;
}

// A teacher is checked before the extraction (here the dataset does not even exist): the options
// that need it, its file and its kind.
// 3dsmoothnet's training takes the options it has a use for, refuses the others before any
// extraction, and writes a model whose words are fitted, which eval descriptors then ranks.
TEST(Cli, TrainsThreeDSmoothNetAndRefusesTheOptionsOfTheOthers) {
  if (!built("train")) GTEST_SKIP() << "this build has no train (SEMSEGMAP_WITH_TORCH=OFF)";
  TempDir tmp;
  const std::string model = (tmp.path() / "3dsmoothnet.model").string();
  const std::string train = "train --dataset sim:nowhere --out " + model + " ";
  const Result teacher =
      run(train + "--descriptor 3dsmoothnet --teacher models/semsegmap-net.model");
  EXPECT_EQ(teacher.code, 2);
  EXPECT_NE(teacher.err.find("--teacher: not an option of 3dsmoothnet's training"),
            std::string::npos)
      << teacher.err;
  const Result words = run(train + "--descriptor semsegmap-net --words 8");
  EXPECT_EQ(words.code, 2);
  EXPECT_NE(words.err.find("--words: only for 3dsmoothnet"), std::string::npos) << words.err;
  const Result one = run(train + "--descriptor 3dsmoothnet --words 1");
  EXPECT_EQ(one.code, 1);
  EXPECT_NE(one.err.find("visual words"), std::string::npos) << one.err;
  if (!built("simulate")) return;
  const Result r =
      run("train --descriptor 3dsmoothnet --dataset sim:world=1,run=S1,preset=tiny --max-frames 40 "
          "--epochs 1 --steps 4 --batch 16 --keypoints 8 --words 4 --out " +
          model);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("fitted 4 visual words to "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("segment retrieval on the validation objects"), std::string::npos) << r.out;
  // A model file of version 4 naming its kind, with the words last (tests/test_smoothnet.cpp
  // reads such files back).
  const std::string bytes = readFile(model);
  EXPECT_EQ(bytes.substr(0, 7), std::string("SSMNET\x04", 7));
  EXPECT_NE(bytes.find("3dsmoothnet"), std::string::npos);
  EXPECT_NE(bytes.rfind("words"), std::string::npos);
  EXPECT_NE(r.out.find("(3dsmoothnet, fingerprint "), std::string::npos) << r.out;
}

// A window of no frames would estimate nothing: refused before the run is simulated.
TEST(Cli, EvalDescriptorsRefusesACompletenessWindowOfNoFrames) {
  if (!built("simulate")) GTEST_SKIP() << "this build has no simulator";
  TempDir tmp;
  const Result r = run("eval descriptors --completeness-window 0 --out " + tmp.path().string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--completeness-window: a window of at least one frame"), std::string::npos)
      << r.err;
}

// train --labels reads as eval localization's, and is checked before the runs are extracted.
TEST(Cli, TrainChecksItsLabelsBeforeExtracting) {
  if (!built("train")) GTEST_SKIP() << "this build has no train (SEMSEGMAP_WITH_TORCH=OFF)";
  TempDir tmp;
  const std::string train = "train --descriptor semsegmap-net --dataset sim:nowhere --out " +
                            (tmp.path() / "m.model").string() + " --labels ";
  const Result typo = run(train + "netwrk");
  EXPECT_EQ(typo.code, 2);
  EXPECT_NE(typo.err.find("--labels expects perfect or network"), std::string::npos) << typo.err;
  const Result missing = run(train + "network,config=/nonexistent.yaml");
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("/nonexistent.yaml"), std::string::npos) << missing.err;
  // The shipped network passes the check: the dataset is what fails.
  const Result shipped = run(train + "network");
  EXPECT_EQ(shipped.code, 1);
  EXPECT_NE(shipped.err.find("sim:nowhere"), std::string::npos) << shipped.err;
}

TEST(Cli, TrainChecksItsTeacherBeforeExtracting) {
  if (!built("train")) GTEST_SKIP() << "this build has no train (SEMSEGMAP_WITH_TORCH=OFF)";
  TempDir tmp;
  const std::string train =
      "train --dataset sim:nowhere --out " + (tmp.path() / "m.model").string() + " ";
  const Result weight = run(train + "--descriptor semsegmap-net --distillation-weight 2");
  EXPECT_EQ(weight.code, 2);
  EXPECT_NE(weight.err.find("--distillation-weight: only with --teacher"), std::string::npos)
      << weight.err;
  const Result dropout = run(train +
                             "--descriptor semsegmap-net --teacher models/semsegmap-net.model "
                             "--modality-dropout 0.3");
  EXPECT_EQ(dropout.code, 2);
  EXPECT_NE(dropout.err.find("the teacher would see the same dropped observation"),
            std::string::npos)
      << dropout.err;
  const Result partial =
      run(train + "--descriptor semsegmap-net --lidar-only --partial-coverage 0.5");
  EXPECT_EQ(partial.code, 2);
  EXPECT_NE(partial.err.find("--partial-coverage: a --lidar-only network sees neither"),
            std::string::npos)
      << partial.err;
  const Result missing =
      run(train + "--descriptor semsegmap-net --teacher " + (tmp.path() / "none.model").string());
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.err.find("none.model"), std::string::npos) << missing.err;
  const Result kind =
      run(train + "--descriptor segmap-cnn --teacher models/semsegmap-net.model --lidar-only");
  EXPECT_EQ(kind.code, 2) << "--lidar-only is semsegmap-net's";
  const Result other = run(train + "--descriptor segmap-cnn --teacher models/semsegmap-net.model");
  EXPECT_EQ(other.code, 1);
  EXPECT_NE(other.err.find("semsegmap-net.model"), std::string::npos) << other.err;
  EXPECT_EQ(other.err.find("extract"), std::string::npos) << other.err;
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "m.model"));
}

// A dataset without odometry (here a folder of scans, no pose file) is refused before any frame
// is processed, with the options that would give it poses; nothing runs on identity poses.
TEST(Cli, NoOdometryIsRefusedUpFrontNamingTheOptions) {
  TempDir tmp;
  {
    std::ofstream bin(tmp.path() / "000000.bin", std::ios::binary);
    const float point[4] = {5.0f, 1.0f, 0.5f, 0.0f};
    bin.write(reinterpret_cast<const char*>(point), sizeof(point));
  }
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "the shipped configurations name learned descriptors";
  const std::string config = "config/segmap.yaml";  // ctest runs in the source tree
  for (const std::string command : {"map", "slam"}) {
    const Result r = run(command + " --dataset folder:" + tmp.path().string() + " --config " +
                         config + " --out " + (tmp.path() / "out").string());
    EXPECT_EQ(r.code, 1) << command << ": " << r.err;
    EXPECT_NE(r.err.find("has no odometry: give --odometry FILE"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(tmp.path() / "out")) << command;
  }
}

// The segmentation network of the tests (tests' colour4.onnx) in a config, with its class map.
std::string networkConfig(const std::filesystem::path& dir) {
  std::ofstream(dir / "colour.yaml")
      << "name: colour4\nclasses:\n  - {id: 0, name: red, class: building}\n"
         "  - {id: 1, name: green, class: vegetation}\n  - {id: 2, name: blue, class: sky}\n"
         "  - {id: 3, name: dark, class: road}\n";
  std::ofstream(dir / "net.yaml") << "semantics:\n  model: " SEMSEGMAP_ONNX_DIR
                                     "/colour4.onnx\n"
                                     "  class_map: colour.yaml\n  mean: [0, 0, 0]\n"
                                     "  std: [1, 1, 1]\n  replace_dataset_labels: true\n";
  return (dir / "net.yaml").string();
}

// The segmentation network as a user runs it: `label` writes a label set once (with a preview to
// look at), later commands read it with --labels; a config without a network, or a label set of
// another dataset, is refused in one line before any frame.
TEST(Cli, LabelWritesALabelSetThatLaterCommandsRead) {
  if (!SEMSEGMAP_WITH_SIM) GTEST_SKIP() << "the pictures come from the simulator";
  TempDir tmp;
  const auto dir = tmp.path();
  networkConfig(dir);
  const std::string data = " --dataset sim:preset=tiny,frames=2";
  const Result r = run("label" + data + " --config " + (dir / "net.yaml").string() + " --out " +
                       (dir / "labels").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("label images 6: network 6"), std::string::npos) << r.out;
  for (const char* file : {"labels.yaml", "preview.png", "cam0/000000.png", "cam2/000001.png"})
    EXPECT_TRUE(std::filesystem::exists(dir / "labels" / file)) << file;
  const Result enrich = run("enrich" + data + " --labels " + (dir / "labels").string() + " --out " +
                            (dir / "e.png").string());
  EXPECT_EQ(enrich.code, 0) << enrich.err;
  std::ofstream(dir / "none.yaml") << "semantics:\n  class_map: cityscapes\n";
  const Result none = run("label" + data + " --config " + (dir / "none.yaml").string() + " --out " +
                          (dir / "l2").string());
  EXPECT_EQ(none.code, 1);
  EXPECT_NE(none.err.find("none.yaml: semantics.model: empty"), std::string::npos) << none.err;
  const Result other = run("enrich --dataset sim:preset=tiny,frames=3 --labels " +
                           (dir / "labels").string() + " --out " + (dir / "e2.png").string());
  EXPECT_EQ(other.code, 1);
  EXPECT_NE(other.err.find("labels a dataset of 2 frames, this one has 3"), std::string::npos)
      << other.err;
}

// ---------------------------------------------------------------------------------------------
// Errors before the work, maps that refuse another configuration, no half-written outputs

// Runs `semsegmap ARGS` with stderr on a pseudo-terminal (so that progress is drawn with '\r'),
// stdout to /dev/null; returns what the terminal showed.
Result runOnTerminal(const std::string& args) {
  Result r;
  int master = -1, slave = -1;
  if (::openpty(&master, &slave, nullptr, nullptr, nullptr) != 0) return r;
  const std::string command = "exec '" + g_binary + "' " + args;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(master);
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(slave, 2);
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(slave);
  char buffer[4096];
  ssize_t n = 0;
  while ((n = ::read(master, buffer, sizeof buffer)) > 0) r.err.append(buffer, size_t(n));
  ::close(master);
  int status = 0;
  ::waitpid(pid, &status, 0);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The peak resident size (KiB) of `semsegmap ARGS`, from a child that runs it and waits for it
// alone (RUSAGE_CHILDREN of this process would keep the largest of every earlier test).
long peakKib(const std::string& args, int* code) {
  int pipe_fds[2];
  if (::pipe(pipe_fds) != 0) return -1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipe_fds[0]);
    const std::string command = "'" + g_binary + "' " + args + " > /dev/null 2>&1 < /dev/null";
    const int status = std::system(command.c_str());
    rusage usage{};
    ::getrusage(RUSAGE_CHILDREN, &usage);
    const long values[2] = {WIFEXITED(status) ? WEXITSTATUS(status) : -1, usage.ru_maxrss};
    if (::write(pipe_fds[1], values, sizeof values) != sizeof values) ::_exit(1);
    ::_exit(0);
  }
  ::close(pipe_fds[1]);
  long values[2] = {-1, -1};
  if (::read(pipe_fds[0], values, sizeof values) != sizeof values) values[1] = -1;
  ::close(pipe_fds[0]);
  ::waitpid(pid, nullptr, 0);
  *code = static_cast<int>(values[0]);
  return values[1];
}

size_t lines(const std::string& text) {
  return static_cast<size_t>(std::count(text.begin(), text.end(), '\n'));
}

// A dataset directory of three simulated frames with cameras and label images, made once per
// process; tests damage copies of it.
const std::filesystem::path& simulatedDataset() {
  struct Made {
    std::filesystem::path dir;
    ~Made() {
      std::error_code ignored;
      std::filesystem::remove_all(dir.parent_path(), ignored);
    }
  };
  static Made made = [] {
    Made m;
    m.dir = std::filesystem::temp_directory_path() /
            ("semsegmap_cli_data_" + std::to_string(::getpid())) / "tiny";
    std::filesystem::create_directories(m.dir.parent_path());  // an output's folder must exist
    const Result r = run("simulate --world tiny --run S2 --max-frames 3 --out " + m.dir.string());
    EXPECT_EQ(r.code, 0) << r.err;
    return m;
  }();
  return made.dir;
}

std::filesystem::path copyOfDataset(const std::filesystem::path& to) {
  std::filesystem::copy(simulatedDataset(), to, std::filesystem::copy_options::recursive);
  return to;
}

// An eigen-descriptor configuration (no model to load), with `extra` YAML appended.
std::string eigenConfig(const std::filesystem::path& dir, const std::string& name,
                        const std::string& extra = "") {
  const std::filesystem::path path = dir / name;
  std::ofstream(path) << "descriptor:\n  kind: eigen\n" << extra;
  return path.string();
}

// Whether `text` shows a progress line of `command` (a frame was processed).
bool showsProgress(const std::string& text, const std::string& command) {
  return text.find(command + " [") != std::string::npos;
}

// The lines of `err` that are errors (the notes before them are not).
size_t errorLines(const std::string& err) {
  std::istringstream in(err);
  size_t n = 0;
  for (std::string line; std::getline(in, line);) n += line.find(": error: ") != std::string::npos;
  return n;
}

// The poses of a dataset directory's frames.csv (`odom_` or `gt_` columns) as a TUM file and as
// a KITTI file (one line per frame, line N for frame N), and its times one per line.
struct PoseFilesOf {
  std::string tum, kitti, times;
};
PoseFilesOf poseFilesOf(const std::filesystem::path& dataset, const std::string& prefix) {
  std::istringstream csv(readFile(dataset / "frames.csv"));
  std::string line;
  std::getline(csv, line);
  std::vector<std::string> header;
  std::istringstream names(line);
  for (std::string name; std::getline(names, name, ',');) header.push_back(name);
  const size_t first =
      static_cast<size_t>(std::find(header.begin(), header.end(), prefix + "x") - header.begin());
  PoseFilesOf files;
  while (std::getline(csv, line)) {
    std::vector<double> v;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) v.push_back(std::stod(cell));
    const double x = v[first], y = v[first + 1], z = v[first + 2], qx = v[first + 3],
                 qy = v[first + 4], qz = v[first + 5], qw = v[first + 6];
    char text[512];
    std::snprintf(text, sizeof(text), "%.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", v[1], x, y, z,
                  qx, qy, qz, qw);
    files.tum += text;
    std::snprintf(text, sizeof(text), "%.9f\n", v[1]);
    files.times += text;
    // The rotation matrix of the unit quaternion, row by row, each row followed by translation.
    const double R[3][3] = {
        {1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)},
        {2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)},
        {2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)}};
    const double t[3] = {x, y, z};
    for (int r = 0; r < 3; ++r) {
      std::snprintf(text, sizeof(text), "%.9f %.9f %.9f %.9f%s", R[r][0], R[r][1], R[r][2], t[r],
                    r < 2 ? " " : "\n");
      files.kitti += text;
    }
  }
  return files;
}

// `--odometry FILE` and `--ground-truth FILE` as the README shows them, in KITTI and in TUM
// format, on a folder of scans named by frame number with one of them missing (frames 0 and 2):
// KITTI lines go by frame number, TUM poses by the times of a times file; each run says which
// rule it used, and a file that fits none is refused in one line naming it.
TEST(CliPoseFiles, MapAndLocalizeWithOdometryFilesInKittiAndTumFormat) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path data = copyOfDataset(tmp.path() / "data"), dir = tmp.path();
  std::filesystem::remove(data / "lidar" / "000001.bin");
  const PoseFilesOf odom = poseFilesOf(data, "odom_"), gt = poseFilesOf(data, "gt_");
  std::ofstream(dir / "odom_kitti.txt") << odom.kitti;
  std::ofstream(dir / "odom.tum") << odom.tum;
  std::ofstream(dir / "gt_kitti.txt") << gt.kitti;
  std::istringstream all_times(odom.times);
  std::string t0, t1, t2;
  all_times >> t0 >> t1 >> t2;
  std::ofstream(dir / "times.txt") << t0 << "\n" << t2 << "\n";  // the scans that are left
  const std::string config = " --config " + eigenConfig(dir, "eigen.yaml");
  const std::string scans = " --dataset folder:" + (data / "lidar").string();
  const std::string map = (dir / "m.map").string();

  const Result m = run("map" + scans + " --odometry " + (dir / "odom_kitti.txt").string() + config +
                       " --out " + map);
  ASSERT_EQ(m.code, 0) << m.err;
  EXPECT_NE(m.err.find("odom_kitti.txt: KITTI poses matched by frame number"), std::string::npos)
      << m.err;
  const Result l =
      run("localize" + scans + ",times=" + (dir / "times.txt").string() + " --odometry " +
          (dir / "odom.tum").string() + " --ground-truth " + (dir / "gt_kitti.txt").string() +
          config + " --map " + map + " --out " + (dir / "loc").string());
  ASSERT_EQ(l.code, 0) << l.err;
  EXPECT_NE(l.err.find("odom.tum: TUM poses matched by time"), std::string::npos) << l.err;
  const std::string summary = readFile(dir / "loc" / "summary.json");
  EXPECT_NE(summary.find("\"has_ground_truth\": true"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"odometry_is_ground_truth\": false"), std::string::npos) << summary;

  // TUM poses for scans whose names are frame numbers and no times file: no rule fits.
  const Result tum = run("map" + scans + " --odometry " + (dir / "odom.tum").string() + config +
                         " --out " + (dir / "m2.map").string());
  EXPECT_EQ(tum.code, 1);
  EXPECT_EQ(errorLines(tum.err), 1u) << tum.err;
  EXPECT_NE(tum.err.find("odom.tum: TUM poses are matched to scans by time"), std::string::npos)
      << tum.err;
  // Two KITTI lines for scans up to frame 2.
  std::ofstream(dir / "short.txt")
      << odom.kitti.substr(0, odom.kitti.find('\n') + 1) + "1 0 0 0 0 1 0 0 0 0 1 0\n";
  const Result few = run("map" + scans + " --odometry " + (dir / "short.txt").string() + config +
                         " --out " + (dir / "m3.map").string());
  EXPECT_EQ(few.code, 1);
  EXPECT_NE(few.err.find("short.txt: 2 KITTI poses, but the scans go up to frame 2"),
            std::string::npos)
      << few.err;
}

// `label --max-frames 1` records the one frame it labelled, and `map --labels` refuses the set
// unless it reads no more; a `label` stopped half way leaves no labels.yaml, even where an
// earlier whole set was.
TEST(CliLabelSets, ASetRecordsTheFramesItLabelledAndAStoppedRunLeavesNoneWhole) {
  if (!built("simulate")) GTEST_SKIP() << "the pictures come from the simulator";
  TempDir tmp;
  const std::filesystem::path dir = tmp.path(), labels = dir / "labels";
  const std::string net = networkConfig(dir);
  const std::string data = " --dataset sim:preset=tiny,frames=2";
  const Result r =
      run("label" + data + " --config " + net + " --out " + labels.string() + " --max-frames 1");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string yaml = readFile(labels / "labels.yaml");
  EXPECT_NE(yaml.find("frames: 1\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("dataset_frames: 2\n"), std::string::npos) << yaml;
  const std::string map =
      " --config " + eigenConfig(dir, "eigen.yaml") + " --labels " + labels.string() + " --out ";
  const Result all = run("map" + data + map + (dir / "all.map").string());
  EXPECT_EQ(all.code, 1);
  EXPECT_EQ(lines(all.err), 1u) << all.err;
  EXPECT_NE(all.err.find(labels.string() + ": the label set labels frames 0 to 0 only"),
            std::string::npos)
      << all.err;
  const Result one = run("map" + data + map + (dir / "one.map").string() + " --max-frames 1");
  EXPECT_EQ(one.code, 0) << one.err;

  // A whole set, then a run over it that fails at its last frame's picture.
  const std::filesystem::path copy = copyOfDataset(dir / "data");
  const std::string label =
      "label --dataset " + copy.string() + " --config " + net + " --out " + labels.string();
  ASSERT_EQ(run(label).code, 0);
  ASSERT_TRUE(std::filesystem::exists(labels / "labels.yaml"));
  // Its header stays (the up-front check reads the size), its pixels are cut off.
  const std::filesystem::path picture = copy / "cam0" / "000002.png";
  std::filesystem::resize_file(picture, std::filesystem::file_size(picture) / 2);
  const Result stopped = run(label);
  EXPECT_EQ(stopped.code, 1) << stopped.err;
  EXPECT_FALSE(std::filesystem::exists(labels / "labels.yaml"));
  const Result refused = run("map --dataset " + copy.string() + map + (dir / "x.map").string());
  EXPECT_EQ(refused.code, 1);
  EXPECT_NE(refused.err.find("labels.yaml: missing"), std::string::npos) << refused.err;
}

// One file as odometry and ground truth: the run says so, and its errors are marked.
TEST(CliPoseFiles, GroundTruthAsOdometryIsSaidAndMarked) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path data = copyOfDataset(tmp.path() / "data"), dir = tmp.path();
  std::ofstream(dir / "gt.txt") << poseFilesOf(data, "gt_").kitti;
  const std::string config = " --config " + eigenConfig(dir, "eigen.yaml");
  const std::string posed = " --dataset folder:" + (data / "lidar").string() + " --odometry " +
                            (dir / "gt.txt").string() + " --ground-truth " +
                            (dir / "gt.txt").string();
  const std::string map = (dir / "m.map").string();
  ASSERT_EQ(run("map" + posed + config + " --out " + map).code, 0);
  const Result l =
      run("localize" + posed + config + " --map " + map + " --out " + (dir / "loc").string());
  ASSERT_EQ(l.code, 0) << l.err;
  EXPECT_NE(l.err.find("ground-truth poses serve as its odometry too"), std::string::npos) << l.err;
  const std::string summary = readFile(dir / "loc" / "summary.json");
  EXPECT_NE(summary.find("\"odometry_is_ground_truth\": true"), std::string::npos) << summary;
  if (summary.find("\"n_localizations\": 0") == std::string::npos) {  // errors printed: marked
    EXPECT_NE(l.out.find("[errors against the ground truth used as odometry]"), std::string::npos)
        << l.out;
  }
}

// The n-th line of a CSV file as its fields (line 0: the header).
std::vector<std::string> csvLine(const std::filesystem::path& file, size_t n) {
  std::istringstream in(readFile(file));
  std::string line;
  for (size_t i = 0; i <= n; ++i) std::getline(in, line);
  std::vector<std::string> fields;
  std::istringstream cells(line + ",");  // a last empty field is a field too
  for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(cell);
  return fields;
}

// A copy of the simulated dataset in DIR/data without its scan `left_out`, and DIR/odom.txt, the
// odometry of all its frames as a KITTI file. Returns the copy.
std::filesystem::path scansWithout(const std::filesystem::path& dir, const std::string& left_out) {
  const std::filesystem::path data = copyOfDataset(dir / "data");
  std::filesystem::remove(data / "lidar" / left_out);
  std::ofstream(dir / "odom.txt") << poseFilesOf(data, "odom_").kitti;
  return data;
}

// Scans named by frame number (000001.bin left out), odometry from a KITTI file, no ground truth
// and no times: what is unknown is null or empty, never 0 or made up, frames are named as the
// dataset names them, and the summary line says no "<1 m".
TEST(CliPoseFiles, WithoutGroundTruthOrTimesNothingIsMadeUp) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path dir = tmp.path(), data = scansWithout(dir, "000001.bin");
  const std::string config = " --config " + eigenConfig(dir, "eigen.yaml");
  const std::string scans = " --dataset folder:" + (data / "lidar").string() + " --odometry " +
                            (dir / "odom.txt").string();
  const std::string map = (dir / "m.map").string();
  ASSERT_EQ(run("map" + scans + config + " --out " + map).code, 0);
  const Result l =
      run("localize" + scans + config + " --map " + map + " --out " + (dir / "loc").string());
  ASSERT_EQ(l.code, 0) << l.err;
  EXPECT_NE(l.out.find("(no ground truth: errors unknown)"), std::string::npos) << l.out;
  EXPECT_EQ(l.out.find("<1 m"), std::string::npos) << l.out;
  const std::string summary = readFile(dir / "loc" / "summary.json");
  EXPECT_NE(summary.find("\"schema\": \"semsegmap.localization/4\""), std::string::npos);
  EXPECT_NE(summary.find("\"n_error_below_1m\": null"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"n_error_below_5m\": null"), std::string::npos) << summary;
  const std::vector<std::string> header = csvLine(dir / "loc" / "localizations.csv", 0);
  ASSERT_GE(header.size(), 3u);
  EXPECT_EQ(header[1], "dataset_frame");
  EXPECT_EQ(header[2], "timestamp");
  // Run frame 1 is the scan named 000002: its number, and no time (the data has none).
  const std::vector<std::string> second = csvLine(dir / "loc" / "trajectory.csv", 2);
  ASSERT_GE(second.size(), 3u);
  EXPECT_EQ(second[0], "1");
  EXPECT_EQ(second[1], "2");
  EXPECT_EQ(second[2], "");
}

// localize --relocalize: a map without segment points is refused before any frame, --prior needs
// --relocalize and two or three numbers, and localizations.csv says which path gave each pose.
TEST(CliPoseFiles, RelocalizeChecksItsMapAndPriorAndNamesEachPath) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path dir = tmp.path(), data = scansWithout(dir, "000001.bin");
  const std::string config = " --config " + eigenConfig(dir, "eigen.yaml");
  const std::string scans = " --dataset folder:" + (data / "lidar").string() + " --odometry " +
                            (dir / "odom.txt").string();
  const std::string bare = (dir / "bare.map").string(), dense = (dir / "dense.map").string();
  ASSERT_EQ(run("map" + scans + config + " --out " + bare).code, 0);
  const std::string localize = "localize" + scans + config + " --out " + (dir / "loc").string();
  // A map without the points relocalization needs still localizes, with it off, and says in
  // one line how to rebuild it.
  const Result no_points = run(localize + " --map " + bare + " --relocalize");
  EXPECT_EQ(no_points.code, 0) << no_points.err;
  const size_t said = no_points.err.find(
      "bare.map: keeps no points a segment, too few to check a relocalization, so relocalization "
      "is off for this run; rebuild the map with target_map.max_points_per_segment: 512");
  EXPECT_NE(said, std::string::npos) << no_points.err;
  if (said != std::string::npos) {
    const std::string line = no_points.err.substr(said, no_points.err.find('\n', said) - said);
    EXPECT_NE(line.find("target_map.scan_context_apart_m: 1.0"), std::string::npos)
        << "one line: " << line;
  }
  const Result prior_alone = run(localize + " --map " + bare + " --prior 1,2");
  EXPECT_EQ(prior_alone.code, 2);
  EXPECT_NE(prior_alone.err.find("--prior narrows a relocalization: give --relocalize too"),
            std::string::npos);
  for (const char* bad : {"1,x", "1", "1,2,3,4", "1,2,-5"}) {
    const Result r = run(localize + " --map " + bare + " --relocalize --prior " + bad);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.err.find("--prior: expected X,Y"), std::string::npos) << r.err;
  }
  ASSERT_EQ(run("map" + scans + config + " --points 512 --out " + dense).code, 0);
  const Result ok = run(localize + " --map " + dense + " --relocalize --prior 0,0,500");
  ASSERT_EQ(ok.code, 0) << ok.err;
  const std::vector<std::string> header = csvLine(dir / "loc" / "localizations.csv", 0);
  const auto column = [&](const std::string& name) {
    return static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  for (const char* name :
       {"path", "fitness", "runner_up_fitness", "sigma_x_m", "sigma_yaw_deg", "status"})
    ASSERT_LT(column(name), header.size()) << name;
  const std::string summary = readFile(dir / "loc" / "summary.json");
  EXPECT_NE(summary.find("\"n_by_path\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"n_ambiguous\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"covariance_calibration\""), std::string::npos) << summary;
  for (size_t row = 1;; ++row) {
    const std::vector<std::string> line = csvLine(dir / "loc" / "localizations.csv", row);
    if (line.size() < header.size()) break;
    const std::string path = line[column("path")];
    const bool relocalized = path == "relocalization" || path == "scan-context";
    EXPECT_TRUE(path == "local-map" || path == "latest-scan" || relocalized) << path;
    // A relocalization's pose always went through the registration check; another path's did
    // when it was found while the robot was lost.
    if (relocalized) {
      EXPECT_FALSE(line[column("fitness")].empty()) << row;
      EXPECT_FALSE(line[column("runner_up_fitness")].empty()) << row;
    }
    const std::string status = line[column("status")];
    EXPECT_TRUE(status == "localized" || status == "ambiguous") << status;
    EXPECT_GT(std::stod(line[column("sigma_x_m")]), 0.0) << row;
  }
}

// slam and odometry on data without frame times write no TUM file (its times would be made up
// from the rate): the KITTI files carry the poses, a note says so, and `semsegmap view` reads
// them.
TEST(CliPoseFiles, WithoutFrameTimesNoTumFileIsWritten) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path data = copyOfDataset(tmp.path() / "data"), dir = tmp.path();
  std::ofstream(dir / "odom.txt") << poseFilesOf(data, "odom_").kitti;
  const std::string scans = " --dataset folder:" + (data / "lidar").string();
  const Result slam =
      run("slam" + scans + " --odometry " + (dir / "odom.txt").string() + " --config " +
          eigenConfig(dir, "eigen.yaml") + " --out " + (dir / "slam").string());
  ASSERT_EQ(slam.code, 0) << slam.err;
  EXPECT_NE(slam.err.find("no trajectory_tum.txt or odometry_tum.txt"), std::string::npos)
      << slam.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "slam" / "trajectory_tum.txt"));
  EXPECT_FALSE(std::filesystem::exists(dir / "slam" / "odometry_tum.txt"));
  EXPECT_EQ(lines(readFile(dir / "slam" / "trajectory_kitti.txt")), 3u);
  EXPECT_EQ(lines(readFile(dir / "slam" / "odometry_kitti.txt")), 3u);
  EXPECT_NE(readFile(dir / "slam" / "summary.json").find("\"has_frame_times\": false"),
            std::string::npos);

  const Result odometry = run("odometry" + scans + " --out " + (dir / "odo").string());
  ASSERT_EQ(odometry.code, 0) << odometry.err;
  EXPECT_NE(odometry.err.find("no trajectory_tum.txt"), std::string::npos) << odometry.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "odo" / "trajectory_tum.txt"));
  EXPECT_EQ(lines(readFile(dir / "odo" / "trajectory_kitti.txt")), 3u);
  EXPECT_NE(readFile(dir / "odo" / "summary.json").find("\"has_frame_times\": false"),
            std::string::npos);

  // With the data's times (the simulator's) the TUM files are there.
  const Result timed =
      run("odometry --dataset " + data.string() + " --out " + (dir / "timed").string());
  ASSERT_EQ(timed.code, 0) << timed.err;
  EXPECT_EQ(lines(readFile(dir / "timed" / "trajectory_tum.txt")), 3u);
  EXPECT_EQ(timed.err.find("no trajectory_tum.txt"), std::string::npos) << timed.err;
}

// The header and row `n` (from 1) of a trajectory.csv, the fields a test looks at: frame,
// dataset_frame, timestamp.
void expectFrameNames(const std::filesystem::path& csv, size_t n, const std::string& frame,
                      const std::string& dataset_frame, const std::string& timestamp) {
  SCOPED_TRACE(csv.string() + " row " + std::to_string(n));
  const std::vector<std::string> header = csvLine(csv, 0), row = csvLine(csv, n);
  ASSERT_GE(header.size(), 3u);
  EXPECT_EQ(header[0], "frame");
  EXPECT_EQ(header[1], "dataset_frame");
  EXPECT_EQ(header[2], "timestamp");
  ASSERT_EQ(row.size(), header.size());
  EXPECT_EQ(row[0], frame);
  EXPECT_EQ(row[1], dataset_frame);
  EXPECT_EQ(row[2], timestamp);
}

// slam and odometry write trajectory.csv as localize does: the run's frame, the dataset's own
// name of it and its time. A folder whose first scan is 000001 (000000 left out): run frame 0 is
// dataset frame 1, and with no times the timestamp stays empty, never made up.
TEST(CliPoseFiles, SlamAndOdometryNameTheDatasetsFramesInTrajectoryCsv) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path dir = tmp.path(), data = scansWithout(dir, "000000.bin");
  const std::string scans = " --dataset folder:" + (data / "lidar").string();
  const Result slam =
      run("slam" + scans + " --odometry " + (dir / "odom.txt").string() + " --config " +
          eigenConfig(dir, "eigen.yaml") + " --out " + (dir / "slam").string());
  ASSERT_EQ(slam.code, 0) << slam.err;
  const std::filesystem::path slam_csv = dir / "slam" / "trajectory.csv";
  EXPECT_EQ(lines(readFile(slam_csv)), 3u);  // the header and the two frames
  expectFrameNames(slam_csv, 1, "0", "1", "");
  expectFrameNames(slam_csv, 2, "1", "2", "");
  EXPECT_EQ(csvLine(slam_csv, 0)[3], "slam_x");
  const Result odometry = run("odometry" + scans + " --out " + (dir / "odo").string());
  ASSERT_EQ(odometry.code, 0) << odometry.err;
  expectFrameNames(dir / "odo" / "trajectory.csv", 2, "1", "2", "");
  EXPECT_EQ(csvLine(dir / "odo" / "trajectory.csv", 0)[3], "odom_x");

  // With the data's times (the simulator's), each row has its frame's time, as the TUM file.
  const std::filesystem::path whole = copyOfDataset(dir / "whole");
  const Result timed =
      run("odometry --dataset " + whole.string() + " --out " + (dir / "timed").string());
  ASSERT_EQ(timed.code, 0) << timed.err;
  const std::string tum_time = readFile(dir / "timed" / "trajectory_tum.txt").substr(0, 8);
  const std::string csv_time = csvLine(dir / "timed" / "trajectory.csv", 1).at(2);
  EXPECT_FALSE(csv_time.empty());
  EXPECT_EQ(csv_time.substr(0, 8), tum_time);
}

// On real data, the first ten scans of KITTI 00 as PCD files from scan 000004 on: LiDAR
// odometry's trajectory.csv names run frame 0 as the dataset's frame 4.
TEST(CliPoseFiles, OdometryOnRealScansFromALaterFrameNamesThemInTrajectoryCsv) {
  const std::filesystem::path sample =
      std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti00_first10_pcd";
  if (!std::filesystem::exists(sample))
    GTEST_SKIP() << "the real KITTI 00 PCD scans (../shared/data/kitti00_first10_pcd) are absent";
  if (!SEMSEGMAP_WITH_PCL)
    GTEST_SKIP() << "PCD files are read with PCL, which this build leaves out";
  TempDir tmp;
  const std::filesystem::path scans = tmp.path() / "scans";
  std::filesystem::create_directories(scans);
  for (int k = 4; k <= 6; ++k) {
    const std::string name = "00000" + std::to_string(k) + ".pcd";
    std::filesystem::create_symlink(sample / name, scans / name);
  }
  const std::filesystem::path out = tmp.path() / "odo";
  const Result r = run("odometry --dataset folder:" + scans.string() + " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(lines(readFile(out / "trajectory.csv")), 4u);
  expectFrameNames(out / "trajectory.csv", 1, "0", "4", "");
  expectFrameNames(out / "trajectory.csv", 3, "2", "6", "");
}

// Runs `semsegmap ARGS` with stderr into a pipe and stdout to /dev/null; once stderr shows
// `progress`, sends `signals` SIGINTs to it, as a user pressing Ctrl-C. Returns the exit code
// and all of stderr.
Result runAndInterrupt(const std::string& args, const std::string& progress, int signals) {
  Result r;
  int fds[2];
  if (::pipe(fds) != 0) return r;
  const std::string command = "exec '" + g_binary + "' " + args;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(fds[0]);
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(fds[1], 2);
    // As a command typed at a terminal: SIGINT not ignored, whatever this test inherited (a
    // background job of a script runs with it ignored, and semsegmap keeps it so).
    ::signal(SIGINT, SIG_DFL);
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ::close(fds[1]);
  char buffer[4096];
  ssize_t n = 0;
  bool sent = false;
  while ((n = ::read(fds[0], buffer, sizeof buffer)) > 0) {
    r.err.append(buffer, size_t(n));
    if (sent || r.err.find(progress) == std::string::npos) continue;
    for (int k = 0; k < signals; ++k) {
      // Apart, or the kernel merges two pending ones into one; well within a frame (~0.3 s).
      if (k > 0) ::usleep(20000);
      ::kill(pid, SIGINT);
    }
    sent = true;
  }
  ::close(fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// The files under `dir` whose names say they are an atomic write's temporary (".NAME.tmp-...").
std::vector<std::string> temporaryFiles(const std::filesystem::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos)
      found.push_back(e.path().string());
  return found;
}

// Ctrl-C during a run: the frame in hand finishes, the frames done are written whole, one line
// says so, summary.json says interrupted with the frames done, exit 130.
TEST(CliInterrupt, CtrlCWritesTheFramesDoneAndExits130) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path out = tmp.path() / "slam";
  const size_t total = 200;  // the whole run S2 of the tiny preset
  const Result r = runAndInterrupt(
      "slam --dataset sim:world=1,run=S2,preset=tiny,frames=" + std::to_string(total) +
          " --config " + eigenConfig(tmp.path(), "eigen.yaml") + " --out " + out.string(),
      "slam [", 1);
  EXPECT_EQ(r.code, 130) << r.err;
  const std::string prefix = "semsegmap slam: interrupted after ";
  const size_t at = r.err.find(prefix);
  ASSERT_NE(at, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find(prefix, at + 1), std::string::npos) << r.err;  // one line
  size_t done = 0, of = 0;
  ASSERT_EQ(std::sscanf(r.err.c_str() + at + prefix.size(), "%zu of %zu frames", &done, &of), 2)
      << r.err;
  EXPECT_EQ(of, total);
  EXPECT_GT(done, 0u);
  EXPECT_LT(done, total);
  const std::string line = r.err.substr(at, r.err.find('\n', at) - at);
  EXPECT_EQ(line, prefix + std::to_string(done) + " of " + std::to_string(total) + " frames; " +
                      out.string() + " holds the " + std::to_string(done) + " frames done");
  const std::string summary = readFile(out / "summary.json");
  EXPECT_NE(summary.find("\"interrupted\": true"), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"frames\": " + std::to_string(done) + ","), std::string::npos)
      << summary;
  EXPECT_EQ(temporaryFiles(tmp.path()), std::vector<std::string>{});
  // Every file whole: one pose per frame done, and the folder reads as a slam output (the view).
  EXPECT_EQ(lines(readFile(out / "trajectory_tum.txt")), done);
  EXPECT_EQ(lines(readFile(out / "trajectory_kitti.txt")), done);
  EXPECT_EQ(readFile(out / "loops.csv").rfind("frame,old_frame,inliers,correction_m\n", 0), 0u);
  EXPECT_TRUE(std::filesystem::exists(out / "slam.png"));
}

// A second Ctrl-C does not wait for the frame in hand: the process exits at once, with 130.
TEST(CliInterrupt, ASecondCtrlCExitsAtOnce) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const Result r =
      runAndInterrupt("odometry --dataset sim:world=1,run=S2,preset=tiny,frames=300 --out " +
                          (tmp.path() / "odo").string(),
                      "odometry [", 2);
  EXPECT_EQ(r.code, 130) << r.err;
  EXPECT_NE(r.err.find("interrupted again: exiting at once"), std::string::npos) << r.err;
}

// A label set stopped by Ctrl-C lists only the frames whose labels are complete, marked so.
TEST(CliInterrupt, AnInterruptedLabelSetListsTheFramesDone) {
  if (!built("simulate")) GTEST_SKIP() << "the pictures come from the simulator";
  TempDir tmp;
  const std::filesystem::path labels = tmp.path() / "labels";
  const Result r = runAndInterrupt("label --dataset sim:preset=tiny,frames=300 --config " +
                                       networkConfig(tmp.path()) + " --out " + labels.string(),
                                   "label [", 1);
  EXPECT_EQ(r.code, 130) << r.err;
  const std::string prefix = "semsegmap label: interrupted after ";
  const size_t at = r.err.find(prefix);
  ASSERT_NE(at, std::string::npos) << r.err;
  size_t done = 0;
  ASSERT_EQ(std::sscanf(r.err.c_str() + at + prefix.size(), "%zu", &done), 1);
  const std::string yaml = readFile(labels / "labels.yaml");
  EXPECT_NE(yaml.find("frames: " + std::to_string(done) + "\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("interrupted: true"), std::string::npos) << yaml;
  const auto picture = [&labels](size_t frame) {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.png", frame);
    return labels / "cam0" / name;
  };
  ASSERT_GT(done, 0u);
  EXPECT_TRUE(std::filesystem::exists(picture(done - 1)));
  EXPECT_FALSE(std::filesystem::exists(picture(done)));
  EXPECT_EQ(temporaryFiles(tmp.path()), std::vector<std::string>{});
}

// The one line an interrupted run prints on stderr, which begins with `prefix`; empty (a test
// failure) when there is none or more than one.
std::string interruptedLine(const std::string& err, const std::string& prefix) {
  const size_t at = err.find(prefix);
  if (at == std::string::npos) {
    ADD_FAILURE() << "no '" << prefix << "' in\n" << err;
    return "";
  }
  EXPECT_EQ(err.find(prefix, at + 1), std::string::npos) << err;  // one line
  return err.substr(at, err.find('\n', at) - at);
}

// `make demo`'s command to its end on a few frames of the tiny world: the results table with both
// configurations and both label passes, the report and its pictures, the viewer's page. (CI runs
// this instead of the whole demo beside its builds, where it took a core for 17 minutes.)
TEST(CliDemo, RunsToItsEndAndPrintsTheTableWithTheNetworkRows) {
  if (!built("demo")) GTEST_SKIP() << "demo needs the simulator";
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "demo's SemSegMap configuration needs libtorch";
  TempDir tmp;
  const std::filesystem::path out = tmp.path() / "demo";
  const Result r = run("demo --preset tiny --max-frames 30 --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| run | config | localizations | < 1 m |"), std::string::npos) << r.out;
  for (const char* row : {"| S2 | semsegmap | ", "| S2 | segmap | ", "| S2 | semsegmap, network | ",
                          "| S3 | semsegmap | ", "| S3 | segmap, network | "})
    EXPECT_NE(r.out.find(row), std::string::npos) << row << "\n" << r.out;
  EXPECT_NE(r.out.find("wrote " + (out / "report.md").string()), std::string::npos) << r.out;
  // SemSegMap localizes on S2 within its first 30 frames (the table's third column).
  const size_t row = r.out.find("| S2 | semsegmap | ");
  ASSERT_NE(row, std::string::npos);
  EXPECT_GT(std::stoi(r.out.substr(row + std::string("| S2 | semsegmap | ").size())), 0) << r.out;
  for (const char* file : {"report.md", "overview.png", "localization_accuracy.png",
                           "localization.json", "semsegmap_S3/localization.png"})
    EXPECT_GT(std::filesystem::file_size(out / file), 100u) << file;
  if (built("view")) {
    EXPECT_TRUE(std::filesystem::exists(out / "view.html"));
  }
  EXPECT_EQ(readFile(out / "report.md").find("Partial: interrupted"), std::string::npos);
  EXPECT_EQ(temporaryFiles(tmp.path()), std::vector<std::string>{});
}

// Ctrl-C during `demo`'s S2 run: the frame in hand finishes, the S2 folders are written whole
// with its frames done, S3 never starts, localization.json and report.md say interrupted.
TEST(CliInterrupt, AnInterruptedDemoWritesTheRunsDoneMarkedInterrupted) {
  if (!built("demo")) GTEST_SKIP() << "demo needs the simulator";
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "demo's SemSegMap configuration needs libtorch";
  TempDir tmp;
  const std::filesystem::path out = tmp.path() / "demo";
  const Result r = runAndInterrupt("demo --preset tiny --max-frames 12 --out " + out.string(),
                                   "localize S2 [", 1);
  EXPECT_EQ(r.code, 130) << r.err;
  const std::string line = interruptedLine(r.err, "semsegmap demo: interrupted in localize S2 at ");
  EXPECT_NE(line.find(" of 12; " + out.string() + " holds the work done, marked interrupted"),
            std::string::npos)
      << line;
  const std::string json = readFile(out / "localization.json");
  EXPECT_NE(json.find("\"interrupted\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"run\": \"S2\""), std::string::npos) << json;
  EXPECT_EQ(json.find("\"run\": \"S3\""), std::string::npos) << json;
  EXPECT_NE(readFile(out / "semsegmap_S2" / "summary.json").find("\"interrupted\": true"),
            std::string::npos);
  EXPECT_FALSE(std::filesystem::exists(out / "semsegmap_S3"));
  EXPECT_NE(readFile(out / "report.md").find("Partial: interrupted"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out / "localization_accuracy.png"));
  EXPECT_EQ(temporaryFiles(tmp.path()), std::vector<std::string>{});
}

// Ctrl-C while `eval localization` maps: the maps of the frames done are saved, no query run
// starts, and localization.json says interrupted with no results.
TEST(CliInterrupt, AnInterruptedLocalizationExperimentKeepsTheMapsOfTheFramesDone) {
  if (!built("eval localization")) GTEST_SKIP() << "the experiment needs the simulator";
  TempDir tmp;
  const std::filesystem::path out = tmp.path() / "eval";
  const std::string configs =
      eigenConfig(tmp.path(), "a.yaml") + "," + eigenConfig(tmp.path(), "b.yaml");
  const Result r = runAndInterrupt("eval localization --preset tiny --max-frames 12 --configs " +
                                       configs + " --query-runs S2 --out " + out.string(),
                                   "map S0 [", 1);
  EXPECT_EQ(r.code, 130) << r.err;
  const std::string line =
      interruptedLine(r.err, "semsegmap eval localization: interrupted in map S0 at ");
  EXPECT_NE(line.find(" of 12; " + out.string() + " holds the work done, marked interrupted"),
            std::string::npos)
      << line;
  const std::string json = readFile(out / "localization.json");
  EXPECT_NE(json.find("\"interrupted\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"results\": []"), std::string::npos) << json;
  EXPECT_GT(std::filesystem::file_size(out / "maps" / "a.map"), 0u);
  EXPECT_GT(std::filesystem::file_size(out / "maps" / "b.map"), 0u);
  EXPECT_EQ(temporaryFiles(tmp.path()), std::vector<std::string>{});
}

// Ctrl-C during training: the epoch in hand is dropped, the model of the best epoch completed
// stays (saved when it ended) with the history of the epochs completed, one line says so.
TEST(CliInterrupt, AnInterruptedTrainingKeepsTheBestCompletedEpoch) {
  if (!built("train")) GTEST_SKIP() << "training needs the simulator and libtorch";
  TempDir tmp;
  const std::filesystem::path model = tmp.path() / "net.model", history = tmp.path() / "h.csv";
  const Result r = runAndInterrupt(
      "train --descriptor semsegmap-net --dataset sim:world=1,run=S1,preset=tiny --max-frames 30 "
      "--epochs 1000 --anchors-per-epoch 64 --threads 1 --history " +
          history.string() + " --out " + model.string(),
      "epoch 2/1000", 1);
  EXPECT_EQ(r.code, 130) << r.err;
  const std::string prefix = "semsegmap train: interrupted after ";
  const std::string line = interruptedLine(r.err, prefix);
  size_t done = 0;
  ASSERT_EQ(std::sscanf(line.c_str() + prefix.size(), "%zu of 1000 epochs", &done), 1) << line;
  EXPECT_GE(done, 1u);
  EXPECT_NE(line.find("; " + model.string() + " holds the model of epoch "), std::string::npos)
      << line;
  EXPECT_NE(line.find(", the best of the " + std::to_string(done) + " epochs done"),
            std::string::npos)
      << line;
  EXPECT_EQ(lines(readFile(history)), done + 1);  // the header and one row per epoch completed
  EXPECT_GT(std::filesystem::file_size(model), 0u);
  EXPECT_EQ(temporaryFiles(tmp.path()), std::vector<std::string>{});
  // A whole model: a map describes its segments with it.
  std::ofstream(tmp.path() / "net.yaml")
      << "descriptor:\n  kind: semsegmap-net\n  model: " << model.string() << "\n";
  const Result map =
      run("map --dataset sim:preset=tiny,frames=2 --config " + (tmp.path() / "net.yaml").string() +
          " --out " + (tmp.path() / "m.map").string());
  EXPECT_EQ(map.code, 0) << map.err;
}

// map --out naming a directory or an unwritable place used to fail after every frame.
TEST(CliUpFront, OutputsOfTheWrongKindOrUnwritableFailBeforeFrame0) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::string config = eigenConfig(tmp.path(), "eigen.yaml");
  const std::string data = "--dataset sim:preset=tiny,frames=3 --config " + config;
  const std::filesystem::path dir = tmp.path() / "a_dir", file = tmp.path() / "a_file";
  std::filesystem::create_directories(dir);
  std::ofstream(file) << "x";
  auto expectRefused = [&](const std::string& command, const std::string& args,
                           const std::string& message) {
    const Result r = run(command + " " + data + " " + args);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err.rfind("semsegmap " + command + ": error: " + message, 0), 0u) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_FALSE(showsProgress(r.err, command)) << r.err;
  };
  expectRefused("map", "--out " + dir.string(),
                dir.string() + ": --out is a directory, expected a file");
  expectRefused("map", "--out " + (file / "x.map").string(),
                (file / "x.map").string() + ": --out cannot be created: " + file.string() +
                    " is not a directory");
  expectRefused("segment", "--out " + file.string(),
                file.string() + ": --out exists and is not a directory");
  EXPECT_EQ(readFile(file), "x");
  if (::geteuid() == 0) {
    std::cout << "[   NOTE   ] running as root, where permissions do not stop writes: the "
                 "read-only --out case is not checked\n";
    return;
  }
  const std::filesystem::path locked = tmp.path() / "locked";
  std::filesystem::create_directories(locked);
  ::chmod(locked.c_str(), 0555);
  expectRefused("map", "--out " + (locked / "x.map").string(),
                (locked / "x.map").string() + ": --out cannot be written: " + locked.string());
  expectRefused("segment", "--out " + (locked / "seg").string(),
                (locked / "seg").string() + ": --out cannot be written");
  ::chmod(locked.c_str(), 0755);
}

// The arguments that fill a command's required options other than --out with a value each
// (a choice's first one): enough to parse, not to run.
std::string requiredOptionsBut(const std::string& command, const std::string& except) {
  // Each option's line with the lines its help wraps onto.
  std::vector<std::string> entries;
  std::istringstream in(help(command).out);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("  --", 0) == 0)
      entries.push_back(line);
    else if (!entries.empty() && line.rfind("    ", 0) == 0)
      entries.back() += line;
  }
  std::string args;
  for (const std::string& entry : entries) {
    if (entry.find("(required)") == std::string::npos) continue;
    const auto options = helpOptions(entry + "\n");
    if (options.empty() || options.front().first == except) continue;
    const auto& [name, placeholder] = options.front();
    args +=
        " --" + name + " " +
        (placeholder.find('|') != std::string::npos ? placeholder.substr(0, placeholder.find('|'))
                                                    : std::string("1"));
  }
  return args;
}

// Every command the same: the folder an output goes into must exist. A mistyped --out is refused
// in one line naming that folder, before any work, and nothing is made (it used to grow the
// missing folders silently).
TEST(CliOutputs, EveryCommandRefusesAnOutputWhoseFolderIsMissing) {
  TempDir tmp;
  const std::filesystem::path missing = tmp.path() / "nonexistent" / "dir";
  for (const CommandOptions& c : kCommands) {
    SCOPED_TRACE(c.command);
    // Every command writes --out, but info, which writes --json only when asked, and the store's
    // maps list|show|import|drop, which write into the store alone.
    const auto has = [&](const char* o) {
      return std::find(c.options.begin(), c.options.end(), o) != c.options.end();
    };
    if (!has("out") && !has("json")) continue;
    const std::string option = has("out") ? "out" : "json";
    const Result r = run(c.command + requiredOptionsBut(c.command, option) + " --" + option + " " +
                         (missing / "x.out").string());
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err, "semsegmap " + c.command + ": error: " + (missing / "x.out").string() +
                         ": --" + option + " cannot be written: its folder " + missing.string() +
                         " does not exist (create it first, or choose another)\n");
    EXPECT_FALSE(std::filesystem::exists(tmp.path() / "nonexistent"));
  }
  // An output folder itself may be new, as long as its own folder exists: the failure is then
  // the dataset's, and the folder made for the run is gone again.
  const Result segment =
      run("segment --dataset " + (tmp.path() / "none").string() + " --config " +
          eigenConfig(tmp.path(), "eigen.yaml") + " --out " + (tmp.path() / "seg").string());
  EXPECT_EQ(segment.code, 1);
  EXPECT_NE(segment.err.find("none: no such dataset directory"), std::string::npos) << segment.err;
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "seg"));
}

// A second run into the outputs of a first overwrites them, saying so in one line per output
// (the rule for every command: `make demo` runs into demo_out each time); a failed run into them
// leaves them as they were.
TEST(CliOutputs, ASecondRunReplacesTheFirstOnesOutputsSayingSo) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const std::filesystem::path sim = tmp.path() / "sim", png = tmp.path() / "overview.png";
  const std::string simulate =
      "simulate --world tiny --run S2 --max-frames 1 --no-cameras --out " + sim.string();
  Result r = run(simulate);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("note: --out"), std::string::npos) << r.err;
  r = run(simulate);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("note: --out " + sim.string() + " already holds "), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(" entries: this run's files replace those of the same name, the others "
                       "stay\n"),
            std::string::npos)
      << r.err;
  const std::string overview = "simulate-overview --world tiny --out " + png.string();
  ASSERT_EQ(run(overview).code, 0);
  const auto first = std::filesystem::last_write_time(png);
  r = run(overview);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("note: --out " + png.string() + " exists: this run replaces it\n"),
            std::string::npos)
      << r.err;
  EXPECT_GE(std::filesystem::last_write_time(png), first);
  // A failed run into the first one's folder keeps what was there.
  const std::string frames = readFile(sim / "frames.csv");
  r = run("convert --dataset " + (tmp.path() / "none").string() + " --out " + sim.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(readFile(sim / "frames.csv"), frames);
}

TEST(CliUpFront, AMissingLabelImageIsFoundBeforeFrame0) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const auto data = copyOfDataset(tmp.path() / "data");
  const std::filesystem::path label = data / "cam0_label" / "000002.png";
  ASSERT_TRUE(std::filesystem::exists(label));
  std::filesystem::remove(label);
  const std::string config = eigenConfig(tmp.path(), "eigen.yaml");
  const std::filesystem::path out = tmp.path() / "seg";
  const Result r =
      run("segment --dataset " + data.string() + " --config " + config + " --out " + out.string());
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("semsegmap segment: error: " + label.string() + ": missing"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(showsProgress(r.err, "segment")) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "a failed run left its folder";
  // The first two frames are whole: a run of them does not look at frame 2's files.
  const Result two = run("segment --dataset " + data.string() + " --config " + config +
                         " --max-frames 2 --out " + out.string());
  EXPECT_EQ(two.code, 0) << two.err;
}

// frames.csv used to be parsed whole at about 0.5 KB a row (10^7 rows: 5.3 GB and 48 s even with
// --max-frames 1); now it is indexed in one streamed pass.
TEST(CliUpFront, MaxFrames1OnAMillionRowFramesCsvIsFastAndSmall) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  TempDir tmp;
  const auto data = copyOfDataset(tmp.path() / "data");
  const std::string config = eigenConfig(tmp.path(), "eigen.yaml");
  const std::string args = "segment --dataset " + data.string() + " --config " + config +
                           " --max-frames 1 --out " + (tmp.path() / "seg").string();
  int code = -1;
  const long small = peakKib(args, &code);
  ASSERT_EQ(code, 0);
  std::string last_row;
  {
    std::ifstream in(data / "frames.csv");
    for (std::string line; std::getline(in, line);)
      if (!line.empty()) last_row = line;
  }
  const std::string rest = last_row.substr(last_row.find(','));
  {
    std::ofstream out(data / "frames.csv", std::ios::app);
    for (size_t i = 3; i < 1000000; ++i) out << i << rest << '\n';
  }
  ASSERT_GT(std::filesystem::file_size(data / "frames.csv"), 50u * 1000 * 1000);
  const auto start = std::chrono::steady_clock::now();
  const long large = peakKib(args, &code);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(code, 0);
  EXPECT_LT(large - small, 64L * 1024) << "peak KiB " << small << " -> " << large;
  EXPECT_LT(seconds, 60.0);
}

// Map files as the CLI writes them: the header's strings, the settings, then the segments.
struct MapLayout {
  size_t first_segment = 0;
};

MapLayout mapLayout(const std::string& bytes) {
  size_t at = 8 + 4 + 4;
  for (int s = 0; s < 2; ++s) at += 1 + static_cast<unsigned char>(bytes.at(at));
  at += 4;
  uint16_t parameters = 0;
  std::memcpy(&parameters, &bytes.at(at), 2);
  at += 2;
  for (int p = 0; p < 2 * parameters; ++p) at += 1 + static_cast<unsigned char>(bytes.at(at));
  return {at + 8};
}

// The project's checksum (core/binary_io.h), so that only the patched value is wrong.
void resign(std::string& bytes) {
  uint64_t h = 1469598103934665603ull;
  for (size_t i = 0; i + 8 < bytes.size(); ++i) {
    h ^= static_cast<unsigned char>(bytes[i]);
    h *= 1099511628211ull;
  }
  std::memcpy(&bytes[bytes.size() - 8], &h, 8);
}

class CliMaps : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
    data_ = " --dataset sim:preset=tiny,frames=6";
    config_ = eigenConfig(tmp_.path(), "eigen.yaml");
    map_ = tmp_.path() / "tiny.map";
    const Result r = run("map" + data_ + " --config " + config_ + " --out " + map_.string());
    ASSERT_EQ(r.code, 0) << r.err;
  }
  Result localize(const std::string& config, const std::filesystem::path& map,
                  const std::string& more = "") {
    return run("localize" + data_ + " --config " + config + " --map " + map.string() + " --out " +
               out().string() + more);
  }
  std::filesystem::path out() const { return tmp_.path() / "loc"; }
  TempDir tmp_;
  std::string data_, config_;
  std::filesystem::path map_;
};

// `map` without --points keeps the points its configuration asks for, so that a configuration
// that refines poses (config/lidar-camera.yaml) builds maps its own localization accepts.
TEST_F(CliMaps, MapKeepsTheConfiguredSegmentPointsUnlessPointsIsGiven) {
  const std::string refine = eigenConfig(tmp_.path(), "refine.yaml",
                                         "target_map:\n  max_points_per_segment: 8\n"
                                         "localization:\n  refinement:\n    enabled: true\n");
  const std::filesystem::path with = tmp_.path() / "with.map", none = tmp_.path() / "none.map";
  ASSERT_EQ(run("map" + data_ + " --config " + refine + " --out " + with.string()).code, 0);
  const Result uses = localize(refine, with);
  EXPECT_EQ(uses.code, 0) << uses.err;
  std::filesystem::remove_all(out());
  ASSERT_EQ(run("map" + data_ + " --config " + refine + " --points 0 --out " + none.string()).code,
            0);
  EXPECT_GT(std::filesystem::file_size(with), std::filesystem::file_size(none));
  const Result refused = localize(refine, none);
  EXPECT_EQ(refused.code, 1);
  EXPECT_NE(refused.err.find("stores no segment points"), std::string::npos) << refused.err;
}

// A map grown with another growing radius localized 0 frames with exit 0 and no warning.
TEST_F(CliMaps, AMapBuiltWithOtherSettingsIsRefusedUnlessAllowed) {
  const Result same = localize(config_, map_);
  ASSERT_EQ(same.code, 0) << same.err;
  EXPECT_EQ(same.err.find("warning"), std::string::npos) << same.err;
  std::filesystem::remove_all(out());

  const std::string other =
      eigenConfig(tmp_.path(), "other.yaml", "segmentation:\n  d_segment_m: 0.5\n");
  const Result refused = localize(other, map_);
  EXPECT_EQ(refused.code, 1) << refused.err;
  EXPECT_EQ(refused.err,
            "semsegmap localize: error: " + map_.string() +
                ": segmentation.d_segment_m: the map was built with 0.3, the configuration has "
                "0.5 (rebuild the map with this configuration, or give --allow-config-mismatch)\n");
  EXPECT_FALSE(std::filesystem::exists(out()));

  const Result allowed = localize(other, map_, " --allow-config-mismatch");
  EXPECT_EQ(allowed.code, 0) << allowed.err;
  EXPECT_NE(allowed.err.find("warning: localizing against a map built with other settings (1 "
                             "differ):\nwarning:   " +
                             map_.string() +
                             ": segmentation.d_segment_m: the map was built with 0.3, the "
                             "configuration has 0.5\n"),
            std::string::npos)
      << allowed.err;
  EXPECT_TRUE(std::filesystem::exists(out() / "summary.json"));
}

TEST_F(CliMaps, NanAndVersion1MapsAreRefusedInOneLine) {
  const std::string good = readFile(map_);
  auto refusedWith = [&](const std::string& bytes, const std::string& message) {
    const std::filesystem::path bad = tmp_.path() / "bad.map";
    std::ofstream(bad, std::ios::binary) << bytes;
    const Result r = localize(config_, bad);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_EQ(r.err.rfind("semsegmap localize: error: " + bad.string() + ": " + message, 0), 0u)
        << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_FALSE(std::filesystem::exists(out()));
  };
  std::string nan_map = good;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&nan_map[mapLayout(good).first_segment + 4], &nan, 4);  // y of segment 0
  resign(nan_map);
  refusedWith(nan_map, "segment 0: non-finite centroid");
  std::string v1 = good;
  v1[8] = 1;
  refusedWith(v1,
              "map format version 1 records no build settings, this build reads version 2: "
              "rebuild the map with `semsegmap map`");
}

// A dataset whose frame 1 has a picture of a plausible size that is no PNG: found only when that
// frame is read, after frame 0 has been processed (and its progress drawn).
std::filesystem::path datasetFailingAtFrame1(const std::filesystem::path& dir) {
  const auto data = copyOfDataset(dir);
  std::ofstream(data / "cam0" / "000001.png", std::ios::binary) << std::string(200, 'x');
  return data;
}

TEST_F(CliMaps, AFailedRunLeavesNoOutputsBehind) {
  const auto data = datasetFailingAtFrame1(tmp_.path() / "bad_data");
  const std::string bad = " --dataset " + data.string();
  const Result segment =
      run("segment" + bad + " --config " + config_ + " --out " + (tmp_.path() / "seg").string());
  EXPECT_EQ(segment.code, 1) << segment.err;
  EXPECT_NE(segment.err.find("cam0/000001.png"), std::string::npos) << segment.err;
  EXPECT_FALSE(std::filesystem::exists(tmp_.path() / "seg"));

  const Result map =
      run("map" + bad + " --config " + config_ + " --out " + (tmp_.path() / "x.map").string());
  EXPECT_EQ(map.code, 1) << map.err;
  EXPECT_FALSE(std::filesystem::exists(tmp_.path() / "x.map"));

  // A folder that was there keeps what it had, and nothing of the failed run.
  std::filesystem::create_directories(out() / "old");
  std::ofstream(out() / "keep.txt") << "mine";
  const Result loc = run("localize" + bad + " --config " + config_ + " --map " + map_.string() +
                         " --out " + out().string());
  EXPECT_EQ(loc.code, 1) << loc.err;
  std::vector<std::string> left;
  for (const auto& e : std::filesystem::recursive_directory_iterator(out()))
    left.push_back(e.path().lexically_relative(out()).string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"keep.txt", "old"}));
  EXPECT_EQ(readFile(out() / "keep.txt"), "mine");

  // The issue's case: localize wrote localizations.csv (and a summary), then failed on the
  // picture (here a folder in its place) with exit 1.
  std::filesystem::create_directories(out() / "localization.png");
  const Result picture = localize(config_, map_);
  EXPECT_EQ(picture.code, 1) << picture.err;
  EXPECT_NE(picture.err.find("localization.png"), std::string::npos) << picture.err;
  left.clear();
  for (const auto& e : std::filesystem::directory_iterator(out()))
    left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"keep.txt", "localization.png", "old"}));
}

TEST_F(CliMaps, AnErrorStartsOnItsOwnLineAfterAProgressBar) {
  const auto data = datasetFailingAtFrame1(tmp_.path() / "bad_data");
  const Result r = runOnTerminal("segment --dataset " + data.string() + " --config " + config_ +
                                 " --out " + (tmp_.path() / "seg").string());
  if (r.code == -1 && r.err.empty()) GTEST_SKIP() << "no pseudo-terminal here";
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.err.find("\rsegment ["), std::string::npos) << "no bar was drawn: " << r.err;
  const size_t error = r.err.find("semsegmap segment: error: ");
  ASSERT_NE(error, std::string::npos) << r.err;
  ASSERT_GT(error, 0u);
  EXPECT_EQ(r.err[error - 1], '\n') << "the error continues the bar's line: " << r.err;
  EXPECT_NE(r.err.find((data / "cam0" / "000001.png").string(), error), std::string::npos);
}

// eval revisits is in every build, the one without the simulator too: a user checks the system
// on their own recording. On the real KITTI scans, with the eigenvalue descriptor that every build
// has and the real-data settings: the table, revisits.json and the picture.
TEST(CliEvalRevisits, RunsOnTheRealKittiScansInEveryBuild) {
  const std::filesystem::path kitti =
      std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti_odometry_00_sparse";
  if (!std::filesystem::exists(kitti / "poses.txt"))
    GTEST_SKIP() << "no real KITTI sample (" << kitti.string() << ")";
  TempDir tmp;
  std::string settings = readFile("config/lidar-camera.yaml");  // ctest runs in the source tree
  settings = settings.substr(0, settings.find("descriptor:")) + "descriptor:\n  kind: eigen\n" +
             settings.substr(settings.find("localization:"));
  const std::filesystem::path config = tmp.path() / "eigen-kitti.yaml", out = tmp.path() / "rev";
  std::ofstream(config) << settings;
  const Result r = run("eval revisits --dataset semantickitti:" + kitti.string() +
                       " --map-frames 0:23 --query-frames 24:35 --configs " + config.string() +
                       " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("| config | method | localizations | < 0.5 m | < 1 m |"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("| eigen-kitti | segments (eigen) |"), std::string::npos) << r.out;
  // Scan Context beside it by default, with its folder.
  EXPECT_NE(r.out.find("| scan-context | Scan Context (whole scan) |"), std::string::npos) << r.out;
  EXPECT_TRUE(std::filesystem::exists(out / "scan-context" / "localizations.csv"));
  const std::string json = readFile(out / "revisits.json");
  EXPECT_NE(json.find("\"n_queries\": 12"), std::string::npos) << json.substr(0, 600);
  EXPECT_NE(json.find("\"n_revisits\": 3"), std::string::npos) << json.substr(0, 600);
  // The sequence's poses are its odometry too: said on stderr, marked in the table and files.
  EXPECT_NE(r.err.find("ground-truth poses serve as its odometry too"), std::string::npos) << r.err;
  EXPECT_NE(r.out.find("[odometry is the ground truth]"), std::string::npos) << r.out;
  EXPECT_NE(json.find("\"odometry_is_ground_truth\": true"), std::string::npos);
  EXPECT_NE(
      readFile(out / "eigen-kitti" / "summary.json").find("\"odometry_is_ground_truth\": true"),
      std::string::npos);
  EXPECT_GT(std::filesystem::file_size(out / "revisits.png"), 1000u);
  // --scan-context off leaves it out; it takes on or off alone.
  const std::filesystem::path off = tmp.path() / "off";
  const std::string few = "eval revisits --dataset semantickitti:" + kitti.string() +
                          " --map-frames 0:1 --query-frames 24:25 --configs " + config.string();
  const Result without = run(few + " --scan-context off --out " + off.string());
  ASSERT_EQ(without.code, 0) << without.err;
  EXPECT_EQ(without.out.find("scan-context"), std::string::npos) << without.out;
  EXPECT_FALSE(std::filesystem::exists(off / "scan-context"));
  const Result typo = run(few + " --scan-context no --out " + (tmp.path() / "typo").string());
  EXPECT_EQ(typo.code, 2) << typo.err;
  EXPECT_NE(typo.err.find("--scan-context"), std::string::npos) << typo.err;
}

// The README's and docs/class-maps.md's eval semantics, as typed: a label set made with a real
// network on the real mini KITTI frames, then measured against SemanticKITTI's labels.
TEST(CliEvalSemantics, LabelsThenEvalOnTheRealMiniKitti) {
  SEMSEGMAP_SKIP_WITHOUT_MINI_KITTI();
  if (!std::filesystem::exists(test_support::kEspNet))
    GTEST_SKIP() << "no ESPNetv2 network (" << test_support::kEspNet.string() << ")";
  TempDir tmp;
  const std::filesystem::path net = test_support::writeEspNetConfig(tmp.path(), "config");
  const std::string dataset =
      " --dataset semantickitti:" + test_support::miniKittiSequence(tmp.path(), "05").string();
  const std::filesystem::path labels = tmp.path() / "labels-05", out = tmp.path() / "semantics";
  Result r = run("label" + dataset + " --config " + net.string() + " --out " + labels.string());
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("eval semantics" + dataset + " --labels " + labels.string() +
          " --config config/lidar-camera.yaml --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("  after votes "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("map segments with a class: "), std::string::npos) << r.out;
  const std::string json = readFile(out / "semantics.json");
  EXPECT_NE(json.find("\"frames\": 10"), std::string::npos) << json.substr(0, 600);
  EXPECT_NE(json.find("\"after_votes\""), std::string::npos);
  // Without a label set or a network there is nothing to measure: one line naming the frame.
  r = run("eval semantics" + dataset + " --config config/lidar-camera.yaml --out " + out.string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("frame 0 has no label image in any camera"), std::string::npos) << r.err;
}

// ---------------------------------------------------------------------------------------------
// semsegmap info: what a dataset holds and what its reader picked, before a long run

// The lines of `info`'s output that start with `key: `, without the key.
std::string infoLine(const std::string& out, const std::string& key) {
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key + ": ", 0) == 0) return line.substr(key.size() + 2);
  return "(no " + key + " line)";
}

// A folder of two scans named by frame number with a KITTI pose file for odometry: the kind, the
// frames, the LiDAR's files and points, no camera, the pose file and the rule that matched it.
TEST(CliInfo, SaysWhatATinyFolderDatasetHoldsAndHowItsPosesWereMatched) {
  TempDir tmp;
  const std::filesystem::path scans = tmp.path() / "scans";
  std::filesystem::create_directories(scans);
  for (const char* name : {"000000.bin", "000001.bin"}) {
    std::ofstream bin(scans / name, std::ios::binary);
    const float points[8] = {5.0f, 1.0f, 0.5f, 0.0f, 6.0f, -1.0f, 0.2f, 0.0f};
    bin.write(reinterpret_cast<const char*>(points), sizeof(points));
  }
  std::ofstream(tmp.path() / "odom.txt") << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n";
  const std::filesystem::path json = tmp.path() / "info.json";
  const Result r = run("info --dataset folder:" + scans.string() + " --odometry " +
                       (tmp.path() / "odom.txt").string() + " --json " + json.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(infoLine(r.out, "dataset"),
            "folder:scans, read as folder, no rig file (a LiDAR alone)");
  EXPECT_EQ(infoLine(r.out, "frames"),
            "2 over 0.10 s (0.000 to 0.100, times made up from the rate)");
  EXPECT_EQ(infoLine(r.out, "lidar"), (scans / "*").string() +
                                          ".bin, no times (made up from the rate); 2 points in "
                                          "frame 0, 10.0 Hz");
  EXPECT_EQ(infoLine(r.out, "cameras"), "none (geometry only)");
  EXPECT_EQ(infoLine(r.out, "odometry"),
            (tmp.path() / "odom.txt").string() + " (KITTI poses matched by frame number)");
  EXPECT_EQ(infoLine(r.out, "ground truth"), "none");
  EXPECT_EQ(infoLine(r.out, "labels"), "none");
  const std::string written = readFile(json);
  EXPECT_NE(written.find("\"count\": 2,"), std::string::npos) << written;
  EXPECT_NE(written.find("\"points_in_frame_0\": 2,"), std::string::npos) << written;
  EXPECT_NE(written.find("\"is_ground_truth\": false"), std::string::npos) << written;
  // Without the pose file: no odometry, and the line says how to give it.
  const Result none = run("info --dataset folder:" + scans.string());
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(infoLine(none.out, "odometry"), "none (give --odometry FILE, or --odometry lidar)");
}

// A dataset directory with cameras and labels (the simulator's, written to disk): every camera
// with its files, lens and extrinsics; odometry and ground truth from frames.csv; the labels.
TEST(CliInfo, SaysWhatADatasetDirectoryWithCamerasHolds) {
  if (!built("simulate")) GTEST_SKIP() << "the data comes from the simulator";
  const std::filesystem::path data = simulatedDataset();
  const Result r = run("info --dataset " + data.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(infoLine(r.out, "dataset").find(", read as dataset directory"), std::string::npos)
      << r.out;
  EXPECT_EQ(infoLine(r.out, "frames").rfind("3 over 0.40 s", 0), 0u) << r.out;
  EXPECT_NE(infoLine(r.out, "lidar").find("lidar/NNNNNN.bin; "), std::string::npos) << r.out;
  EXPECT_EQ(infoLine(r.out, "camera front"),
            "cam1/NNNNNN.png; 640x480 pinhole fx 320.00 fy 320.00 cx 320.00 cy 240.00; "
            "T_camera_lidar xyz 0.000 -0.250 -0.350 m, rpy 90.00 -90.00 0.00 deg; T_lidar_camera "
            "xyz 0.350 0.000 -0.250 m, rpy -90.00 0.00 -90.00 deg")
      << r.out;
  EXPECT_EQ(infoLine(r.out, "odometry"), "frames.csv (odom_ columns)");
  EXPECT_EQ(infoLine(r.out, "ground truth"), "frames.csv (gt_ columns)");
  EXPECT_EQ(infoLine(r.out, "labels"),
            "images cam0_label/, cam1_label/, cam2_label/ (3 of 3 cameras in frame 0); per point "
            "lidar_gt/NNNNNN.bin");
}

// The real KITTI raw sample: its one camera with KITTI's calibration, no oxts (so no odometry
// unless asked for), and --odometry lidar named as the source.
TEST(CliInfo, SaysWhatTheRealKittiRawSampleHolds) {
  const std::filesystem::path sample = std::filesystem::path(SEMSEGMAP_SHARED_DATA) /
                                       "kitti_raw_2011_09_26_sample/2011_09_26/sample_sync";
  if (!std::filesystem::exists(sample))
    GTEST_SKIP() << "the real KITTI raw sample is absent (" << sample.string() << ")";
  const Result r = run("info --dataset kitti-raw:" + sample.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(infoLine(r.out, "dataset"), "kitti-raw:sample_sync, read as kitti-raw");
  EXPECT_EQ(infoLine(r.out, "frames").rfind("10 over ", 0), 0u) << r.out;
  const std::string lidar = infoLine(r.out, "lidar");
  EXPECT_EQ(lidar.rfind("velodyne_points/data/*.bin; ", 0), 0u) << lidar;
  EXPECT_GT(std::stoul(lidar.substr(lidar.find("; ") + 2)), 100000u) << "an HDL-64E scan";
  const std::string camera = infoLine(r.out, "camera image_02");
  EXPECT_EQ(camera.rfind("image_02/data/*.png, calibration ", 0), 0u) << r.out;
  EXPECT_NE(camera.find("; 1242x375 pinhole fx 721.54 fy 721.54 cx 609.56 cy 172.85; "),
            std::string::npos)
      << camera;
  EXPECT_EQ(infoLine(r.out, "odometry"), "none (give --odometry FILE, or --odometry lidar)");
  EXPECT_EQ(infoLine(r.out, "ground truth"), "none");
  const Result lidar_odometry =
      run("info --dataset kitti-raw:" + sample.string() + " --odometry lidar");
  ASSERT_EQ(lidar_odometry.code, 0) << lidar_odometry.err;
  EXPECT_EQ(infoLine(lidar_odometry.out, "odometry"), "LiDAR odometry on the scans");
}

// A spec info cannot read is refused as every command refuses it: one line naming it, exit 1,
// nothing printed on stdout; a mistyped option is a usage error with the nearest name.
TEST(CliInfo, RefusesABadSpecInOneLine) {
  TempDir tmp;
  std::ofstream(tmp.path() / "run.bag") << "never read";
  const std::string bag = (tmp.path() / "run.bag").string();
  Result r = run("info --dataset " + bag);
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "semsegmap info: error: " + bag +
                       ": a ROS 1 bag, not a dataset directory: write rosbag:" + bag + "\n");
  EXPECT_EQ(r.out, "");
  r = run("info --dataset folder:" + (tmp.path() / "none").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("none: no such folder"), std::string::npos) << r.err;
  r = run("info --datset " + bag);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("unknown option --datset (did you mean --dataset?)"), std::string::npos)
      << r.err;
}

// The commonest real rig as a user runs it: one front camera on a 360-degree HDL-64E (the real
// KITTI raw sample), labelled by a real network, mapped and localized with the real-data config
// and LiDAR odometry. Three quarters of each scan is unobserved and stays as geometry.
// A command line the documentation shows: where, the shell variables its block sets first
// (`S=sim:...`), and the line itself with its `\` continuations joined.
struct DocumentedCommand {
  std::string where;
  std::vector<std::pair<std::string, std::string>> variables;
  std::string line;
};

// `$NAME` replaced by the value an earlier assignment of the block gave it.
std::string expanded(std::string value,
                     const std::vector<std::pair<std::string, std::string>>& variables) {
  for (const auto& [name, v] : variables)
    for (size_t at; (at = value.find("$" + name)) != std::string::npos;)
      value.replace(at, name.size() + 1, v);
  return value;
}

std::vector<DocumentedCommand> documentedCommands() {
  std::vector<std::filesystem::path> files = {"README.md", "models/MODEL_CARD.md",
                                              "fuzz/README.md"};
  for (const auto& entry : std::filesystem::directory_iterator("docs"))
    if (entry.path().extension() == ".md") files.push_back(entry.path());
  const std::regex command("^build/semsegmap\\s+(.*)$"), assignment("([A-Z_]+)=(\\S*)");
  std::vector<DocumentedCommand> found;
  for (const auto& file : files) {
    for (const std::vector<std::string>& block : test_support::codeBlocks(file)) {
      std::vector<std::pair<std::string, std::string>> variables;
      for (const std::string& l : block) {
        std::smatch m;
        if (std::regex_match(l, m, command)) {
          // Without a trailing `# comment`, which would also swallow run()'s redirections.
          found.push_back({file.string(), variables,
                           std::regex_replace(m[1].str(), std::regex("\\s+#.*$"), "")});
          continue;
        }
        // `S=...` or `S=...; G=$S,...`: a line of assignments alone.
        if (!std::regex_match(l, std::regex("^([A-Z_]+=\\S*;?\\s*)+$"))) continue;
        for (std::sregex_iterator a(l.begin(), l.end(), assignment), end; a != end; ++a) {
          std::string value = (*a)[2].str();
          if (!value.empty() && value.back() == ';') value.pop_back();
          variables.emplace_back((*a)[1].str(), expanded(value, variables));
        }
      }
    }
  }
  return found;
}

// Every `build/semsegmap ...` line of the README, docs/, the model card and fuzz/README.md
// parses as its command would (`semsegmap --check-usage`): a renamed option or a placeholder
// read as a list of choices breaks this test, not a user's first try.
// All lines in one `--check-usage-lines` process: one by one, the program's start made this the
// slowest test of the suite (three minutes in CI).
TEST(Docs, EveryCommandLineTheDocumentationShowsParses) {
  const std::vector<DocumentedCommand> commands = documentedCommands();
  ASSERT_GE(commands.size(), 40u) << "the README and docs show that many";
  std::vector<std::string> lines;
  for (const DocumentedCommand& c : commands) lines.push_back(expanded(c.line, c.variables));
  const std::vector<Result> results = checkUsageLines(lines);
  size_t checked = 0;
  for (size_t i = 0; i < commands.size(); ++i) {
    const DocumentedCommand& c = commands[i];
    const Result& r = results[i];
    SCOPED_TRACE(c.where + ": build/semsegmap " + c.line);
    // This build may leave a command out (the SEMSEGMAP_WITH_* options): it says so. A build with
    // the simulator and libtorch may still lack the viewer (no Node.js), and nothing else.
    if (r.code == 1 && r.err.find("this build has no") != std::string::npos) {
      if (SEMSEGMAP_WITH_SIM && SEMSEGMAP_WITH_TORCH) {
        EXPECT_EQ(c.line.rfind("view ", 0), 0u);
      }
      continue;
    }
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("usage ok"), std::string::npos) << r.out;
    ++checked;
  }
  EXPECT_GE(checked, 10u);
}

// The batch form says which line is wrong and still checks the others.
TEST(Docs, CheckUsageLinesChecksEachLineOnItsOwn) {
  TempDir tmp;
  const std::filesystem::path lines = tmp.path() / "lines.txt";
  {
    std::ofstream out(lines);
    out << "map --dataset folder:nowhere --config c.yaml --out 'a b.map'\n\nmap --bogus "
           "1\nlocalize \"unclosed\n";
  }
  const Result r = run("--check-usage-lines '" + lines.string() + "'");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--- line 1 exit 0\nsemsegmap map: usage ok"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--- line 3 exit 2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--bogus"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--- line 4 exit 2\n--- stderr\nsemsegmap --check-usage-lines: line 4 is no "
                       "command line a shell splits"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(run("--check-usage-lines '" + (tmp.path() / "none.txt").string() + "'").code, 1);
}

TEST(Docs, CheckUsageRefusesWhatTheCommandWouldAndRunsNothing) {
  Result r = run("--check-usage map --dataset folder:nowhere --out x.map --bogus 1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--bogus"), std::string::npos) << r.err;
  TempDir tmp;
  const std::filesystem::path out = tmp.path() / "never.map";
  r = run("--check-usage map --dataset folder:nowhere --config nowhere.yaml --out " + out.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "nothing runs, nothing is written";
}

// A documented `build/semsegmap ...` line run as shown, from `dir` (this build's binary for
// `build/semsegmap`; `--version` first, since run() names the binary itself).
Result runDocumented(const std::filesystem::path& dir, const std::string& line) {
  return run("--version > /dev/null && cd '" + dir.string() + "' && '" +
             std::filesystem::absolute(g_binary).string() + "' " +
             line.substr(std::string("build/semsegmap ").size()));
}

// docs/real-data.md's PJLab example run as the page shows it, in a folder where `pjlab/` is the
// real sample and `examples/` the repository's: the overlay is written at the width asked.
TEST(Docs, ThePjlabEnrichExampleRunsAsShown) {
  const std::filesystem::path sample =
      std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "pjlab_lidar_camera_sample";
  if (!std::filesystem::exists(sample)) GTEST_SKIP() << "the real PJLab sample is absent";
  if (!SEMSEGMAP_WITH_PCL)
    GTEST_SKIP() << "PCD files are read with PCL, which this build leaves out";
  TempDir tmp;
  std::filesystem::create_directory_symlink(sample, tmp.path() / "pjlab");
  std::filesystem::create_directory_symlink(std::filesystem::absolute("examples"),
                                            tmp.path() / "examples");
  size_t ran = 0;
  for (std::string line : test_support::blockContaining("docs/real-data.md", "folder:pjlab")) {
    if (line.rfind("build/semsegmap ", 0) != 0) continue;
    const Result r = runDocumented(tmp.path(), line);
    ASSERT_EQ(r.code, 0) << line << "\n" << r.err;
    ++ran;
  }
  ASSERT_EQ(ran, 1u);
  const std::string png = readFile(tmp.path() / "pjlab_overlay.png");
  ASSERT_GT(png.size(), 24u) << "no overlay written";
  // The PNG header's width, big-endian at byte 16.
  const auto byte = [&](size_t i) { return static_cast<uint32_t>(static_cast<uint8_t>(png[i])); };
  EXPECT_EQ(byte(16) << 24 | byte(17) << 16 | byte(18) << 8 | byte(19), 720u);
}

// The README's PCD example as it reads, in a folder where `kitti00/` is the real first ten scans
// of KITTI 00 with their poses.txt and calib.txt, and `config/` a copy of the shipped configs: it
// prints what the README shows.
TEST(Docs, TheReadmeKittiPcdExampleRunsAsShown) {
  const std::filesystem::path sample =
      std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti00_first10_pcd";
  if (!std::filesystem::exists(sample)) GTEST_SKIP() << "the real KITTI 00 PCD scans are absent";
  if (!SEMSEGMAP_WITH_PCL)
    GTEST_SKIP() << "PCD files are read with PCL, which this build leaves out";
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "config/lidar-camera.yaml's descriptor needs libtorch";
  TempDir tmp;
  std::filesystem::create_directory_symlink(sample, tmp.path() / "kitti00");
  std::filesystem::copy("config", tmp.path() / "config");
  const std::vector<std::string> block =
      test_support::blockContaining("README.md", "folder:kitti00");
  ASSERT_EQ(block.size(), 2u) << "the command and the line it prints";
  const Result r = runDocumented(tmp.path(), block[0]);
  ASSERT_EQ(r.code, 0) << r.err;
  // What the README says it prints, up to the map's size in bytes (which holds the paths given).
  const std::string shown = block[1].substr(2, block[1].find(" segments, ") + 9 - 2);
  EXPECT_NE(r.out.find(shown), std::string::npos) << r.out << "\nthe README shows: " << shown;
}

TEST(CliRealRig, AFrontCameraOnA360DegreeLidarMapsAndLocalizesWithANetworksLabels) {
  const std::filesystem::path sample = std::filesystem::path(SEMSEGMAP_SHARED_DATA) /
                                       "kitti_raw_2011_09_26_sample/2011_09_26/sample_sync";
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "the real-data config's descriptor needs libtorch";
  if (!std::filesystem::exists(sample)) GTEST_SKIP() << "the real KITTI raw sample is absent";
  if (!std::filesystem::exists(test_support::kEspNet))
    GTEST_SKIP() << "no ESPNetv2 network (" << test_support::kEspNet.string() << ")";
  TempDir tmp;
  const std::filesystem::path net = test_support::writeEspNetConfig(tmp.path(), "config");
  const std::string scans = " --dataset kitti-raw:" + sample.string();
  const std::string dataset = scans + " --odometry lidar";
  const std::string labels = (tmp.path() / "labels").string(),
                    map = (tmp.path() / "k.map").string();
  Result r = run("label" + scans + " --config " + net.string() + " --out " + labels);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("map" + dataset + " --labels " + labels + " --config config/lidar-camera.yaml --out " +
          map);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;  // a quarter is enough coverage
  const size_t at = r.out.find("frames 10  segments ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_GE(std::stoul(r.out.substr(at + 20)), 25u) << r.out;  // not 3, as when dropped
  r = run("localize" + dataset + " --labels " + labels + " --config config/lidar-camera.yaml" +
          " --map " + map + " --out " + (tmp.path() / "loc").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("frames 10  localizations 10"), std::string::npos) << r.out;
  // Against the map without labels, the labels lose only what the config drops by class (the
  // cars): kept, the class boundaries give at least as many map segments.
  const auto map_segments = [&](const std::string& options) {
    const Result m = run("map" + dataset + options + " --out " + map);
    EXPECT_EQ(m.code, 0) << m.err;
    const size_t at = m.out.find(")  map ");
    return at == std::string::npos ? 0ul : std::stoul(m.out.substr(at + 7));
  };
  std::ifstream in("config/lidar-camera.yaml");
  std::string keep((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t setting = keep.find("remove_dynamic_classes: true");
  ASSERT_NE(setting, std::string::npos);
  keep.replace(setting, 28, "remove_dynamic_classes: false");
  std::ofstream((tmp.path() / "keep-dynamic.yaml").string()) << keep;  // finds its models by name
  const size_t without_labels = map_segments(" --config config/lidar-camera.yaml");
  EXPECT_GE(map_segments(" --labels " + labels + " --config " +
                         (tmp.path() / "keep-dynamic.yaml").string()),
            without_labels);
  EXPECT_GT(without_labels, 40u);
}

TEST(CliFollow, FollowIdleWithoutFollowOrNotPositiveIsAUsageError) {
  const std::string base =
      "localize --dataset folder:nowhere --config config/lidar-camera.yaml --map m.map --out o";
  Result r = run(base + " --follow-idle 2");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("give --follow too"), std::string::npos) << r.err;
  r = run(base + " --follow --follow-idle -1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--follow-idle: expected a positive number"), std::string::npos) << r.err;
  r =
      run("localize --dataset kitti-raw:nowhere --config config/lidar-camera.yaml --map m.map "
          "--out o --follow");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("give --dataset folder:DIR"), std::string::npos) << r.err;
}

// A robot without ROS: `localize --follow` on a folder a driver writes the real KITTI 00 scans
// into (renamed into place, named by their times, 0.3 s apart) localizes them as they come against
// a map of the same scans, prints each pose when found and, told to stop after 2 s without a new
// scan, writes the run's files. Whatever it drops when it falls behind (with 2 cores shared by
// other tests it may), every scan is either worked on or dropped and said; with nothing dropped
// it localizes as many frames as the offline run.
TEST(CliFollow, AFolderAsADriverWritesItIsLocalizedAsItGrows) {
  const std::filesystem::path sample =
      std::filesystem::path(SEMSEGMAP_SHARED_DATA) / "kitti00_first10_pcd";
  if (!std::filesystem::exists(sample))
    GTEST_SKIP() << "the real KITTI 00 PCD scans (../shared/data/kitti00_first10_pcd) are absent";
  if (!SEMSEGMAP_WITH_PCL)
    GTEST_SKIP() << "PCD files are read with PCL, which this build leaves out";
  if (!SEMSEGMAP_WITH_TORCH) GTEST_SKIP() << "config/lidar-camera.yaml's descriptor needs libtorch";
  TempDir tmp;
  const std::string config = " --config config/lidar-camera.yaml";
  const std::string map = (tmp.path() / "k.map").string();
  const std::string offline = " --dataset folder:" + sample.string() + " --odometry lidar";
  Result r = run("map" + offline + config + " --out " + map);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("localize" + offline + config + " --map " + map + " --out " +
          (tmp.path() / "offline").string());
  ASSERT_EQ(r.code, 0) << r.err;
  const size_t at = r.out.find("localizations ");
  ASSERT_NE(at, std::string::npos) << r.out;
  const unsigned long offline_localizations = std::stoul(r.out.substr(at + 14));
  ASSERT_GT(offline_localizations, 5u) << r.out;

  const std::filesystem::path live = tmp.path() / "live";
  std::filesystem::create_directories(live);
  std::thread driver([&] {
    for (int k = 0; k < 10; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      const std::string stamp = "1317000000." + std::to_string(k) + "00000";
      std::filesystem::copy_file(sample / ("00000" + std::to_string(k) + ".pcd"),
                                 live / (stamp + ".pcd.part"));
      std::filesystem::rename(live / (stamp + ".pcd.part"), live / (stamp + ".pcd"));
    }
  });
  r = run("localize --dataset folder:" + live.string() + " --follow --follow-idle 2" + config +
          " --map " + map + " --out " + (tmp.path() / "followed").string());
  driver.join();
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("poses from LiDAR odometry on its scans"), std::string::npos) << r.err;
  const std::smatch m = [&] {
    std::smatch found;
    std::regex_search(r.out, found,
                      std::regex("followed (\\d+) scans: (\\d+) worked on, (\\d+) dropped"));
    return found;
  }();
  ASSERT_EQ(m.size(), 4u) << r.out;
  EXPECT_EQ(std::stoul(m[1]), 10u) << r.out;
  EXPECT_EQ(std::stoul(m[2]) + std::stoul(m[3]), 10u) << r.out;
  size_t printed = 0;
  for (size_t p = r.out.find("pose t=1317000000."); p != std::string::npos;
       p = r.out.find("pose t=1317000000.", p + 1))
    ++printed;
  EXPECT_EQ(lines(readFile(tmp.path() / "followed" / "localizations.csv")), printed + 1);
  if (std::stoul(m[3]) == 0) {
    EXPECT_EQ(printed, offline_localizations) << r.out;
  }
}

}  // namespace
}  // namespace semsegmap

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  // The binary of this build, or another one given as the first argument.
  semsegmap::g_binary = argc >= 2 ? argv[1] : SEMSEGMAP_BINARY;
  return RUN_ALL_TESTS();
}
