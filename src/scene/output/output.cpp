#include "scene/output/output.hpp"

#include <cmath>
#include <cstdio>

#include "delayspec/convergence.hpp"
#include "delayspec/errors.hpp"

namespace delayspec::cli {

nlohmann::json number_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }

std::string csv_number(double x) { return std::isfinite(x) ? format_number(x) : "nan"; }

nlohmann::json lyapunov_json(const LyapunovResult& r) {
  nlohmann::json j;
  j["exponents_per_period"] = r.per_period;
  j["standard_error_per_period"] = r.error_per_period;
  j["exponents_per_time"] = r.per_time;
  j["standard_error_per_time"] = r.error_per_time;
  j["batch_standard_error_per_period"] = r.batch_standard_error_per_period;
  j["fluctuation_bound_per_period"] = r.fluctuation_bound_per_period;
  j["period_time"] = r.map_time;
  return j;
}

nlohmann::json characteristic_roots_json(const std::vector<CharacteristicRoot>& roots) {
  const auto complex_json = [](std::complex<double> z) { return nlohmann::json{{"re", z.real()}, {"im", z.imag()}}; };
  nlohmann::json list = nlohmann::json::array();
  for (const CharacteristicRoot& c : roots) {
    nlohmann::json root = complex_json(c.value);
    root["error_bound"] = c.error_bound;
    root["residual"] = c.residual;
    root["discretised"] = complex_json(c.discretised);  // from the monodromy at N
    root["moved"] = std::abs(c.value - c.discretised);  // the discretisation's error at N
    root["iterations"] = c.iterations;
    list.push_back(root);
  }
  return list;
}

nlohmann::json multipliers_json(const std::vector<std::complex<double>>& values) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& mu : values) list.push_back({{"re", mu.real()}, {"im", mu.imag()}, {"abs", std::abs(mu)}});
  return list;
}

void print_multipliers(std::ostream& out, const std::vector<std::complex<double>>& values) {
  print_multipliers(out, values, {});
}

void add_resolution_json(nlohmann::json& multipliers, const std::vector<std::complex<double>>& values,
                         const std::vector<double>& accuracy) {
  for (size_t i = 0; i < values.size() && i < multipliers.size() && i < accuracy.size(); ++i) {
    const bool resolved = multiplier_resolved(values[i], accuracy[i]);
    multipliers[i]["resolved"] = resolved;
    if (resolved) continue;
    multipliers[i]["re"] = nullptr;
    multipliers[i]["im"] = nullptr;
    multipliers[i]["abs"] = nullptr;
    multipliers[i]["bound"] = accuracy[i];
  }
}

void print_multipliers(std::ostream& out, const std::vector<std::complex<double>>& values,
                       const std::vector<double>& accuracy) {
  char line[160];
  std::snprintf(line, sizeof line, "  %3s  %22s  %22s  %18s\n", "#", "re", "im", "|mu|");
  out << line;
  for (size_t i = 0; i < values.size(); ++i) {
    if (i < accuracy.size() && !multiplier_resolved(values[i], accuracy[i]))
      std::snprintf(line, sizeof line, "  %3zu  not resolved: |mu| <= %.3g (the accuracy next to mu_1)\n", i + 1,
                    accuracy[i]);
    else
      std::snprintf(line, sizeof line, "  %3zu  %22.15e  %22.15e  %18.15f\n", i + 1, values[i].real(),
                    values[i].imag(), std::abs(values[i]));
    out << line;
  }
}

void add_error_bars_json(nlohmann::json& multipliers, const ErrorBars& bars) {
  for (size_t i = 0; i < bars.bars.size() && i < multipliers.size(); ++i) {
    if (i < bars.resolved.size() && !bars.resolved[i]) continue;  // no value, so no bar (add_resolution_json)
    const MultiplierErrorBar& bar = bars.bars[i];
    multipliers[i]["error_estimate"] = number_or_null(bar.error_estimate);
    if (bar.extrapolated)
      multipliers[i]["extrapolated"] = {{"re", bar.extrapolated->real()},
                                        {"im", bar.extrapolated->imag()},
                                        {"abs", std::abs(*bar.extrapolated)},
                                        {"error_estimate", number_or_null(bar.extrapolated_error)}};
  }
}

