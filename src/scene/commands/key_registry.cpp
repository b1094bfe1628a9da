#include "scene/commands/key_registry.hpp"

#include <algorithm>
#include <cctype>
#include <iomanip>
#include <sstream>

#include "delayspec/errors.hpp"
#include "delayspec/lyapunov.hpp"  // kMaxTangentVectors
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

Config probe_config(const std::string& command, const std::string& model) {
  Config config;
  if (model != model_names().front()) config.set("model", model, "--help");
  for (const auto& [key, value] : command_spec(command).placeholders) config.set(key, value, "--help");
  return config;
}

// The probe of every (command, model).
using Probes = std::map<std::string, std::map<std::string, std::vector<Config::Read>>>;
const Probes& all_probes() {
  static const Probes probes = [] {
    Probes p;
    for (const auto& spec : command_table())
      for (const auto& model : model_names())
        p[spec.name][model] = probe_command(spec.name, probe_config(spec.name, model)).reads;
    return p;
  }();
  return probes;
}

std::string default_text(const std::string& command, const Config::Read& r) {
  if (command_spec(command).placeholders.count(r.key)) return "(required)";
  return r.fallback ? (r.fallback->empty() ? "\"\"" : *r.fallback) : "-";
}

}  // namespace

Probe probe_command(const std::string& command, Config config, OnBadInput on_bad_input) {
  config.collect_keys_only(true);
  std::ostringstream sink_out, sink_err;
  Invocation dry{.command = command,
                 .scene = std::nullopt,
                 .json = true,
                 .out_dir = std::nullopt,
                 .quiet = true,
                 .resume = false,
                 .out = sink_out,
                 .err = sink_err};
  try {
    command_spec(command).run(config, dry);
  } catch (const KeysCollected&) {
    // the keys it carries are config.used_keys()
  } catch (const BadInput&) {
    if (on_bad_input == OnBadInput::rethrow) throw;
  }
  // (a command that never checked its keys, as every command should: what it read)
  return {config.reads(), config.used_keys()};
}

const KeyIndex& key_index() {
  static const KeyIndex index = [] {
    KeyIndex i;
    i.models = model_names();
    for (const auto& [command, by_model] : all_probes())
      for (const auto& [model, reads] : by_model)
        for (const auto& read : reads) i.readers[read.key][command].insert(model);
    return i;
  }();
  return index;
}

