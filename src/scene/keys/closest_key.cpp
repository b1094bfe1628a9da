#include "scene/keys/closest_key.hpp"

#include <algorithm>
#include <cctype>

namespace delayspec::cli {

namespace {

// Levenshtein distance, case-insensitive: `n` for `N` costs 0, so a wrong case is always suggested.
size_t edit_distance(const std::string& a, const std::string& b) {
  auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t substitution = diagonal + (lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitution});
    }
  }
  return row[b.size()];
}

}  // namespace

std::string closest_key(const std::string& key, const std::vector<std::string>& candidates) {
  const size_t threshold = key.size() <= 2 ? 0 : key.size() <= 4 ? 1 : 2;
  std::string best;
  size_t best_distance = threshold + 1;
  for (const auto& candidate : candidates) {
    if (candidate == key) continue;
    // the distance is at least the difference in length: skip without the O(|key| |candidate|)
    // table (a 5 MB key is answered at once)
    const size_t length_gap =
        key.size() > candidate.size() ? key.size() - candidate.size() : candidate.size() - key.size();
    if (length_gap > threshold) continue;
    const size_t d = edit_distance(key, candidate);
    if (d < best_distance || (d == best_distance && !best.empty() && candidate < best)) {
      best = candidate;
      best_distance = d;
    }
  }
  return best;
}

}  // namespace delayspec::cli