nlohmann::json error_bars_json(const ErrorBars& bars, double seconds) {
  nlohmann::json j;
  j["Ns"] = bars.Ns;
  j["failures"] = bars.failures;
  j["order"] = bars.order ? number_or_null(*bars.order) : nlohmann::json(nullptr);
  j["deciding_N"] = bars.deciding_N > 0 ? nlohmann::json(bars.deciding_N) : nlohmann::json(nullptr);
  j["note"] = bars.note;
  j["seconds"] = seconds;
  return j;
}

void print_error_bars(std::ostream& out, const std::vector<std::complex<double>>& values, const ErrorBars& bars) {
  out << "error bars (distance to the N -> infinity value; levels N =";
  for (int N : bars.Ns) out << " " << N;
  out << "):\n";
  char line[200];
  for (size_t i = 0; i < bars.bars.size() && i < values.size(); ++i) {
    const MultiplierErrorBar& bar = bars.bars[i];
    if (i < bars.resolved.size() && !bars.resolved[i]) {
      std::snprintf(line, sizeof line, "  %3zu  not resolved\n", i + 1);
      out << line;
      continue;
    }
    if (std::isfinite(bar.error_estimate))
      std::snprintf(line, sizeof line, "  %3zu  |mu| = %.10g +- %.2g", i + 1, std::abs(values[i]), bar.error_estimate);
    else
      std::snprintf(line, sizeof line, "  %3zu  |mu| = %.10g, no error bar", i + 1, std::abs(values[i]));
    out << line;
    if (bar.extrapolated) {
      std::snprintf(line, sizeof line, "   extrapolated |mu| = %.12g +- %.2g", std::abs(*bar.extrapolated),
                    bar.extrapolated_error);
      out << line;
    }
    out << "\n";
  }
  out << "verdict: " << to_string(bars.verdict);
  if (bars.verdict == StabilityVerdict::undecided) {
    // Undecided comes from the leading multiplier (error_bars.cpp): its bar holds the unit circle,
    // or it has none (the levels did not show their order), and then that is what is said.
    const bool barred = !bars.bars.empty() && std::isfinite(bars.bars[0].error_estimate);
    out << (barred ? " (the unit circle is within an error bar" : " (the leading multiplier has no error bar");
    if (bars.deciding_N > 0)
      out << "; about N = " << bars.deciding_N << " would decide it if the error falls like N^-"
          << format_number(bars.expected_order);
    out << ")";
  }
  out << "\n";
  if (!bars.note.empty()) out << "error bars: " << bars.note << "\n";
}

nlohmann::json grid_json(const HistoryGrid& grid) {
  nlohmann::json j;
  j["layout"] = grid.has_breakpoints() ? "aligned" : "uniform";
  if (grid.has_breakpoints()) {
    j["pattern"] = grid.pattern;
    j["pieces"] = nlohmann::json::array();
    for (size_t i = 0; i < grid.breakpoints.size(); ++i)
      j["pieces"].push_back({{"start", grid.breakpoints[i]}, {"steps", grid.piece_steps[i]}});
  }
  return j;
}

nlohmann::json contact_alignment_json(const LinearisedOrbit& orbit) {
  nlohmann::json j;
  if (!orbit.contact_times.empty()) {
    j["times"] = nlohmann::json::array();
    for (const auto& [entry, exit] : orbit.contact_times) j["times"].push_back({entry, exit});
    j["moves"] = orbit.contact_moves;
  } else if (!orbit.alignment_note.empty()) {
    j["not_aligned"] = orbit.alignment_note;
  }
  return j;
}

