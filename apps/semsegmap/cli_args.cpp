#include "cli_args.h"

#include <stdexcept>

namespace semsegmap::app {

CliArgs::CliArgs(const std::vector<std::string>& args, const std::set<std::string>& options,
                 const std::set<std::string>& flags) {
  for (size_t k = 0; k < args.size(); ++k) {
    const std::string& a = args[k];
    if (a.rfind("--", 0) != 0) throw std::invalid_argument("unexpected argument '" + a + "'");
    const std::string name = a.substr(2);
    if (flags.count(name)) {
      values_[name] = "1";
    } else if (options.count(name)) {
      if (k + 1 >= args.size()) throw std::invalid_argument("option --" + name + " needs a value");
      values_[name] = args[++k];
    } else {
      throw std::invalid_argument("unknown option --" + name);
    }
  }
}

bool CliArgs::has(const std::string& name) const {
  return values_.count(name) > 0;
}

std::string CliArgs::get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  return it == values_.end() ? fallback : it->second;
}

std::string CliArgs::require(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) throw std::invalid_argument("missing required option --" + name);
  return it->second;
}

long long CliArgs::getInt(const std::string& name, long long fallback) const {
  auto it = values_.find(name);
  if (it == values_.end()) return fallback;
  size_t used = 0;
  long long v = 0;
  try {
    v = std::stoll(it->second, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != it->second.size() || it->second.empty())
    throw std::invalid_argument("option --" + name + " expects an integer, got '" + it->second +
                                "'");
  return v;
}

}  // namespace semsegmap::app
