// A small argument parser for the subcommands: `--name value` options and `--flag` switches.
// Unknown options are an error, so a typo never silently falls back to a default.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

namespace semsegmap::app {

class CliArgs {
 public:
  // `options` take a value, `flags` do not. Throws std::invalid_argument on anything else.
  CliArgs(const std::vector<std::string>& args, const std::set<std::string>& options,
          const std::set<std::string>& flags);

  bool has(const std::string& name) const;
  std::string get(const std::string& name, const std::string& fallback) const;
  std::string require(const std::string& name) const;
  long long getInt(const std::string& name, long long fallback) const;

 private:
  std::map<std::string, std::string> values_;
};

// Subcommands: each takes its arguments (after the subcommand name) and returns the exit code.
int runSimulate(const std::vector<std::string>& args);
int runSimulateOverview(const std::vector<std::string>& args);
int runDemo(const std::vector<std::string>& args);
int runEnrich(const std::vector<std::string>& args);
int runConvert(const std::vector<std::string>& args);
int runSegment(const std::vector<std::string>& args);
int runMap(const std::vector<std::string>& args);
int runLocalize(const std::vector<std::string>& args);
int runSlam(const std::vector<std::string>& args);
int runTrain(const std::vector<std::string>& args);
int runEval(const std::vector<std::string>& args);

}  // namespace semsegmap::app
