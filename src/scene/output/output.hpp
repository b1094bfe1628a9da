#pragma once
// Shared output pieces of the commands: numbers, multipliers and Lyapunov exponents as JSON,
// multipliers as text.
#include <complex>
#include <ostream>
#include <vector>

#include <nlohmann/json.hpp>

#include "delayspec/equilibrium.hpp"
#include "delayspec/error_bars.hpp"
#include "delayspec/lyapunov.hpp"
#include "delayspec/model_analyses.hpp"
#include "delayspec/orbit_contacts.hpp"
#include "delayspec/periodic_orbit.hpp"

namespace delayspec::cli {

// A number, or null when it is not finite (JSON has no nan or inf).
nlohmann::json number_or_null(double x);
// A CSV cell: the shortest exact text of x (format_number), "nan" when x is not finite.
std::string csv_number(double x);

// The exponents and their errors, the fields `lyapunov --json` and each `sweep` point share:
// exponents_per_period, standard_error_per_period (= error_per_period, the historical key),
// exponents_per_time, standard_error_per_time,
// batch_standard_error_per_period, fluctuation_bound_per_period, period_time.
nlohmann::json lyapunov_json(const LyapunovResult& r);

// Characteristic roots, rightmost first: [{"re", "im", "error_bound", "residual", "discretised":
// {"re", "im"}, "moved", "iterations"}, ...] (docs/cli.md, equilibrium).
nlohmann::json characteristic_roots_json(const std::vector<CharacteristicRoot>& roots);

// [{"re": .., "im": .., "abs": ..}, ...]
nlohmann::json multipliers_json(const std::vector<std::complex<double>>& values);
// One line per multiplier: index, re, im, |mu|.
void print_multipliers(std::ostream& out, const std::vector<std::complex<double>>& values);

// Each multiplier's "resolved" (multiplier_resolved, convergence.hpp, from `accuracy`, one per
// multiplier); one that is not has "re", "im", "abs" null and its "bound" (|mu| <= bound): no
// value is printed that double precision does not vouch for.
void add_resolution_json(nlohmann::json& multipliers, const std::vector<std::complex<double>>& values,
                         const std::vector<double>& accuracy);
// print_multipliers with the unresolved ones as their bound.
void print_multipliers(std::ostream& out, const std::vector<std::complex<double>>& values,
                       const std::vector<double>& accuracy);

// Each multiplier's "error_estimate" (of the value at N; null: none possible) and, where the
// order is shown, "extrapolated": {"re", "im", "abs", "error_estimate"} (error_bars.hpp), added to
// the objects of multipliers_json.
void add_error_bars_json(nlohmann::json& multipliers, const ErrorBars& bars);
// {"Ns", "failures", "order", "deciding_N", "note", "seconds"}: how the bars were obtained.
nlohmann::json error_bars_json(const ErrorBars& bars, double seconds);
// The bars under print_multipliers' table, and the verdict in words (which N would decide it).
void print_error_bars(std::ostream& out, const std::vector<std::complex<double>>& values, const ErrorBars& bars);
// The periodic orbit the multipliers belong to: {"method", "residual", "periods", "contacts",
// "nodes_in_contact", "max_H", and for newton "newton_iterations", "newton_residuals",
// "newton_step_fractions", "jacobian_reciprocal_condition", "jacobian_nonzeros", "factor_nonzeros"}.
nlohmann::json orbit_json(const PeriodicOrbit& orbit, const ContactSummary& contacts);
// The grid's layout: {"layout": "aligned" | "uniform", and on a grid with breakpoints "pieces":
// [{"start", "steps"}, ...] of one pattern and "pattern" (grid.hpp)}. A uniform grid is "uniform"
// whatever was asked (a model without time switches, a fractional or several delays).
nlohmann::json grid_json(const HistoryGrid& grid);
// How the orbit's grid was aligned with its contacts: {"times": [[entry, exit], ...] (map time),
// "moves": each alternation's largest move of a contact time / T} or {"not_aligned": why}; null
// when not tried (contact_aligned_orbit.hpp).
nlohmann::json contact_alignment_json(const LinearisedOrbit& orbit);
// The same for people, one or two lines.
void print_orbit(std::ostream& out, const PeriodicOrbit& orbit, const ContactSummary& contacts);

}  // namespace delayspec::cli
