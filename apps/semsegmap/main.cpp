// semsegmap: the command line. Each subcommand lives in its own cmd_*.cpp with the table of its
// options; usage errors exit 2 with a hint to the command's help, runtime errors (files, data)
// print one line and exit 1. A command this build leaves out (the SEMSEGMAP_WITH_* options of
// CMakeLists.txt) is not listed, and asking for it prints one line that says why and exits 1.
#include <algorithm>
#include <exception>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include <wordexp.h>

#include "cli_args.h"
#include "eval_args.h"
#include "interrupt.h"
#include "progress.h"
#include "semsegmap/core/diagnostics.h"
#include "semsegmap/outputs/run_output.h"
#include "semsegmap/store/map_store_uri.h"
#if SEMSEGMAP_WITH_TORCH
#include "semsegmap/describe/learned_describer.h"
#endif

#ifndef SEMSEGMAP_VERSION
#error "SEMSEGMAP_VERSION comes from apps/semsegmap/CMakeLists.txt (the CMake project version)"
#endif

namespace semsegmap::app {
namespace {

const std::vector<const CommandSpec*>& commands() {
  static const std::vector<const CommandSpec*> all = [] {
    std::vector<const CommandSpec*> c;
#if SEMSEGMAP_WITH_SIM
    c = {&simulateCommand(), &simulateOverviewCommand()};
#endif
    c.insert(c.end(), {&infoCommand(), &enrichCommand(), &labelCommand(), &convertCommand(),
                       &segmentCommand(), &mapCommand(), &localizeCommand(), &slamCommand(),
                       &odometryCommand()});
#if SEMSEGMAP_WITH_TORCH
    c.push_back(&trainCommand());
    c.push_back(&trainSegmentationCommand());
#endif
#if SEMSEGMAP_WITH_VIEWER
    c.push_back(&viewCommand());
#endif
#if SEMSEGMAP_WITH_POSTGRES
    c.insert(c.end(), {&mapsListCommand(), &mapsShowCommand(), &mapsExportCommand(),
                       &mapsImportCommand(), &mapsDropCommand()});
#endif
#if SEMSEGMAP_WITH_SIM
    c.push_back(&demoCommand());
#endif
    return c;
  }();
  return all;
}

// The experiments: those on the simulator when the build has it, and `eval revisits`,
// `eval semantics` and `eval labels` always.
const std::vector<const CommandSpec*>& evalCommands() {
  static const std::vector<const CommandSpec*> all = [] {
    std::vector<const CommandSpec*> e;
#if SEMSEGMAP_WITH_SIM
    e = simulatedEvalCommands();
#endif
    // Before `eval paper`, which runs the others.
    const std::ptrdiff_t before_paper = e.empty() ? 0 : 1;
    e.insert(e.end() - before_paper,
             {&evalRevisitsCommand(), &evalSemanticsCommand(), &evalLabelsCommand()});
    return e;
  }();
  return all;
}

// A command this build leaves out: its name (one word, or two after `eval`), the option that
// would bring it, and why.
struct AbsentCommand {
  std::string name, option, why;
};

const std::vector<AbsentCommand>& absentCommands() {
  static const std::vector<AbsentCommand> absent = [] {
    std::vector<AbsentCommand> a;
    if (!SEMSEGMAP_WITH_SIM)
      for (const char* name :
           {"simulate", "simulate-overview", "eval segmentation", "eval descriptors",
            "eval localization", "eval fleet", "eval paper", "demo"})
        a.push_back({name, "SEMSEGMAP_WITH_SIM",
                     "this build has no simulator (built without Embree, reconfigure with "
                     "-DSEMSEGMAP_WITH_SIM=ON)"});
    if (!SEMSEGMAP_WITH_TORCH)
      a.push_back({"train", "SEMSEGMAP_WITH_TORCH",
                   "this build has no learned descriptors to train (built without libtorch, "
                   "reconfigure with -DSEMSEGMAP_WITH_TORCH=ON)"});
    if (!SEMSEGMAP_WITH_TORCH)
      a.push_back({"train-segmentation", "SEMSEGMAP_WITH_TORCH",
                   "this build has no segmentation network training (built without libtorch, "
                   "reconfigure with -DSEMSEGMAP_WITH_TORCH=ON)"});
    if (!SEMSEGMAP_WITH_POSTGRES)
      for (const char* name : {"maps list", "maps show", "maps export", "maps import", "maps drop"})
        a.push_back({name, "SEMSEGMAP_WITH_POSTGRES",
                     "this build has no PostgreSQL map store (built without libpq, reconfigure "
                     "with -DSEMSEGMAP_WITH_POSTGRES=ON)"});
    if (!SEMSEGMAP_WITH_VIEWER)
      a.push_back({"view", "SEMSEGMAP_WITH_VIEWER",
                   "this build has no viewer (built without Node.js and npm: run "
                   "scripts/setup.sh and reconfigure with -DSEMSEGMAP_WITH_VIEWER=ON)"});
    return a;
  }();
  return absent;
}

// "not in this build:" and a line per option: "  simulate, eval (SEMSEGMAP_WITH_SIM=OFF)"; or
// nothing.
std::string absentNote() {
  std::string note, option;
  for (const AbsentCommand& c : absentCommands()) {
    if (c.option != option && !option.empty()) note += " (" + option + "=OFF)\n";
    note += (c.option == option ? ", " : "  ") + c.name;
    option = c.option;
  }
  return note.empty() ? "" : "\nnot in this build:\n" + note + " (" + option + "=OFF)\n";
}

std::string overview() {
  std::vector<const CommandSpec*> listed = commands();
  // The experiments before the demo (at the end in a build without it).
  auto demo = listed.end();
#if SEMSEGMAP_WITH_SIM
  demo = std::find(listed.begin(), listed.end(), &demoCommand());
#endif
  listed.insert(demo, evalCommands().begin(), evalCommands().end());
  return "usage: semsegmap <command> [options]\n       semsegmap --version\n       semsegmap "
         "--check-usage <command> [options]   (parses, runs nothing)\n       semsegmap "
         "--check-usage-lines FILE   (the same for each line of FILE)\n\ncommands:\n" +
         commandOverview(listed) + absentNote() + "\n" + kDatasetNotes +
         "\nrun 'semsegmap <command> --help' for a command's options and their defaults.\n";
}

std::string evalOverview() {
  return "usage: semsegmap eval <experiment> [options]\n\nthe paper's experiments, SemSegMap "
         "against SegMap on the same frames\n\nexperiments:\n" +
         commandOverview(evalCommands()) +
         "\nrun 'semsegmap eval <experiment> --help' for an experiment's options.\n";
}

// "segmentation, descriptors, localization, revisits or paper": the experiments of this build.
std::string experimentList() {
  std::string list;
  const std::vector<const CommandSpec*>& e = evalCommands();
  for (size_t i = 0; i < e.size(); ++i)
    list += (i == 0 ? "" : i + 1 == e.size() ? " or " : ", ") + e[i]->name.substr(5);
  return list;
}

bool asksForHelp(const std::vector<std::string>& args) {
  for (const std::string& a : args)
    if (a == "--help" || a == "-h") return true;
  return false;
}

// The first words a command line may start with, for the hint after an unknown one: the
// commands, those this build leaves out (which then say why), and the options of `semsegmap`
// itself.
std::vector<std::string> firstWords() {
  std::vector<std::string> words = {"eval", "--help", "--version", "--check-usage"};
  for (const CommandSpec* c : commands())
    if (std::find(words.begin(), words.end(), c->name.substr(0, c->name.find(' '))) == words.end())
      words.push_back(c->name.substr(0, c->name.find(' ')));
  for (const AbsentCommand& c : absentCommands())
    if (c.name.find(' ') == std::string::npos) words.push_back(c.name);
  return words;
}

// An unknown experiment: the nearest one when it looks like a typo, else the list.
UsageError unknownExperiment(const std::string& typed) {
  std::vector<std::string> experiments;
  for (const CommandSpec* c : evalCommands()) experiments.push_back(c->name.substr(5));
  const std::string hint = didYouMean(typed, experiments);
  return UsageError("unknown experiment '" + typed + "'" +
                    (hint.empty() ? " (expected " + experimentList() + ")" : hint));
}

// The command `args` names (one word, or two after `eval`); `name` is set to what was found so
// far, for the error messages. Throws UsageError for an unknown one.
const CommandSpec* findCommand(const std::vector<std::string>& args, std::string* name) {
  const std::string two_words = args.size() > 1 ? args[0] + " " + args[1] : "";
  for (const CommandSpec* c : commands()) {
    if (c->name != args[0] && c->name != two_words) continue;
    *name = c->name;
    return c;
  }
  if (args[0] == "maps" && SEMSEGMAP_WITH_POSTGRES)
    throw UsageError("maps needs an action: list, show, export, import or drop");
  if (args[0] != "eval")
    throw UsageError("unknown command '" + args[0] + "'" + didYouMean(args[0], firstWords()));
  *name = "eval";
  if (args.size() < 2 || args[1].rfind("-", 0) == 0)
    throw UsageError("eval needs an experiment: " + experimentList());
  for (const CommandSpec* c : evalCommands()) {
    if (c->name != "eval " + args[1]) continue;
    *name = c->name;
    return c;
  }
  throw unknownExperiment(args[1]);
}

bool isOutput(const OptionSpec& o) {
  return o.name == "out" || o.name == "ply" || o.name == "history" || o.name == "json" ||
         (o.name == "cameras" && o.placeholder == "FILE.png");
}

// One line for an output that is there already: it is overwritten, the same rule for every
// command, since runs are repeated into one folder (`make demo`, an evaluation after a change).
std::string replacedNote(const std::string& option, const std::string& path, size_t entries,
                         bool folder) {
  if (!folder) return option + " " + path + " exists: this run replaces it";
  return option + " " + path + " already holds " + std::to_string(entries) +
         (entries == 1 ? " entry" : " entries") +
         ": this run's files replace those of the same name, the others stay";
}

// What a command writes: --out and the options naming another file it writes; a DIR placeholder
// says a folder. Checked before the command starts, removed again when it fails; what is there
// already is said, once every output passed its check.
void declareOutputs(const CliArgs& a, RunOutputs& outputs) {
  std::vector<std::string> replaced;
  for (const OptionSpec& o : a.command().options) {
    if (o.name == "cache" && a.has("cache")) outputs.keptFile(a.get("cache"), "--cache");
    if (!isOutput(o) || (!a.has(o.name) && o.fallback.empty())) continue;
    const std::string option = "--" + o.name, path = a.get(o.name);
    if (isMapStoreUri(path)) continue;  // a map in a store: written in one transaction
    const bool folder = o.placeholder == "DIR";
    const size_t before = folder ? outputs.folder(path, option) : outputs.file(path, option);
    if (before > 0) replaced.push_back(replacedNote(option, path, before, folder));
  }
  for (const std::string& line : replaced) note(line);
}

int usageError(const std::string& name, const std::string& message) {
  const std::string prefix = name.empty() ? "semsegmap" : "semsegmap " + name;
  std::cerr << prefix << ": usage error: " << message << "\nrun '" << prefix << " --help' for "
            << (name.empty() ? "the commands" : "its options") << "\n";
  return 2;
}

// `check_only`: the command line is parsed as the command would (its name, option names, value
// types and choices) and nothing runs: scripts and the documentation's test check command lines
// this way without their data.
int run(const std::vector<std::string>& args, bool check_only) {
  const std::string two_words = args.size() > 1 ? args[0] + " " + args[1] : args[0];
  for (const AbsentCommand& c : absentCommands()) {
    if (args[0] != c.name && two_words != c.name) continue;
    std::cerr << "semsegmap " << c.name << ": error: " << c.why << "\n";
    return 1;
  }
  if (args[0] == "eval" && args.size() > 1 && (args[1] == "--help" || args[1] == "-h")) {
    std::cout << evalOverview();
    return 0;
  }
  std::string name;
  try {
    const CommandSpec* command = findCommand(args, &name);
    const size_t words = command->name.find(' ') == std::string::npos ? 1 : 2;
    const std::vector<std::string> rest(args.begin() + words, args.end());
    if (asksForHelp(rest)) {
      std::cout << commandHelp(*command);
      return 0;
    }
    const CliArgs parsed(*command, rest);
    if (check_only) {
      std::cout << "semsegmap " << name << ": usage ok\n";
      return 0;
    }
    // Notes and warnings of the library on a line of their own, never after a progress bar.
    setMessageSink([](const std::string& line) {
      endProgressLine();
      std::fprintf(stderr, "%s\n", line.c_str());
      std::fflush(stderr);
    });
    RunOutputs outputs;  // a failed command leaves none of its outputs behind
    declareOutputs(parsed, outputs);
    if (command->stops_between_frames) installInterruptHandler();
    const int code = command->run(parsed);
    // An interrupted run wrote the frames it did as whole outputs: they stay.
    if (code == 0 || (code == kExitInterrupted && interruptedRunKeepsOutputs())) outputs.commit();
    return code;
  } catch (const UsageError& e) {
    endProgressLine();
    return usageError(name, e.what());
  } catch (const std::exception& e) {
    endProgressLine();  // the error on a line of its own, not glued to a progress bar
    std::cerr << "semsegmap " << name << ": error: " << e.what() << "\n";
    return 1;
  }
}

// --check-usage for every line of `path` in one process, each line split as a shell would
// (wordexp: quotes, $VARIABLES; no command substitution). Per line: "--- line N exit C", what it
// printed, "--- stderr", what it printed there. Tests check every command line of the docs so:
// the program's start (its libraries loaded) costs about a second each time.
int checkUsageLines(const std::string& path) {
  std::ifstream in(path);
  if (!in) {
    std::cerr << "semsegmap --check-usage-lines: " << path << ": cannot open\n";
    return 1;
  }
  std::string line;
  int worst = 0;
  for (size_t n = 1; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    std::ostringstream out, err;
    int code = 2;
    wordexp_t words;
    if (wordexp(line.c_str(), &words, WRDE_NOCMD) != 0) {
      err << "semsegmap --check-usage-lines: line " << n << " is no command line a shell splits\n";
    } else {
      const std::vector<std::string> args(words.we_wordv, words.we_wordv + words.we_wordc);
      wordfree(&words);
      std::streambuf* const saved_out = std::cout.rdbuf(out.rdbuf());
      std::streambuf* const saved_err = std::cerr.rdbuf(err.rdbuf());
      code = args.empty() ? 2 : run(args, true);
      std::cout.rdbuf(saved_out);
      std::cerr.rdbuf(saved_err);
    }
    std::cout << "--- line " << n << " exit " << code << "\n"
              << out.str() << "--- stderr\n"
              << err.str();
    worst = std::max(worst, code);
  }
  return worst;
}

}  // namespace
}  // namespace semsegmap::app

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
#if SEMSEGMAP_WITH_TORCH
  semsegmap::keepFreedMemoryForTorch();  // the program's choice, not the library's
#endif
  if (args.empty()) {
    std::cerr << semsegmap::app::overview();
    return 2;
  }
  if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    std::cout << semsegmap::app::overview();
    return 0;
  }
  if (args[0] == "--version" || args[0] == "version") {
    std::cout << "semsegmap " << SEMSEGMAP_VERSION << "\n";
    return 0;
  }
  if (args[0] == "--check-usage") {
    if (args.size() < 2) {
      std::cerr << "semsegmap --check-usage: usage error: a command line to check follows\n";
      return 2;
    }
    return semsegmap::app::run({args.begin() + 1, args.end()}, true);
  }
  if (args[0] == "--check-usage-lines") {
    if (args.size() != 2) {
      std::cerr << "semsegmap --check-usage-lines: usage error: one FILE of command lines\n";
      return 2;
    }
    return semsegmap::app::checkUsageLines(args[1]);
  }
  return semsegmap::app::run(args, false);
}
