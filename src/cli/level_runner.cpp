#include "level_runner.hpp"

#include <climits>
#include <sstream>

#include "delayspec/errors.hpp"
#include "delayspec/lambert_w.hpp"

namespace delayspec::cli {

std::vector<int> read_N_list(Config& config, const Problem& problem, int default_min, int default_max) {
  std::vector<int> Ns;
  const bool has_list = config.has("Ns");
  const bool has_range = config.has("N_min") || config.has("N_max");
  if (has_list && has_range) throw BadInput("`Ns` and `N_min`/`N_max` are both given: give one of them");
  std::string what = "`Ns`";
  if (has_list) {
    what = "`Ns = " + config.get_string("Ns", "") + "`";
    for (long N : config.get_int_list("Ns", {})) {
      if (N < 1 || N > INT_MAX) throw BadInput(what + ": `" + std::to_string(N) + "` is not an integer >= 1");
      Ns.push_back(static_cast<int>(N));
    }
  } else {
    const long lo = config.get_int_in_range("N_min", default_min, 1, INT_MAX);
    const long hi = config.get_int_in_range("N_max", default_max, lo, INT_MAX);  // lo = N_min
    for (long N = lo; N <= hi; N *= 2) Ns.push_back(static_cast<int>(N));
  }
  for (size_t i = 1; i < Ns.size(); ++i)
    if (Ns[i] <= Ns[i - 1])
      throw BadInput(what + ": must be strictly increasing (" + std::to_string(Ns[i - 1]) + " then " +
                     std::to_string(Ns[i]) + ")");
  for (int N : Ns) {  // fail fast on an N the grid cannot take
    Problem at_N = problem;
    at_N.N = N;
    at_N.grid();
  }
  return Ns;
}

std::vector<std::string> read_word_list(Config& config, const std::string& key, const std::string& fallback,
                                        const std::vector<std::string>& allowed) {
  const std::string text = config.get_string(key, fallback);
  std::vector<std::string> words;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const auto b = item.find_first_not_of(" \t"), e = item.find_last_not_of(" \t");
    item = b == std::string::npos ? "" : item.substr(b, e - b + 1);
    bool ok = false;
    for (const auto& a : allowed) ok = ok || a == item;
    if (!ok) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw BadInput("`" + key + " = " + text + "`: `" + item + "` is not one of " + list);
    }
    for (const auto& w : words)
      if (w == item) throw BadInput("`" + key + " = " + text + "`: `" + item + "` is listed twice");
    words.push_back(item);
  }
  if (words.empty()) throw BadInput("`" + key + " = " + text + "`: empty list");
  return words;
}

std::vector<std::complex<double>> exact_multipliers(const Problem& problem, int count) {
  if (const auto* linear = problem.model ? std::get_if<LinearModel>(&*problem.model) : nullptr) {
    const LinearParameters& p = linear->parameters();
    if (p.b == 0) return {};  // no delay term: Lambert W form does not apply
    return linear_dde_multipliers(p.a, p.b, p.tau, p.period, count);
  }
  return {};
}

}  // namespace delayspec::cli
