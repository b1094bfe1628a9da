#pragma once
// `floquet` for a periodic orbit of unknown period (period_guess; autonomous_orbit.hpp), the
// scene's side: the key, the JSON and the text. The study itself (the orbit, its period, its
// trivial multiplier apart from the others, and with error bars the coarser levels and the
// period's extrapolation) is the engine's: delayspec/resolution_study.hpp.
#include <ostream>
#include <optional>

#include <nlohmann/json.hpp>

#include "delayspec/resolution_study.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

// {Ns, steps_per_period, periods, extrapolated, error_estimate, observed_order, note}
nlohmann::json period_study_json(const PeriodStudy& study);

// The key `period_guess` (absent: "none", the forced orbit as ever); BadInput when it is not a
// number, or given for a model that is not autonomous (its orbit has the forcing's period).
std::optional<double> read_period_guess(Config& config, const Problem& problem);

// The JSON fields `floquet --json` adds or replaces for such an orbit (docs/cli.md, floquet):
// period, period_guess, steps_per_period, trivial_multiplier, multipliers (the others), verdict,
// error_bars, period_error_bars, orbit.
void add_autonomous_floquet_json(nlohmann::json& j, const AutonomousFloquet& r, double period_guess);
// The text report's lines after the header.
void print_autonomous_floquet(std::ostream& out, const AutonomousFloquet& r, double period_guess);

}  // namespace delayspec::cli
