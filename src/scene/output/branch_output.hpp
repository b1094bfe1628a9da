#pragma once
// The JSON and CSV of a branch of periodic orbits (continuation.hpp), shared by `continue`'s
// orbit branches and the branches born at Hopf points (continue_equilibria.cpp). An orbit of
// unknown period adds its period (JSON `period` and `trivial_multiplier` per point, a CSV
// column `period`); a forced orbit's output is as it was.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "delayspec/continuation.hpp"
#include "delayspec/error_bars.hpp"

namespace delayspec::cli {

nlohmann::json measures_json(const OrbitMeasures& m);
// verdicts (branch_verdicts.hpp), when given: one per point, the field `verdict`.
nlohmann::json points_json(const std::vector<ContinuationPoint>& points,
                           const std::vector<StabilityVerdict>& verdicts = {});
// The extrapolated bifurcations, each with the finest branch's multipliers, measures and note.
nlohmann::json bifurcations_json(const std::vector<BifurcationEstimate>& estimates, const ContinuationResult& branch);
// branch.csv after `header`: one row per point, with the first `nev` multipliers, and a last
// column `undecided` when verdicts are given (one per point): 1 where the point is undecided, 0
// where `stable` is the N -> infinity branch's too (numbers only: plot reads every column so).
std::string branch_csv(const std::string& header, const ContinuationResult& branch, int nev,
                       const std::vector<StabilityVerdict>& verdicts = {});
// bifurcations.csv after `header`: one row per bifurcation, |mu| the critical multiplier's.
std::string bifurcations_csv(const std::string& header, const std::vector<BifurcationEstimate>& estimates,
                             const ContinuationResult& branch);

}  // namespace delayspec::cli
