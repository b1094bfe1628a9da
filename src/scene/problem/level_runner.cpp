#include "scene/problem/level_runner.hpp"

#include "delayspec/error_expansion.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <sstream>

#include "delayspec/errors.hpp"
#include "delayspec/lambert_w.hpp"

namespace delayspec::cli {

namespace {

// Whether the problem's grid can be made at N (make_grid: a delay/period ratio may need multiples).
bool valid_grid(const Problem& problem, long N) {
  try {
    Problem at_N = problem;
    at_N.N = static_cast<int>(N);
    at_N.grid();
    return true;
  } catch (const BadInput&) {
    return false;
  }
}

}  // namespace

void use_first_level_as_N(Config& config) {
  if (!config.has("Ns")) return;
  const std::vector<long> Ns = config.get_int_list("Ns", {});
  if (!Ns.empty() && Ns.front() >= 1 && Ns.front() <= INT_MAX) config.set("N", std::to_string(Ns.front()), "Ns");
}

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
    long lo = config.get_int_in_range("N_min", default_min, 1, INT_MAX);
    long hi = config.get_int_in_range("N_max", default_max, lo, INT_MAX);  // lo = N_min
    if (!has_range) {
      // The defaults, on a grid that needs multiples (tau/T = 2 needs even N): the first valid N
      // from default_min on, doubled as often as the defaults are (26, 52, ... for 25, 50, ...).
      long first = lo;
      while (first < 2 * lo && !valid_grid(problem, first)) ++first;
      if (valid_grid(problem, first)) {
        hi = first * (hi / lo);
        lo = first;
      }
    }
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

ReferenceKind read_reference_kind(Config& config) {
  std::vector<std::pair<std::string, ReferenceKind>> kinds;
  for (ReferenceKind k : {ReferenceKind::exact, ReferenceKind::extrapolated, ReferenceKind::finest, ReferenceKind::automatic})
    kinds.emplace_back(to_string(k), k);
  return config.get_enum("reference", ReferenceKind::automatic, kinds);
}

std::vector<int> read_levels(Config& config, const std::string& key) {
  std::vector<int> Ns;
  if (!config.has(key)) return Ns;
  for (long N : config.get_int_list(key, {})) {
    if (N < 1 || N > 10'000'000)
      throw BadInput("`" + key + "`: N = " + std::to_string(N) + " must be between 1 and 1e7");
    if (!Ns.empty() && N <= Ns.back())
      throw BadInput("`" + key + "`: must be increasing (" + std::to_string(Ns.back()) + ", " + std::to_string(N) + ")");
    Ns.push_back(static_cast<int>(N));
  }
  return Ns;
}

std::vector<std::string> read_word_list(Config& config, const std::string& key, const std::string& fallback,
                                        const std::vector<std::string>& allowed) {
  const std::string text = config.get_string(key, fallback);
  std::vector<std::string> words;
  for (const std::string& item : split_items(text)) {
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

ExactReference exact_reference(const Problem& problem, int count) {
  ExactReference r;
  if (const auto* linear = problem.model ? std::get_if<LinearModel>(&*problem.model) : nullptr) {
    const LinearParameters& p = linear->parameters();
    if (p.b != 0) {  // (no delay term: the Lambert W form does not apply)
      r.multipliers = linear_dde_multipliers(p.a, p.b, p.tau, p.period, count);
      r.source = "lambert_w";
      return r;
    }
  }
  if (!problem.analyses->is_linear() || problem.analyses->delays().size() != 1 || problem.orbit_period != 1) return r;
  SpectralOptions o;
  o.degree = 32;
  o.degree_step = 8;
  o.pieces = 2;
  o.nev = count;
  SpectralResult spectral;
  try {
    spectral = problem.analyses->spectral_reference(o);
  } catch (const BadInput&) {  // tau != T: no spectral reference, nothing else wrong
    return r;
  } catch (const NumericalFailure&) {
    return r;
  }
  if (static_cast<int>(spectral.multipliers.size()) < count) return r;
  double precision = 0;
  for (size_t k = 0; k < spectral.multipliers.size(); ++k)
    precision = std::max(precision, spectral.error_estimate[k] / std::abs(spectral.multipliers[k]));
  if (!(precision <= 1e-10)) return r;
  r.multipliers = std::move(spectral.multipliers);
  r.precision = std::max(precision, 1e-14);
  r.source = "spectral";
  return r;
}

RichardsonOptions error_expansion(const Problem& problem) {
  return delayspec::error_expansion(*problem.analyses, step_options(problem));
}

ResolutionStudy resolution_study(const Problem& problem, const OrbitSettings& orbit, const FloquetOptions& solver,
                                 Progress* progress) {
  std::function<void()> on_level;
  if (progress) on_level = [progress] { progress->add(); };
  return ResolutionStudy(problem.analyses, problem.map_settings(), orbit, solver, std::move(on_level));
}

}  // namespace delayspec::cli
