#pragma once
// Convergence studies (design.md 1.8): sweep the resolution N, compute the leading Floquet
// multipliers at each level, match them across levels, measure errors, correct digits and the
// observed order, and extrapolate (richardson.hpp).
//
// Model-agnostic: a study takes a LevelFunction, "the leading `count` multipliers at resolution
// N" (plus what they cost), so it can be driven by any model, solver, or a synthetic sequence.
//
// Matching. Multipliers are followed as tracks, anchored at the exact values (when given) or at
// the finest level's leading nev. Going from the finest level to the coarsest, level i is matched
// to the matched values of level i + 1 by a minimum-total-distance assignment (Hungarian
// algorithm on |mu_a - mu_b|), among nev + extra candidates. This is robust to two multipliers
// swapping rank in modulus between levels and to a complex pair that becomes two real
// multipliers (each gets one partner; no value is used twice), where matching by index is not.
//
// Errors are relative: e = |mu - mu_ref| / |mu_ref|. Correct digits (LRE) = -log10(e), capped at
// the precision of the reference (its own relative error estimate, at least 1e-16).
//
// Reference:
//   exact        the exact multipliers (e.g. Lambert W for the scalar linear DDE);
//   extrapolated Richardson on the matched levels (richardson.hpp), with its error estimate; a
//                column is used only if the column below shows its expected order (the error
//                expansion is checked, not assumed); an infinite estimate (no estimate possible)
//                gives the reference precision 1 (no digit certified);
//   finest       the finest level (its error estimated from the last two levels);
//   automatic    exact when given, else extrapolated (>= 2 levels).
//
// Observed order (of the leading track):
//   exact reference: per pair of levels p = log(e_i / e_{i+1}) / log(N_{i+1} / N_i), using only
//     levels whose error is above 10x the reference precision;
//   otherwise: from successive differences d_i = |mu_{i+1} - mu_i| (they do not depend on a
//     reference built from the same levels, which would make the order tautological):
//     p solves d_{i+1} / d_i = (h_{i+1}^p - h_{i+2}^p) / (h_i^p - h_{i+1}^p), h = 1 / N
//     (order_of_differences, richardson.hpp; log(d_i / d_{i+1}) / log(r) for equal ratios r).
//   The least-squares slope of log e (or log d) against log N over all usable levels.
//   Settled when the last (up to 3) pair orders spread by at most `settled_spread`; only then is
//   `observed` set (the slope over the levels of those pairs). Otherwise it stays empty and `note`
//   says that the sequence is pre-asymptotic, with the numbers.
//
// Accuracy of the inputs. Each level may give the absolute accuracy of each multiplier
// (LevelResult::accuracy, multiplier_accuracy below); the extrapolation's error estimate never
// goes below that accuracy amplified by the extrapolation weights (richardson.hpp), so a study
// at round-off still gets a finite, honest estimate.
//
// Failed levels. A level may fail (LevelResult::failure, or a NumericalFailure thrown by the
// level function, which is caught and recorded). After the first pass over Ns, each failed level
// is retried once through the RetryFunction (when given), nearest (in log N) to a level that
// succeeded first, with that level's N: the CLI starts Newton for the periodic orbit there from
// the neighbour's orbit. A level that still fails stays in the rows with its reason and is left
// out of the analysis; the study needs one successful level with an exact reference, else two
// (NumericalFailure naming every failure otherwise).
//
// Target (options.target > 0). After Ns, N keeps doubling until the relative error estimate of
// every tracked extrapolated multiplier, error_estimate_k / |mu_k|, is <= target, or the next N
// would exceed max_N, or the next level would not finish within max_seconds of the study's
// total (its cost predicted from the last level's, times the growth of the last doubling, at
// least 2), or a new level fails; `stopped_by` says which.
#include <complex>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "delayspec/multipliers.hpp"
#include "delayspec/richardson.hpp"

