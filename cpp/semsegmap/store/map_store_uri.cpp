#include "semsegmap/store/map_store_uri.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace semsegmap {

namespace {

// "user:secret@host" -> "user:***@host": a URI is printed in errors and logs.
std::string withoutPassword(const std::string& uri) {
  const size_t scheme = uri.find("://");
  if (scheme == std::string::npos) return uri;
  const size_t start = scheme + 3;
  const size_t at = uri.find('@', start), end = uri.find_first_of("/?", start);
  if (at == std::string::npos || (end != std::string::npos && at > end)) return uri;
  const size_t colon = uri.find(':', start);
  if (colon == std::string::npos || colon > at) return uri;
  return uri.substr(0, colon + 1) + "***" + uri.substr(at);
}

std::vector<std::string> split(const std::string& s, char by) {
  std::vector<std::string> parts;
  size_t from = 0;
  while (true) {
    const size_t to = s.find(by, from);
    parts.push_back(s.substr(from, to - from));
    if (to == std::string::npos) return parts;
    from = to + 1;
  }
}

double regionNumber(const std::string& shown, const std::string& text) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(v))
    throw std::invalid_argument(shown + ": region=X,Y,RADIUS: '" + text + "' is not a number");
  return v;
}

MapRegion parseRegion(const std::string& shown, const std::string& value) {
  const std::vector<std::string> v = split(value, ',');
  if (v.size() != 3)
    throw std::invalid_argument(shown + ": region=X,Y,RADIUS takes three numbers, got '" + value +
                                "'");
  MapRegion r{regionNumber(shown, v[0]), regionNumber(shown, v[1]), regionNumber(shown, v[2])};
  if (!(r.radius_m > 0))
    throw std::invalid_argument(shown + ": region radius must be > 0, got " + v[2]);
  return r;
}

}  // namespace

bool isMapStoreUri(std::string_view where) {
  return where.rfind("postgresql://", 0) == 0 || where.rfind("postgres://", 0) == 0;
}

bool isMapName(std::string_view name) {
  if (name.empty() || name.size() > 63) return false;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-')
      return false;
  return true;
}

MapStoreUri parseMapStoreUri(const std::string& uri, bool need_map) {
  MapStoreUri out;
  out.shown = withoutPassword(uri);
  if (!isMapStoreUri(uri)) throw std::invalid_argument(out.shown + ": not a postgresql:// URI");
  const size_t question = uri.find('?');
  out.conninfo = uri.substr(0, question);
  std::string kept;  // libpq's own parameters, passed on
  if (question != std::string::npos)
    for (const std::string& param : split(uri.substr(question + 1), '&')) {
      if (param.empty()) continue;
      const size_t eq = param.find('=');
      const std::string key = param.substr(0, eq);
      const std::string value = eq == std::string::npos ? "" : param.substr(eq + 1);
      if (key == "map")
        out.map = value;
      else if (key == "region")
        out.region = parseRegion(out.shown, value);
      else
        kept += (kept.empty() ? "?" : "&") + param;
    }
  out.conninfo += kept;
  if (!out.map.empty() && !isMapName(out.map))
    throw std::invalid_argument(out.shown + ": map name '" + out.map +
                                "' must be 1..63 letters, digits, '.', '_' or '-'");
  if (need_map && out.map.empty())
    throw std::invalid_argument(out.shown + ": which map? add ?map=NAME to the URI");
  return out;
}

}  // namespace semsegmap
