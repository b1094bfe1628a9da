#include "delayspec/error_bars.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "delayspec/errors.hpp"

namespace delayspec {

namespace {
constexpr double kInfinity = std::numeric_limits<double>::infinity();
}  // namespace

std::string to_string(StabilityVerdict verdict) {
  switch (verdict) {
    case StabilityVerdict::stable: return "stable";
    case StabilityVerdict::unstable: return "unstable";
    case StabilityVerdict::undecided: return "undecided";
  }
  return "undecided";
}

std::vector<int> coarser_levels(int N, const std::function<bool(int)>& valid, int min_N, LevelSpacing spacing) {
  std::vector<int> levels;
  // N/4 and N/2 (error_bars.hpp: why not coarser); quartering: N/16 and N/4, below N = 256 N/8
  const int coarsest = spacing == LevelSpacing::halving ? 4 : N / 16 >= 16 ? 16 : 8;
  for (int divisor : {coarsest, spacing == LevelSpacing::halving ? 2 : 4}) {
    int candidate = N / divisor;
    while (candidate >= min_N && !valid(candidate)) --candidate;
    if (candidate >= min_N && (levels.empty() || candidate > levels.back()) && candidate < N)
      levels.push_back(candidate);
  }
  return levels;
}

ErrorBars error_bars(const std::vector<int>& Ns, const std::vector<LevelResult>& levels,
                     const RichardsonOptions& richardson) {
  if (Ns.empty() || Ns.size() != levels.size())
    throw BadInput("error_bars: " + std::to_string(levels.size()) + " levels for " + std::to_string(Ns.size()) + " N");
  const LevelResult& finest = levels.back();
  if (!finest.failure.empty()) throw BadInput("error_bars: the level at N failed: " + finest.failure);
  const Multipliers& at_N = finest.multipliers;
  ErrorBars out;
  out.Ns = Ns;
  out.expected_order = richardson.order;
  for (const LevelResult& level : levels) out.failures.push_back(level.failure);
  out.bars.assign(at_N.size(), MultiplierErrorBar{kInfinity, std::nullopt, 0});
  out.resolved.assign(at_N.size(), true);
  for (size_t i = 0; i < at_N.size() && i < finest.accuracy.size(); ++i)
    out.resolved[i] = multiplier_resolved(at_N[i], finest.accuracy[i]);
  if (at_N.empty()) return out;

  size_t succeeded = 0;
  for (const LevelResult& level : levels) succeeded += level.failure.empty();
  if (succeeded < 2) {
    out.note = "no error bar: no coarser level succeeded";
    for (size_t i = 0; i + 1 < levels.size(); ++i) out.note += "; N = " + std::to_string(Ns[i]) + ": " + levels[i].failure;
    return out;
  }
  ConvergenceOptions options;
  options.Ns = Ns;
  options.nev = static_cast<int>(at_N.size());
  options.extra = 0;
  options.reference = ReferenceKind::extrapolated;
  options.richardson = richardson;
  ConvergenceStudy study;
  try {
    study = analyse_convergence(levels, options);
  } catch (const NumericalFailure& e) {  // e.g. a coarse level with fewer multipliers than N's
    out.note = std::string("no error bar: ") + e.what();
    return out;
  }
  const Multipliers& tracks_at_N = study.rows.back().multipliers;
  const std::vector<int> track_of = match_by_proximity(at_N, tracks_at_N);

  double worst_ratio = 0;  // undecided multipliers: (bar of mu_N / distance to the circle)^(1/p)
  bool decidable = true, any_undecided = false, any_unstable = false;
  for (size_t i = 0; i < at_N.size(); ++i) {
    if (!out.resolved[i]) continue;  // no digit to bar (multiplier_resolved): infinite, no verdict
    const int k = track_of[i];
    const ExtrapolatedMultiplier& x = study.extrapolated.at(k);
    MultiplierErrorBar& bar = out.bars[i];
    std::complex<double> best = at_N[i];
    double best_error = x.error_estimate;
    if (x.levels >= 2 && std::isfinite(x.error_estimate)) {
      bar.extrapolated = x.value;
      bar.extrapolated_error = x.error_estimate;
      bar.error_estimate = std::abs(at_N[i] - x.value) + x.error_estimate;
      best = x.value;
    } else {
      bar.error_estimate = x.error_estimate;  // column 0: the value at N (or infinity)
    }
    const double modulus = std::abs(best);
    // The leading multiplier at N (and its conjugate, or any of its modulus): the spectral radius,
    // whose limit bounds every other multiplier's (header comment).
    const bool leading = std::abs(at_N[i]) >= std::abs(at_N[0]) * (1 - 1e-12);
    if (modulus - best_error > 1) {
      any_unstable = true;
    } else if (leading && !(modulus + best_error < 1)) {
      any_undecided = true;
      const double gap = std::abs(modulus - 1);
      // The expected order: an observed one from three levels can be pre-asymptotic (0.4 on a
      // coarse impacting orbit) and would ask for an absurd N.
      const double p = richardson.order;
      if (!std::isfinite(bar.error_estimate) || !(gap > 0) || !(p > 0))
        decidable = false;
      else
        worst_ratio = std::max(worst_ratio, std::pow(bar.error_estimate / gap, 1 / p));
    }
  }
  out.order = study.order.observed;
  out.verdict = any_unstable    ? StabilityVerdict::unstable
                : any_undecided ? StabilityVerdict::undecided
                                : StabilityVerdict::stable;
  if (out.verdict == StabilityVerdict::undecided && decidable)
    out.deciding_N = static_cast<long>(std::ceil(Ns.back() * std::max(1.0, worst_ratio)));
  if (!out.bars.empty() && out.bars[0].extrapolated) {
    out.note = "extrapolated over N = ";
  } else {
    out.note = "no order shown over N = ";
  }
  for (size_t i = 0; i < Ns.size(); ++i) out.note += (i ? ", " : "") + std::to_string(Ns[i]);
  if (!study.extrapolated.empty() && !study.extrapolated[0].note.empty()) out.note += ": " + study.extrapolated[0].note;
  for (size_t i = 0; i < levels.size(); ++i)
    if (!levels[i].failure.empty()) out.note += "; N = " + std::to_string(Ns[i]) + " failed: " + levels[i].failure;
  return out;
}

}  // namespace delayspec