namespace delayspec {

// assignment[i] = index in `candidates` matched to targets[i], minimising sum_i |t_i - c_a(i)|.
// BadInput when there are fewer candidates than targets or a value is not finite.
std::vector<int> match_by_proximity(const Multipliers& targets, const Multipliers& candidates);

// What one level of a study computed.
struct LevelResult {
  Multipliers multipliers;         // the leading multipliers (any order; matching does not rely on it)
  double seconds = 0;              // what the level cost (wall time)
  long operator_applications = 0;  // single-vector applications of the monodromy
  std::vector<double> accuracy;    // absolute accuracy of each multiplier (empty: the Richardson default,
                                   // RichardsonOptions::input_precision |mu|)
  std::string failure;             // non-empty: the level failed, why (multipliers are then ignored)
  std::string note;                // how it was computed when that is worth saying (e.g. a retry)
};

// The leading `count` multipliers at resolution N.
using LevelFunction = std::function<LevelResult(int N, int count)>;
// A failed level once more, knowing that the level at from_N succeeded (see the header comment);
// nullopt: no other way to compute this level (its first failure stands).
using RetryFunction = std::function<std::optional<LevelResult>(int N, int count, int from_N)>;

// Absolute accuracy of a multiplier mu computed by an eigen-solver from a monodromy of dimension n
// that is a product of `steps` step maps, given its true relative residual |M v - mu v| / (|mu| |v|)
// (FloquetResult::residuals; NaN when the solver gives none, the dense path):
//   eigen-solver:  |mu_computed - mu(M_float)| <= kappa |r|, |r| = residual |mu|, kappa = 1 / |y^H x|
//     the eigenvalue's condition number (unit left / right vectors), first order. Not known at run
//     time; measured on the dense monodromies (linear a = -1 b = -2 and a = -1 b = 0.5, Mathieu
//     delta = 1 and 3; N = 50, 200; eight leading multipliers): kappa = 0.4 .. 3.0 sqrt(n),
//     growing like sqrt(n) (the history's Euclidean norm against a point evaluation). Taken as
//     kappa <= 10 sqrt(n). |r| is taken no smaller than eps |mu_1| (spectral_radius), the rounding
//     of computing M v itself (a multiplier at round-off, even one reported as 0, is known to that
//     much only). Dense (no residual): |r| <= n eps |mu_1|, the backward error of the QR algorithm
//     with the spectral radius for the norm.
//   the operator's own rounding: M_float is a product of `steps` step maps whose coefficients each
//     carry a relative rounding error; their product, and its eigenvalues, a relative
//     error up to steps * eps. Measured against the exact eigenvalues of the discrete linear DDE
//     (its characteristic polynomial in 50 digits, mpmath): 0.04 .. 0.19 steps * eps |mu|,
//     growing linearly with steps; the residual does not see it (|r| stayed at 2e-15 while the
//     error grew to 6e-14 at N = 800).
// accuracy = 10 sqrt(n) max(|r|, eps |mu_1|) + steps eps |mu|.
double multiplier_accuracy(std::complex<double> mu, double relative_residual, long n, long steps,
                           double spectral_radius);

// Whether a multiplier is resolved: its modulus above its accuracy (multiplier_accuracy). One
// that is not (at the floor eps |mu_1| next to a large mu_1: dense-eigen gave -93948 for a true
// modulus of 0.01 next to 6.7e21) has no digit that double precision vouches for: it is reported
// with its bound, never as a value, and is not part of a stability verdict (issue 32, item 2).
inline bool multiplier_resolved(std::complex<double> mu, double accuracy) { return std::abs(mu) > accuracy; }

enum class ReferenceKind { exact, extrapolated, finest, automatic };
// "exact", "extrapolated", "finest", "auto".
std::string to_string(ReferenceKind kind);

struct ConvergenceOptions {
  std::vector<int> Ns;  // strictly increasing, each >= 1
  int nev = 1;          // multipliers tracked
  int extra = 2;        // computed beyond nev at each level, as matching candidates
  ReferenceKind reference = ReferenceKind::automatic;
  Multipliers exact;               // exact multipliers (>= nev of them), for `exact` / `automatic`
  double exact_precision = 1e-14;  // relative accuracy of `exact`
  RichardsonOptions richardson;    // the error expansion (order 2, step 2: trapezoid, smooth)
  double settled_spread = 0.3;     // pair orders within this band count as settled
  // Target (header comment); 0: none, the study is Ns.
  double target = 0;         // relative error estimate wanted of every tracked multiplier
  int max_N = 51200;         // no level beyond this N
  double max_seconds = 600;  // total wall time of the levels
};

struct ConvergenceRow {
  int N = 0;
  std::string failure;                 // non-empty: the level failed (then the vectors below are empty
                                       // and error is NaN)
  std::string note;                    // LevelResult::note
  Multipliers multipliers;             // matched: multipliers[k] is track k
  std::vector<double> errors;          // relative error of each track
  std::vector<double> correct_digits;  // LRE of each track, capped
  double error = 0;                    // errors[0], the leading track
  double seconds = 0;
  long operator_applications = 0;
};

struct OrderReport {
  std::string basis;                // "error" (exact reference) or "difference"
  std::vector<double> pair_orders;  // basis error: rows (i, i+1); difference: rows (i, i+1, i+2)
  std::vector<int> pair_N;          // the finest N involved in each pair order
  double least_squares = 0;         // slope over all usable levels (NaN when < 2 points)
  std::optional<double> observed;   // set only when the orders are settled
  bool settled = false;
  std::string note;  // why `observed` is empty, or a caveat
};

struct ExtrapolatedMultiplier {
  std::complex<double> value;
  double error_estimate = 0;  // absolute (see richardson.hpp; infinity: no estimate possible)
  int levels = 0;             // Richardson levels combined (the column used, see richardson.hpp)
  std::string note;           // why that column
};

// Richardson columns of the leading track: columns[j][i] = T[i][j] (entries with fewer than j + 1
// levels below them are absent: the column starts at row j), with errors against the reference
// and the observed order of each column.
struct RichardsonReport {
  std::vector<int> Ns;
  std::vector<std::vector<std::complex<double>>> columns;
  std::vector<std::vector<double>> errors;           // relative, NaN where the reference is not independent
  std::vector<std::optional<double>> column_orders;  // least-squares order of each column's errors
  std::vector<double> expected_orders;               // e_{j+1} for column j
  // Reference-free, what the choice of column rests on (richardson.hpp): the order of each column
  // from its last three entries' differences, and whether the column is consistent with its
  // expected order (1), not (0), or too short to tell (-1).
  std::vector<double> difference_orders;
  std::vector<int> consistent;
  int levels_used = 0;  // the column the extrapolated value comes from (+1)
};

// What ended a study: its list of levels (no target), the target met, the largest N allowed, the
// time allowed, a level that failed.
enum class StudyStop { levels, target, max_N, max_seconds, failure };

struct ConvergenceStudy {
  std::vector<ConvergenceRow> rows;                    // every level, failed ones included, by N
  ReferenceKind reference = ReferenceKind::automatic;  // the one used (never automatic)
  Multipliers reference_values;                        // per track
  std::vector<double> reference_precision;             // relative, per track
  OrderReport order;                                   // of track 0
  std::vector<OrderReport> track_orders;               // of every track
  std::vector<ExtrapolatedMultiplier> extrapolated;    // per track (empty with one level)
  RichardsonReport richardson;                         // of track 0
  double seconds = 0;                                  // sum over the levels
  // The target (options.target > 0): met or not, and what ended the study (levels: the list of
  // Ns without a target). stop_note says it in words with the numbers.
  std::optional<bool> target_met;
  StudyStop stopped_by = StudyStop::levels;
  std::string stop_note;
};

// Runs the level function at every N of options.Ns (count = nev + extra), retries failed levels,
// continues towards options.target, and analyses the results. BadInput: empty or non-increasing
// Ns, nev < 1, reference exact without exact values, extrapolated/finest with one level, a bad
// target / max_N / max_seconds. NumericalFailure: a successful level returns fewer than nev
// values, or too few levels succeed (header comment).
ConvergenceStudy run_convergence_study(const LevelFunction& level, const ConvergenceOptions& options,
                                       const RetryFunction& retry = {});

// The analysis part alone, for levels computed elsewhere (levels[i] belongs to options.Ns[i]);
// failed levels are reported and left out. The target fields are left as "Ns".
ConvergenceStudy analyse_convergence(const std::vector<LevelResult>& levels, const ConvergenceOptions& options);

// Relative errors and capped LRE of `values` against `reference` (matched by proximity;
// values.size() >= reference.size()). matched[k] is the value matched to reference[k].
struct MatchedErrors {
  Multipliers matched;
  std::vector<double> errors;
  std::vector<double> correct_digits;
};
MatchedErrors errors_against(const Multipliers& values, const Multipliers& reference,
                             const std::vector<double>& reference_precision);

// -log10(error), capped at -log10(max(precision, 1e-16)); the cap when error == 0.
double correct_digits(double relative_error, double reference_precision);

}  // namespace delayspec