namespace {

// The one-line meaning of each key, in two tables for length: the problem and the analyses of
// one orbit, then the grids, continuation and the commands that run others.
const std::map<std::string, std::string>& problem_and_analysis_meanings() {
  static const std::map<std::string, std::string> meanings = {
      // the problem (problem.cpp)
      {"model", "the system: impact, linear, mathieu, mackey-glass, milling, equations (the scene's [equations])"},
      {"N", "steps per delay (h = tau / N; the mean step on a grid aligned with time switches), integer >= 1"},
      {"orbit_period", "forcing periods per stroboscopic map (period-p orbits; forced models only)"},
      {"events", "impact events: on (located), linear (first-order estimate), off"},
      {"jacobian", "consistent (exact derivative of the discrete map) or frozen (the paper's)"},
      {"contact_substeps", "trapezoid sub-steps per piece of a step on the contact side, events on/linear"},
      {"grid", "aligned (a node on every time switch, each piece uniform) or uniform (switches inside steps)"},
      {"zeta", "damping ratio"},
      {"e", "impact model: gap to the soft wall (contact where x > e)"},
      {"a", "impact: forcing amplitude; linear: coefficient of x(t) in x' = a x + b x(t - tau)"},
      {"beta", "impact: wall stiffness; mackey-glass: production rate"},
      {"omega", "forcing frequency (T = 2 pi / omega)"},
      {"k", "delayed-feedback gain k (v(t - tau) - v(t))"},
      {"tau_over_T", "delay as a fraction of the forcing period T (or give `tau` in time units)"},
      {"tau", "delay in time units (impact: instead of tau_over_T)"},
      {"x0", "constant initial history: position"},
      {"v0", "constant initial history: velocity"},
      {"b", "coefficient of the delayed term x(t - tau)"},
      {"period", "period T of the stroboscopic map (a time; default tau)"},
      {"kappa", "damping of the delayed Mathieu equation"},
      {"delta", "Mathieu: constant stiffness delta"},
      {"eps", "Mathieu: amplitude of the periodic stiffness eps cos t"},
      {"gamma", "mackey-glass: decay rate"},
      {"n", "mackey-glass: exponent of the nonlinearity x_tau^n"},
      {"spindle_rpm", "milling: spindle speed Omega (rpm); equal pitch: tau = T = 60 / (teeth Omega)"},
      {"depth", "milling: axial depth of cut a_p (m), >= 0"},
      {"radial_immersion", "milling: radial immersion a/D, in (0, 1]"},
      {"teeth", "milling: number of teeth N_t, 1 to 30"},
      {"pitch_angles", "milling: degrees from each tooth to the next, teeth of them summing to 360 (variable pitch: "
                       "one delay per distinct spacing, at most 4)"},
      {"Kt", "milling: tangential cutting coefficient (N/m^2)"},
      {"Kn", "milling: normal cutting coefficient (N/m^2)"},
      {"omega_n", "milling: natural angular frequency (rad/s)"},
      {"mass", "milling: modal mass (kg)"},
      {"milling", "milling: down or up (which side of the cut the tooth enters)"},
      // orbit and eigensolver (orbit_settings.cpp, floquet_settings.cpp)
      {"orbit", "periodic orbit: auto (shooting, sparse LU where it fails), shooting, simulate, newton"},
      {"orbit_tolerance", "orbit settled (simulate) / Newton's relative residual |P(U) - U|, > 0"},
      {"orbit_max_periods", "simulate: most periods simulated before giving up (exit 3)"},
      {"orbit_max_iterations", "newton, auto, shooting: Newton steps allowed (per level), 1..10000"},
      {"orbit_guess_periods", "newton, auto, shooting: periods simulated from the initial history before the guess"},
      {"orbit_coarse_N", "auto, shooting: levels N, N/8, ... down to the last >= this, then this; one level below 2x it"},
      {"nev", "multipliers wanted, >= 1"},
      {"period_guess", "autonomous models: the orbit's period is an unknown, found by Newton from this guess (time units); continue: the branch of such orbits from the one found at continue_from"},
      // equilibrium (equilibrium_settings.cpp)
      {"nroots", "equilibrium: rightmost characteristic roots wanted, 1..1000"},
      {"equilibrium_guess", "equilibrium: where Newton starts, one number per state component (default: the initial history)"},
      {"equilibrium_tolerance", "equilibrium: Newton's relative step at which the state and each root count as converged, (0, 1e-3]"},
      {"orbit_series", "floquet: on: the orbit as a time series over one map (t and each state component at the "
                       "grid's K nodes) in the text and the JSON (orbit_series); off"},
      {"error_bars",
       "on: each multiplier's distance to the N -> infinity value, from solves at N/4 and N/2 (about 1.75x the "
       "time), and a verdict stable / unstable / undecided; off: the solve at N alone"},
      {"solver",
       "eigensolver: auto (dense n <= 100, spectra n < 3000, else block), spectra, arpack, block, dense, dense-eigen"},
      {"block_size", "solver = block: vectors per product (Krylov-Schur; 1 = one vector, DCGS2), 1..64"},
      {"ncv", "Krylov subspace dimension; 0 = max(2 nev + 1, nev + 10), at most n"},
      {"tol", "Krylov: converged when residual estimate <= tol max(|mu|, eps^(2/3))"},
      {"residual_bound",
       "Krylov: a returned pair needs a true residual |M v - mu v| / (|mu| |v|) <= max(residual_bound, 100 tol) (else retried, then exit 3)"},
      {"max_restarts", "Krylov: implicit restarts allowed (more: exit 3), 0..1000000"},
      {"seed", "seed of the random start vector (Krylov) or initial tangent block (Lyapunov)"},
      // lyapunov (lyapunov_settings.cpp), sweep
      {"exponents", "Lyapunov exponents wanted, 1.." + std::to_string(kMaxTangentVectors)},
      {"periods", "Lyapunov: periods averaged (a multiple of qr_every), >= 2"},
      {"transient", "Lyapunov: periods discarded first, >= 0"},
      {"qr_every", "Lyapunov: periods between QR factorisations"},
      {"batches", "Lyapunov: batches for the standard error, >= 2"},
      {"sweep_key", "the swept parameter (any numeric model key)"},
      {"sweep_from", "first value of the swept parameter"},
      {"sweep_to", "last value of the swept parameter (end points included)"},
      {"sweep_points", "values of the swept parameter, 1..1000000"},
      {"section_points", "Poincare-section points recorded per parameter after the transient"},
      {"threads", "worker threads for the points (0 = all cores)"},
      // converge, bench (level_runner.cpp, command_converge.cpp, command_bench.cpp)
      {"Ns", "the list of N (comma-separated, increasing); instead of N_min..N_max"},
      {"N_min", "smallest N (N doubles up to N_max)"},
      {"N_max", "largest N"},
      {"reference", "errors against: exact (Lambert W; Mathieu, milling: spectral), extrapolated, finest, auto"},
      {"extrapolation_order", "Richardson: leading error order p (impact with events off: 1)"},
      {"extrapolation_order_step", "Richardson: order step q of c1 h^p + c2 h^(p+q) + ..."},
      {"extrapolation_levels", "Richardson: most levels combined, >= 1"},
      {"converge_target",
       "converge: keep doubling N past Ns until every tracked multiplier's relative error estimate is <= this (none: off)"},
      {"converge_max_N", "converge_target: the largest N tried, 1..1e7"},
      {"converge_max_seconds", "converge_target: stop when the next level would end past this many seconds"},
      {"solvers", "bench: solvers compared (comma list; also sdm0, fdm1: classic discretisations)"},
      {"classic_max_N", "bench: the classic discretisations (sdm0, fdm1) run at the listed N up to this one"},
      {"dense_memory_limit_mb", "bench: dense rows needing more memory (3 n^2 doubles) are skipped"},
      {"repeats", "bench: solves timed per row (the fastest is reported, the slowest beside it), 1..1000"},
      // simulate (command_simulate.cpp)
      {"t_end", "end of the simulated time (default 10 periods)"},
      {"t_start", "start of the recorded window"},
      {"sample_every", "grid points between trajectory samples"},
      {"control_on_at", "impact: k = 0 before this time, the given k from it on (paper Fig. 6.3)"},
      {"events_before_control", "events mode before control_on_at (default: = events)"},
  };
  return meanings;
}

const std::map<std::string, std::string>& grid_and_continuation_meanings() {
  static const std::map<std::string, std::string> meanings = {
      // chart, basin (command_chart.cpp, command_basin.cpp, parameter_grid.cpp)
      {"chart_x", "chart: parameter on the x axis (a numeric model key)"},
      {"chart_y", "chart: parameter on the y axis"},
      {"chart_x_range", "chart: [min, max] of x"},
      {"chart_y_range", "chart: [min, max] of y"},
      {"chart_x_points", "chart: points along x, 2..100000"},
      {"chart_y_points", "chart: points along y, 2..100000"},
      {"basin_x", "basin: initial-history parameter on the x axis"},
      {"basin_y", "basin: initial-history parameter on the y axis"},
      {"basin_x_range", "basin: [min, max] of x"},
      {"basin_y_range", "basin: [min, max] of y"},
      {"basin_x_points", "basin: points along x"},
      {"basin_y_points", "basin: points along y"},
      {"basin_transient", "basin: maps discarded before classifying"},
      {"basin_max_period", "basin: longest period detected (0 in the result: none up to it)"},
      {"basin_tolerance", "basin: relative sup-norm tolerance of a repeat"},
      // continue (continue_settings.cpp, command_continue.cpp)
      {"continue_object", "continue: orbit (the periodic orbit) or equilibrium (an autonomous model's equilibria, folds and Hopf points)"},
      {"continue_key", "continue: the model parameter continued (any numeric model key)"},
      {"continue_from", "continue: start of the branch (the orbit there is found as `floquet` finds it)"},
      {"continue_to", "continue: end of the range (the branch may turn back at folds; it ends at either end)"},
      {"continue_step", "continue: first arclength step (parameter units); 0 = |to - from| / 50"},
      {"continue_step_min", "continue: smallest step; below it the branch ends (exit 3); 0 = 1e-6 |to - from|"},
      {"continue_step_max", "continue: largest step; 0 = |to - from| / 10"},
      {"continue_max_points", "continue: branch points at most, 2..1e7"},
      {"continue_tolerance",
       "continue: bifurcations located to this in the parameter; 0 = 1e-10 |to - from|, narrowed on towards 1e-13 "
       "|to - from| with continue_Ns where that works"},
      {"continue_Ns", "continue: N list (increasing) for error bars on the bifurcations (none: N only)"},
      {"continue_switch", "continue: true = also the period-2 branch from each period doubling (finest N), or the orbits from each Hopf point"},
      {"continue_solver",
       "continue: the corrector's linear solver: krylov (GMRES on the condensed system, matrix-free), lu (sparse LU), "
       "auto (krylov, lu where GMRES fails)"},
      {"boundary_object", "boundary: orbit (stability curves of the periodic orbit) or equilibrium (an autonomous model's Hopf curves, with l1 and their codim-2 points, or fold curves)"},
      {"boundary_x", "boundary: the model key stepped along the curve (e.g. spindle_rpm)"},
      {"boundary_y", "boundary: the model key solved for (e.g. depth)"},
      {"boundary_x_from", "boundary: where the curve starts (x)"},
      {"boundary_x_to", "boundary: where the curve ends (x), landed on exactly"},
      {"boundary_y_from", "boundary: start of the y range (the start is searched by continue in y over the range)"},
      {"boundary_y_to", "boundary: end of the y range (a curve that leaves it ends there)"},
      {"boundary_type", "boundary: neimark-sacker, period-doubling, fold, grazing (max H = 0), or any (the first found at x_from but grazing); with boundary_object = equilibrium: hopf (default) or fold"},
      {"boundary_starts", "boundary: first (the first bifurcation in y at x_from) or scan (the first in y at each of "
                          "boundary_scan_points values of x: every curve met, e.g. the lobes of a speed range)"},
      {"boundary_scan_points", "boundary: values of x searched for starts with boundary_starts = scan, 2..1e5"},
      {"boundary_step", "boundary: initial arclength step, in the plane scaled by the two ranges"},
      {"boundary_step_min", "boundary: smallest step (the curve ends below it)"},
      {"boundary_step_max", "boundary: largest step"},
      {"boundary_max_points", "boundary: curve points at most, 2..1e7"},
      {"boundary_chord_error", "boundary: how far the curve may stray from the chord between two points, in the "
                               "scaled plane (sets the steps, > 0)"},
      {"boundary_tolerance", "boundary: a point's accuracy, in the scaled plane"},
      {"boundary_Ns", "boundary: N list (increasing) for error bars on each point's y (none: N only)"},
      {"boundary_refine", "boundary: on (with three levels or more: where the levels of boundary_Ns do not show their "
                          "order at a point, the level 2 N is added there and the coarsest dropped, then if need be "
                          "4 N and the next) or off"},
      // plot, run
      {"plot_gnuplot", "plot: the gnuplot program"},
      {"plot_width", "plot: PNG width in pixels, 100..10000"},
      {"plot_height", "plot: PNG height in pixels, 100..10000"},
      {"plot_component", "continue, plot: the state component a branch's table and figures show, a state name or "
                         "1-based index (default the first; plot: the one continue was given)"},
      {"analyses", "run: the analyses (command names) to run, in order (default: the command reading every key)"},
      {"title", "run: a title for the manifest"},
  };
  return meanings;
}

}  // namespace

