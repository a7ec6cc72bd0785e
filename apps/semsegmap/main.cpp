// semsegmap: the command line. Each subcommand lives in its own cmd_*.cpp with the table of its
// options; usage errors exit 2 with a hint to the command's help, runtime errors (files, data)
// print one line and exit 1. A command this build leaves out (the SEMSEGMAP_WITH_* options of
// CMakeLists.txt) is not listed, and asking for it prints one line that says why and exits 1.
#include <algorithm>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "cli_args.h"
#include "progress.h"
#include "semsegmap/io/run_output.h"

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
    c.insert(c.end(), {&enrichCommand(), &labelCommand(), &convertCommand(), &segmentCommand(),
                       &mapCommand(), &localizeCommand(), &slamCommand(), &odometryCommand()});
#if SEMSEGMAP_WITH_TORCH
    c.push_back(&trainCommand());
#endif
#if SEMSEGMAP_WITH_VIEWER
    c.push_back(&viewCommand());
#endif
#if SEMSEGMAP_WITH_SIM
    c.push_back(&demoCommand());
#endif
    return c;
  }();
  return all;
}

// A command this build leaves out: its first word, the option that would bring it, and why.
struct AbsentCommand {
  std::string name, option, why;
};

const std::vector<AbsentCommand>& absentCommands() {
  static const std::vector<AbsentCommand> absent = [] {
    std::vector<AbsentCommand> a;
    if (!SEMSEGMAP_WITH_SIM)
      for (const char* name : {"simulate", "simulate-overview", "eval", "demo"})
        a.push_back({name, "SEMSEGMAP_WITH_SIM",
                     "this build has no simulator (built without Embree, reconfigure with "
                     "-DSEMSEGMAP_WITH_SIM=ON)"});
    if (!SEMSEGMAP_WITH_TORCH)
      a.push_back({"train", "SEMSEGMAP_WITH_TORCH",
                   "this build has no learned descriptors to train (built without libtorch, "
                   "reconfigure with -DSEMSEGMAP_WITH_TORCH=ON)"});
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
#if SEMSEGMAP_WITH_SIM
  // The experiments before the demo.
  listed.insert(std::find(listed.begin(), listed.end(), &demoCommand()), evalCommands().begin(),
                evalCommands().end());
#endif
  return "usage: semsegmap <command> [options]\n       semsegmap --version\n\ncommands:\n" +
         commandOverview(listed) + absentNote() + "\n" + kDatasetNotes +
         "\nrun 'semsegmap <command> --help' for a command's options and their defaults.\n";
}

#if SEMSEGMAP_WITH_SIM
std::string evalOverview() {
  return "usage: semsegmap eval <experiment> [options]\n\nthe paper's experiments, SemSegMap "
         "against SegMap on the same frames\n\nexperiments:\n" +
         commandOverview(evalCommands()) +
         "\nrun 'semsegmap eval <experiment> --help' for an experiment's options.\n";
}
#endif

bool asksForHelp(const std::vector<std::string>& args) {
  for (const std::string& a : args)
    if (a == "--help" || a == "-h") return true;
  return false;
}

// The command `args` names (one word, or two after `eval`); `name` is set to what was found so
// far, for the error messages. Throws UsageError for an unknown one.
const CommandSpec* findCommand(const std::vector<std::string>& args, std::string* name) {
  for (const CommandSpec* c : commands()) {
    if (c->name != args[0]) continue;
    *name = c->name;
    return c;
  }
  if (args[0] != "eval") throw UsageError("unknown command '" + args[0] + "'");
#if SEMSEGMAP_WITH_SIM
  *name = "eval";
  const std::string expected = "segmentation, descriptors, localization, revisits or paper";
  if (args.size() < 2 || args[1].rfind("-", 0) == 0)
    throw UsageError("eval needs an experiment: " + expected);
  for (const CommandSpec* c : evalCommands()) {
    if (c->name != "eval " + args[1]) continue;
    *name = c->name;
    return c;
  }
  throw UsageError("unknown experiment '" + args[1] + "' (expected " + expected + ")");
#else
  throw std::logic_error("eval is not in this build; run() answers it");
#endif
}

// What a command writes: --out and the options naming another file it writes; a DIR placeholder
// says a folder. Checked before the command starts, removed again when it fails.
void declareOutputs(const CliArgs& a, RunOutputs& outputs) {
  for (const OptionSpec& o : a.command().options) {
    const bool output = o.name == "out" || o.name == "ply" || o.name == "history" ||
                        (o.name == "cameras" && o.placeholder == "FILE.png");
    if (!output || (!a.has(o.name) && o.fallback.empty())) continue;
    if (o.placeholder == "DIR")
      outputs.folder(a.get(o.name), "--" + o.name);
    else
      outputs.file(a.get(o.name), "--" + o.name);
  }
}

int usageError(const std::string& name, const std::string& message) {
  const std::string prefix = name.empty() ? "semsegmap" : "semsegmap " + name;
  std::cerr << prefix << ": usage error: " << message << "\nrun '" << prefix << " --help' for "
            << (name.empty() ? "the commands" : "its options") << "\n";
  return 2;
}

int run(const std::vector<std::string>& args) {
  for (const AbsentCommand& c : absentCommands()) {
    if (args[0] != c.name) continue;
    std::cerr << "semsegmap " << c.name << ": error: " << c.why << "\n";
    return 1;
  }
#if SEMSEGMAP_WITH_SIM
  if (args[0] == "eval" && args.size() > 1 && (args[1] == "--help" || args[1] == "-h")) {
    std::cout << evalOverview();
    return 0;
  }
#endif
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
    RunOutputs outputs;  // a failed command leaves none of its outputs behind
    declareOutputs(parsed, outputs);
    const int code = command->run(parsed);
    if (code == 0) outputs.commit();
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

}  // namespace
}  // namespace semsegmap::app

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
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
  return semsegmap::app::run(args);
}
