// The command line's options, declared once per command: a table of OptionSpec that the parser
// (CliArgs) accepts and that `semsegmap CMD --help` prints, so the help cannot disagree with what
// is accepted. `--name value` and `--name=value` both work; unknown options, missing required
// ones, malformed numbers and values out of range are a UsageError (exit 2), anything that goes
// wrong afterwards (files, data) a runtime error (exit 1).
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace semsegmap::app {

// A mistake in the command line itself: main prints it with a hint to --help and exits 2.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

// What an option takes; the parser checks it before the command starts.
enum class Value {
  kFlag,      // no value: `--float32`
  kText,      // any non-empty text
  kCount,     // an integer >= 0
  kPositive,  // an integer >= 1
  kNumber,    // a number > 0
  kWeight,    // a number >= 0
};

constexpr bool kRequired = true;

struct OptionSpec {
  std::string name;  // without the leading "--"
  Value kind = Value::kText;
  std::string placeholder;  // shown in the help ("N", "DIR"); "a|b|c" accepts only a, b or c
  std::string fallback;     // the value when the option is not given, shown as its default
  std::string help;         // one line
  bool required = false;
};

class CliArgs;

struct CommandSpec {
  std::string name;     // as typed after `semsegmap`: "map", "eval localization"
  std::string summary;  // one line, for the overview and the command's help
  std::vector<OptionSpec> options;
  std::string notes;  // printed after the options; may be empty
  int (*run)(const CliArgs&) = nullptr;
  // Ctrl-C asks it to stop between frames (apps/semsegmap/interrupt.h): it writes the frames
  // done and exits 130. Any other command is ended at once by the signal's default action.
  bool stops_between_frames = false;
};

// `semsegmap CMD --help`: usage, summary, one line per option with its default, the notes.
std::string commandHelp(const CommandSpec& command);
// For `semsegmap --help`: per command its name, its options (required ones as `--out DIR`, the
// others in brackets) and its summary.
std::string commandOverview(const std::vector<const CommandSpec*>& commands);

// " (did you mean --odometry?)": the hint an error about an unknown `typed` name ends with when
// it is a typo of one of `known` (core/nearest_name.h), each shown with `prefix`; else empty.
std::string didYouMean(const std::string& typed, const std::vector<std::string>& known,
                       const std::string& prefix = "");

// Options shared by several commands.
OptionSpec maxFramesOption(const std::string& help = "stop after the first K frames, 0: all");
extern const char* const kDatasetNotes;  // the forms --dataset SPEC takes

class CliArgs {
 public:
  // Throws UsageError on anything `command` does not declare or accept.
  CliArgs(const CommandSpec& command, const std::vector<std::string>& args);

  // Reading an option the command does not declare is a programming error (std::logic_error),
  // as is reading the value of an option that was not given and has no default.
  bool has(const std::string& name) const;  // given on the command line
  std::string get(const std::string& name) const;
  long long getInt(const std::string& name) const;
  size_t getCount(const std::string& name) const;
  double getNumber(const std::string& name) const;
  // A file option: as typed when given (relative to the current directory), else its default
  // among the shipped configs and models (resources.h), wherever the command runs from.
  std::filesystem::path getPath(const std::string& name) const;
  size_t frameLimit() const;                  // --max-frames: 0 means all frames
  size_t frameLimit(size_t available) const;  // how many of `available` frames to process

  const CommandSpec& command() const { return *command_; }
  const std::vector<std::string>& args() const { return args_; }  // as typed

 private:
  const OptionSpec& spec(const std::string& name) const;
  const std::string& value(const std::string& name) const;
  void set(const OptionSpec& option, const std::string& text);

  const CommandSpec* command_;
  std::vector<std::string> args_;
  std::map<std::string, std::string> values_;
};

// The commands (each in its cmd_*.cpp).
const CommandSpec& simulateCommand();
const CommandSpec& simulateOverviewCommand();
const CommandSpec& demoCommand();
const CommandSpec& enrichCommand();
const CommandSpec& labelCommand();
const CommandSpec& convertCommand();
const CommandSpec& infoCommand();
const CommandSpec& segmentCommand();
const CommandSpec& mapCommand();
const CommandSpec& localizeCommand();
const CommandSpec& slamCommand();
const CommandSpec& odometryCommand();
const CommandSpec& trainCommand();
const CommandSpec& trainSegmentationCommand();  // a build with libtorch
// `maps list|show|export|import|drop`: a build with the PostgreSQL map store.
const CommandSpec& mapsListCommand();
const CommandSpec& mapsShowCommand();
const CommandSpec& mapsExportCommand();
const CommandSpec& mapsImportCommand();
const CommandSpec& mapsDropCommand();
const CommandSpec& viewCommand();  // a build with the viewer (SEMSEGMAP_WITH_VIEWER)

}  // namespace semsegmap::app
