#include "semsegmap/core/nearest_name.h"

#include <algorithm>
#include <cctype>
#include <vector>

namespace semsegmap {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

// The optimal string alignment distance: Levenshtein's, where swapping two neighbouring
// characters ("loaclize") counts as one edit, as a typist makes it.
size_t editDistance(const std::string& a, const std::string& b) {
  const size_t n = a.size(), m = b.size();
  std::vector<std::vector<size_t>> d(n + 1, std::vector<size_t>(m + 1, 0));
  for (size_t i = 0; i <= n; ++i) d[i][0] = i;
  for (size_t j = 0; j <= m; ++j) d[0][j] = j;
  for (size_t i = 1; i <= n; ++i) {
    for (size_t j = 1; j <= m; ++j) {
      const size_t substitution = d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1);
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, substitution});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  }
  return d[n][m];
}

std::string nearestName(const std::string& typed, const std::vector<std::string>& known) {
  const std::string t = lower(typed);
  if (t.empty()) return "";
  const size_t allowed = std::min(std::max<size_t>(2, t.size() / 3), t.size() - 1);
  std::string best;
  size_t best_distance = allowed + 1;
  for (const std::string& name : known) {
    const size_t d = editDistance(t, lower(name));
    if (d < best_distance) {
      best = name;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace semsegmap