nlohmann::json orbit_json(const PeriodicOrbit& orbit, const ContactSummary& contacts) {
  nlohmann::json j;
  j["method"] = to_string(orbit.method);
  j["residual"] = orbit.residual;
  j["periods"] = orbit.maps;
  j["contacts"] = contacts.contacts;
  j["nodes_in_contact"] = contacts.nodes_in_contact;
  j["max_H"] = contacts.max_H;  // NaN (models without switching) is written as null
  if (orbit.method == OrbitFoundBy::newton || orbit.method == OrbitFoundBy::shooting) {
    j["newton_iterations"] = orbit.newton_iterations;
    j["newton_residuals"] = orbit.newton_residuals;
    j["newton_step_fractions"] = orbit.newton_step_fractions;
  }
  if (orbit.method == OrbitFoundBy::newton) {
    j["jacobian_reciprocal_condition"] = orbit.jacobian_reciprocal_condition;
    j["jacobian_nonzeros"] = orbit.jacobian_nonzeros;
    j["factor_nonzeros"] = orbit.factor_nonzeros;
  }
  if (orbit.method == OrbitFoundBy::shooting) j["linear_iterations"] = orbit.linear_iterations;
  if (!orbit.levels.empty()) {
    nlohmann::json levels = nlohmann::json::array();
    for (const PeriodicOrbit::Level& l : orbit.levels)
      levels.push_back({{"N", l.N},
                        {"method", to_string(l.method)},
                        {"newton_iterations", l.newton_iterations},
                        {"linear_iterations", l.linear_iterations},
                        {"residual", l.residual},
                        {"seconds", l.seconds}});
    j["levels"] = levels;
  }
  return j;
}

void print_orbit(std::ostream& out, const PeriodicOrbit& orbit, const ContactSummary& contacts) {
  if (orbit.method == OrbitFoundBy::zero) {
    out << "periodic orbit: the zero orbit (linear model)\n";
    return;
  }
  out << "periodic orbit (" << to_string(orbit.method) << "): |P(U) - U| = " << orbit.residual;
  if (orbit.method == OrbitFoundBy::newton || orbit.method == OrbitFoundBy::shooting)
    out << " after " << orbit.newton_iterations << " Newton iterations";
  if (orbit.levels.size() > 1)
    out << " at N = " << orbit.levels.back().N << ", from the orbit at N = " << orbit.levels[orbit.levels.size() - 2].N;
  if (orbit.method == OrbitFoundBy::newton || orbit.method == OrbitFoundBy::shooting)
    out << " (first guess simulated for " << orbit.maps << " periods"
        << (orbit.levels.size() > 1 ? " at N = " + std::to_string(orbit.levels.front().N) : std::string()) << ")";
  else out << " after " << orbit.maps << " periods";
  out << "\n";
  if (orbit.method == OrbitFoundBy::newton || orbit.method == OrbitFoundBy::shooting) {
    out << "  Newton " << (orbit.method == OrbitFoundBy::newton ? "|F|_inf" : "|P(U) - U|_inf") << ":";
    for (double r : orbit.newton_residuals) out << " " << r;
    out << "\n";
  }
  if (orbit.levels.size() > 1) {
    out << "  levels (N: method, Newton steps, GMRES products, seconds):";
    for (const PeriodicOrbit::Level& l : orbit.levels)
      out << " " << l.N << ": " << to_string(l.method) << " " << l.newton_iterations << " " << l.linear_iterations << " "
          << l.seconds << ";";
    out << "\n";
  }
  if (!std::isnan(contacts.max_H))  // NaN: the model has no switching surface
    out << "  contacts per map: " << contacts.contacts << " (" << contacts.nodes_in_contact
        << " grid nodes in contact, max H = " << contacts.max_H << ")\n";
}

}  // namespace delayspec::cli