const std::map<std::string, std::string>& key_meanings() {
  static const std::map<std::string, std::string> meanings = [] {
    std::map<std::string, std::string> all = problem_and_analysis_meanings();
    all.insert(grid_and_continuation_meanings().begin(), grid_and_continuation_meanings().end());
    return all;
  }();
  return meanings;
}

std::string command_keys_help(const std::string& command) {
  command_spec(command);  // BadInput for an unknown command (the probes hold every command of the table)
  const auto probes = all_probes().find(command);
  const auto& by_model = probes->second;
  // Keys every model reads (in the default model's reading order), then each model's own keys.
  auto read_by_all = [&](const std::string& key) {
    return std::all_of(by_model.begin(), by_model.end(), [&](const auto& entry) {
      return std::any_of(entry.second.begin(), entry.second.end(), [&](const Config::Read& r) { return r.key == key; });
    });
  };
  auto line = [&](std::ostream& out, const std::string& key, const std::string& def) {
    const auto meaning = key_meanings().find(key);
    out << "  " << std::left << std::setw(26) << key + " = " + def << " "
        << (meaning == key_meanings().end() ? "" : meaning->second) << "\n";
  };
  std::ostringstream out;
  out << "\nKeys read by `" << command << "` (scene file or --set KEY=VALUE; KEY = default, - when it has none):\n";
  for (const auto& r : by_model.at(model_names().front())) {
    if (!read_by_all(r.key)) continue;
    // A default that differs by model: each value with its models.
    std::map<std::string, std::vector<std::string>> defaults;
    for (const auto& model : model_names())
      for (const auto& other : by_model.at(model))
        if (other.key == r.key && !(r.key == "model" && model != model_names().front()))  // given by the probe
          defaults[default_text(command, other)].push_back(model);
    std::vector<std::string> parts;
    for (const auto& [value, models] : defaults)
      parts.push_back(defaults.size() == 1 ? value : value + " (" + join(models, ", ") + ")");
    line(out, r.key, join(parts, "; "));
  }
  for (const auto& model : model_names()) {
    std::ostringstream own;
    for (const auto& r : by_model.at(model))
      if (!read_by_all(r.key)) line(own, r.key, default_text(command, r));
    if (!own.str().empty()) out << " with model = " << model << ":\n" << own.str();
  }
  return out.str();
}

}  // namespace delayspec::cli
