#include "cli_args.h"

#include "resources.h"
#include "semsegmap/core/nearest_name.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace semsegmap::app {

namespace {

bool parseInteger(const std::string& text, long long* out) {
  size_t used = 0;
  try {
    *out = std::stoll(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return !text.empty() && used == text.size();
}

bool parseNumber(const std::string& text, double* out) {
  size_t used = 0;
  try {
    *out = std::stod(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return !text.empty() && used == text.size() && std::isfinite(*out);
}

// The literal words an option accepts ("point|voxel", "S0|S1"), or none when any value goes:
// without a '|', or when one of the items is itself a placeholder, a word of capital letters
// alone ("FILE|lidar": a file, or the word lidar).
std::vector<std::string> choicesOf(const OptionSpec& option) {
  std::vector<std::string> out;
  if (option.placeholder.find('|') == std::string::npos) return out;
  std::stringstream s(option.placeholder);
  std::string item;
  while (std::getline(s, item, '|')) {
    if (!item.empty() &&
        std::all_of(item.begin(), item.end(), [](char c) { return c >= 'A' && c <= 'Z'; }))
      return {};
    out.push_back(item);
  }
  return out;
}

// Throws UsageError unless `text` is a value `option` accepts.
void checkValue(const OptionSpec& option, const std::string& text) {
  const std::string got = ", got '" + text + "'";
  const std::string what = "option --" + option.name;
  if (text.empty()) throw UsageError(what + " needs a value");
  const std::vector<std::string> choices = choicesOf(option);
  if (!choices.empty() && std::find(choices.begin(), choices.end(), text) == choices.end())
    throw UsageError(what + " expects " + option.placeholder + got + didYouMean(text, choices));
  long long n = 0;
  double x = 0.0;
  switch (option.kind) {
    case Value::kCount:
    case Value::kPositive:
      if (!parseInteger(text, &n)) throw UsageError(what + " expects an integer" + got);
      if (option.kind == Value::kCount && n < 0)
        throw UsageError(what + " must not be negative" + got);
      if (option.kind == Value::kPositive && n < 1)
        throw UsageError(what + " must be at least 1" + got);
      break;
    case Value::kNumber:
      if (!parseNumber(text, &x) || !(x > 0))
        throw UsageError(what + " expects a positive number" + got);
      break;
    case Value::kWeight:
      if (!parseNumber(text, &x) || !(x >= 0))
        throw UsageError(what + " expects a number >= 0" + got);
      break;
    case Value::kFlag:
    case Value::kText:
      break;
  }
}

const OptionSpec* findOption(const CommandSpec& command, const std::string& name) {
  for (const OptionSpec& o : command.options)
    if (o.name == name) return &o;
  return nullptr;
}

// Parts joined by spaces into lines of at most `width` characters, all but the first indented.
std::string wrap(const std::vector<std::string>& parts, size_t indent, size_t width) {
  std::string out, line;
  for (const std::string& part : parts) {
    if (!line.empty() && indent + line.size() + 1 + part.size() > width) {
      out += line + "\n" + std::string(indent, ' ');
      line.clear();
    }
    line += (line.empty() ? "" : " ") + part;
  }
  return out + line + "\n";
}

// "--name PLACEHOLDER", or "--name" for a flag.
std::string optionText(const OptionSpec& o) {
  return o.kind == Value::kFlag ? "--" + o.name : "--" + o.name + " " + o.placeholder;
}

std::string synopsisPart(const OptionSpec& o) {
  return o.required ? optionText(o) : "[" + optionText(o) + "]";
}

std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

// "  --name PLACEHOLDER  help (default: X)", the help wrapped at 100 columns under itself. A help
// that says its default itself, in words ("(default: shipped)"), is not given a second one.
std::string optionLine(const OptionSpec& o, size_t width) {
  const std::string left = optionText(o);
  std::string help = o.help;
  if (o.required) help += " (required)";
  if (!o.fallback.empty() && help.find("(default: ") == std::string::npos)
    help += " (default: " + o.fallback + ")";
  return "  " + left + std::string(width - left.size(), ' ') + wrap(words(help), 2 + width, 100);
}

// A table's defaults must be values it accepts: a wrong one is a bug, not a usage error.
void checkDefaults(const CommandSpec& command) {
  for (const OptionSpec& o : command.options) {
    if (o.fallback.empty()) continue;
    try {
      checkValue(o, o.fallback);
    } catch (const UsageError& e) {
      throw std::logic_error("semsegmap " + command.name + ": bad default: " + e.what());
    }
  }
}

}  // namespace

std::string didYouMean(const std::string& typed, const std::vector<std::string>& known,
                       const std::string& prefix) {
  const std::string nearest = nearestName(typed, known);
  return nearest.empty() ? "" : " (did you mean " + prefix + nearest + "?)";
}

OptionSpec maxFramesOption(const std::string& help) {
  return {"max-frames", Value::kCount, "K", "0", help};
}

const char* const kDatasetNotes =
#if SEMSEGMAP_WITH_SIM
    "datasets (SPEC): DIR (the project's format), kitti-raw:PATH, semantickitti:PATH, nclt:PATH,\n"
    "  folder:DIR[,rig=FILE][,times=FILE][,tolerance=S] (scans and pictures, docs/rig-format.md),\n"
    "  rosbag:FILE.bag|FILE.db3|FILE.mcap|DIR[,lidar=T][,camera=T;T|none][,odometry=T]\n"
    "    [,base_frame=F][,odom_frame=F][,tolerance=S] (ROS 1 and ROS 2 bags),\n"
    "  "
    "sim:world=N,run=S0..S3[,condition=sunrise][,traffic=M][,frames=K][,preset=small][,sweep=1]\n"
    "    [,label_noise=0..3][,lidar=paper|hdl64|vlp32|os128|solid][,cameras=0|front[+left...]]\n"
    "    [,classes=0][,laps=N] (the built-in simulator; cameras=0,classes=0: a LiDAR without a\n"
    "    camera; cameras=front: its front camera alone; laps: S2 or S3 driven N times)\n";
#else
    "datasets (SPEC): DIR (the project's format), kitti-raw:PATH, semantickitti:PATH, nclt:PATH,\n"
    "  folder:DIR[,rig=FILE][,times=FILE][,tolerance=S] (scans and pictures, docs/rig-format.md),\n"
    "  rosbag:FILE.bag|FILE.db3|FILE.mcap|DIR[,lidar=T][,camera=T;T|none][,odometry=T]\n"
    "    [,base_frame=F][,odom_frame=F][,tolerance=S] (ROS 1 and ROS 2 bags)\n"
    "  (not sim:, this build has no simulator: reconfigure with -DSEMSEGMAP_WITH_SIM=ON)\n";
#endif

std::string commandOverview(const std::vector<const CommandSpec*>& commands) {
  const size_t indent = 21, width = 100;
  std::string out;
  for (const CommandSpec* c : commands) {
    std::vector<std::string> parts;
    for (const OptionSpec& o : c->options) parts.push_back(synopsisPart(o));
    const std::string name = "  " + c->name;
    out += name + std::string(name.size() < indent ? indent - name.size() : 1, ' ');
    out += wrap(parts, indent, width) + std::string(indent, ' ') + c->summary + "\n";
  }
  return out;
}

std::string commandHelp(const CommandSpec& command) {
  std::string usage = "usage: semsegmap " + command.name;
  bool optional = false;
  size_t width = std::string("--help").size();
  for (const OptionSpec& o : command.options) {
    if (o.required) usage += " " + synopsisPart(o);
    optional |= !o.required;
    width = std::max(width, optionText(o).size());
  }
  width += 2;
  std::string out = usage + (optional ? " [options]" : "") + "\n\n" + command.summary + "\n\n";
  out += "options:\n";
  for (const OptionSpec& o : command.options) out += optionLine(o, width);
  out += optionLine({"help", Value::kFlag, "", "", "print this help and exit"}, width);
  if (!command.notes.empty()) out += "\n" + command.notes;
  return out;
}

CliArgs::CliArgs(const CommandSpec& command, const std::vector<std::string>& args)
    : command_(&command), args_(args) {
  checkDefaults(command);
  std::vector<std::string> names = {"help"};  // for the hint after an unknown option
  for (const OptionSpec& o : command.options) names.push_back(o.name);
  for (size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (a.rfind("--", 0) != 0 || a.size() == 2) {
      // "-odometry": an option with one dash.
      const std::string hint =
          a.size() > 1 && a[0] == '-' ? didYouMean(a.substr(1), names, "--") : "";
      throw UsageError("unexpected argument '" + a + "'" + hint);
    }
    const size_t eq = a.find('=');
    const std::string name = a.substr(2, eq == std::string::npos ? std::string::npos : eq - 2);
    const OptionSpec* option = findOption(command, name);
    if (!option) throw UsageError("unknown option --" + name + didYouMean(name, names, "--"));
    if (values_.count(name)) throw UsageError("option --" + name + " given twice");
    if (option->kind == Value::kFlag) {
      if (eq != std::string::npos) throw UsageError("option --" + name + " takes no value");
      values_[name] = "1";
    } else if (eq != std::string::npos) {
      set(*option, a.substr(eq + 1));
    } else {
      if (k + 1 >= args.size() || args[k + 1].rfind("--", 0) == 0)
        throw UsageError("option --" + name + " needs a value");
      set(*option, args[++k]);
    }
  }
  for (const OptionSpec& o : command.options)
    if (o.required && !values_.count(o.name))
      throw UsageError("missing required option --" + o.name);
}

void CliArgs::set(const OptionSpec& option, const std::string& text) {
  checkValue(option, text);
  values_[option.name] = text;
}

const OptionSpec& CliArgs::spec(const std::string& name) const {
  const OptionSpec* option = findOption(*command_, name);
  if (!option)
    throw std::logic_error("semsegmap " + command_->name + " does not declare --" + name);
  return *option;
}

const std::string& CliArgs::value(const std::string& name) const {
  const OptionSpec& option = spec(name);
  auto it = values_.find(name);
  if (it != values_.end()) return it->second;
  if (option.fallback.empty())
    throw std::logic_error("option --" + name + " was not given and has no default");
  return option.fallback;
}

bool CliArgs::has(const std::string& name) const {
  spec(name);
  return values_.count(name) > 0;
}

std::string CliArgs::get(const std::string& name) const {
  return value(name);
}

long long CliArgs::getInt(const std::string& name) const {
  long long n = 0;
  if (!parseInteger(value(name), &n))
    throw UsageError("option --" + name + " expects an integer, got '" + value(name) + "'");
  return n;
}

size_t CliArgs::getCount(const std::string& name) const {
  const long long n = getInt(name);
  if (n < 0)
    throw UsageError("option --" + name + " must not be negative, got '" + value(name) + "'");
  return static_cast<size_t>(n);
}

double CliArgs::getNumber(const std::string& name) const {
  double x = 0.0;
  if (!parseNumber(value(name), &x))
    throw UsageError("option --" + name + " expects a number, got '" + value(name) + "'");
  return x;
}

std::filesystem::path CliArgs::getPath(const std::string& name) const {
  if (has(name)) return value(name);
  return shippedFile(value(name));
}

size_t CliArgs::frameLimit() const {
  return getCount("max-frames");
}

size_t CliArgs::frameLimit(size_t available) const {
  const size_t limit = frameLimit();
  return limit > 0 ? std::min(limit, available) : available;
}

}  // namespace semsegmap::app
