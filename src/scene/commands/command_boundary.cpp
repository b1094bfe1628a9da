// delayspec boundary: a stability boundary as a curve in two model keys, each point with its
// distance to the N -> infinity curve (issue 36; docs/continuation.md, "Stability boundaries as
// curves"). The command reads the keys, calls the engine's boundary_diagram
// (delayspec/boundary_diagram.hpp: the starts' search, the tracing at the finest N, the points'
// studies against boundary_Ns and the refinement's levels) on the model's family, and writes.
//
// Files with --out DIR: boundary.csv (metadata header; one row per point: curve, x, y, angle,
// the extrapolations and their estimates, x and y at each N; nan where there is none) and
// boundary.json (the --json result).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

#include <nlohmann/json.hpp>

#include "delayspec/boundary_diagram.hpp"
#include "delayspec/error_expansion.hpp"
#include "scene/commands/boundary_equilibria.hpp"
#include "scene/commands/commands.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/output/progress.hpp"
#include "scene/problem/boundary_settings.hpp"
#include "scene/problem/floquet_settings.hpp"
#include "scene/problem/level_runner.hpp"
#include "scene/problem/orbit_settings.hpp"
#include "scene/problem/parameter_grid.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

using nlohmann::json;

struct BoundaryRun {
  std::string x_key, y_key;
  BoundaryOptions options;
  std::optional<BifurcationType> type;  // none: any (the first found at x_from)
  std::vector<int> Ns;                  // boundary_Ns, or the one level N
  std::vector<int> finer_Ns;            // boundary_refine: 2 and 4 Ns.back(), studied where Ns are pre-asymptotic
  int scan_points = 0;                  // boundary_starts = scan: the x values searched; 0: the first start only
  int threads = 1;                      // for the error bars (study_points)
  OrbitSettings orbit_settings;
  FloquetOptions floquet;
  Problem problem;  // at (x_from, y_from)
  int x_index = -1, y_index = -1;  // the keys' parameters in problem.family
};

BoundaryRun read_boundary_run(Config& config) {
  BoundaryRun run;
  const BoundarySettings settings = read_boundary_settings(config);
  run.x_key = settings.x_key;
  run.y_key = settings.y_key;
  run.options = settings.options;
  run.scan_points = settings.scan_points;
  const BoundaryOptions& o = run.options;
  const std::string type = config.get_choice("boundary_type", "any",
                                             {"any", "neimark-sacker", "period-doubling", "fold", "grazing"});
  for (BifurcationType t : {BifurcationType::neimark_sacker, BifurcationType::period_doubling, BifurcationType::fold,
                            BifurcationType::grazing})
    if (type == to_string(t)) run.type = t;
  run.Ns = read_levels(config, "boundary_Ns");
  const bool refine = config.get_switch("boundary_refine", true);
  run.threads = read_threads(config);
  run.orbit_settings = read_orbit_settings(config);
  run.floquet = read_floquet_options(config);
  run.problem = starting_problem(read_problem(config, 100), config,
                                 {{"boundary_x", run.x_key, o.x_from, "boundary_x_from"},
                                  {"boundary_y", run.y_key, o.y_from, "boundary_y_from"}});
  run.x_index = family_parameter(run.problem, "boundary_x", run.x_key);
  run.y_index = family_parameter(run.problem, "boundary_y", run.y_key);
  if (run.type == BifurcationType::grazing && !run.problem.analyses->switches_in_state())
    throw BadInput("`boundary_type = grazing`: model " + run.problem.model_name +
                   " has no switching surface H(y) = 0 for its orbit to graze");
  config.check_all_used();
  if (run.Ns.empty()) run.Ns = {run.problem.N};
  if (refine && run.Ns.size() >= 3)  // (with two, the refined levels are two)
    run.finer_Ns = {2 * run.Ns.back(), 4 * run.Ns.back()};
  return run;
}

// The levels every point reports, in the JSON's by_N and the CSV's columns: boundary_Ns, then the
// refinement's 2 N and 4 N (null / nan where a point did not need them), so that every point has them all.
std::vector<int> reported_levels(const BoundaryRun& run) {
  std::vector<int> levels = run.Ns;
  levels.insert(levels.end(), run.finer_Ns.begin(), run.finer_Ns.end());
  return levels;
}

// The point of level N's curve in a study: (x, y), NaN where it was not studied or not found.
std::pair<double, double> study_at_level(const BoundaryPointStudy& study, int N) {
  const auto at = std::find(study.levels.begin(), study.levels.end(), N);
  if (at == study.levels.end()) return {NAN, NAN};
  const size_t l = static_cast<size_t>(at - study.levels.begin());
  return {study.x_by_N[l], study.y_by_N[l]};
}

// The curves of the run, through the engine (boundary_diagram.hpp), with a progress line over
// the points' studies.
BoundaryDiagram compute_boundary(const BoundaryRun& run, const Invocation& inv) {
  BoundaryDiagramOptions o;
  o.x = run.x_index;
  o.y = run.y_index;
  o.values = run.problem.parameter_values;
  o.map = run.problem.map_settings();
  o.curve = run.options;
  o.type = run.type;
  o.Ns = run.Ns;
  o.finer_Ns = run.finer_Ns;
  o.scan_points = run.scan_points;
  o.threads = run.threads;
  o.orbit = run.orbit_settings;
  o.floquet = run.floquet;
  o.richardson = error_expansion(*run.problem.analyses, o.map.step);
  std::optional<Progress> progress;
  o.on_studies = [&](long points) { progress.emplace(inv.err, "boundary", points, inv.quiet); };
  o.on_point_studied = [&] { progress->add(); };
  BoundaryDiagram out = boundary_diagram(run.problem.family, o);
  if (progress) progress->finish();
  return out;
}

json boundary_json(const BoundaryRun& run, const BoundaryDiagram& out, double seconds) {
  json j;
  j["model"] = run.problem.model_name;
  j["boundary_x"] = run.x_key;
  j["boundary_y"] = run.y_key;
  j["N"] = run.Ns.back();
  j["Ns"] = run.Ns;
  j["x_range"] = {run.options.x_from, run.options.x_to};
  j["y_range"] = {run.options.y_from, run.options.y_to};
  j["curves"] = json::array();
  for (size_t i = 0; i < out.curves.size(); ++i) {
    const BoundaryCurve& curve = out.curves[i];
    const std::vector<BoundaryPointStudy>& studies = out.studies[i];
    json c;
    c["type"] = to_string(out.types[i]);
    c["end"] = to_string(curve.end);
    c["note"] = curve.note;
    c["points"] = json::array();
    for (size_t k = 0; k < curve.points.size(); ++k) {
      const BoundaryPoint& p = curve.points[k];
      const BoundaryPointStudy& st = studies[k];
      json by_N = json::array();
      for (int N : reported_levels(run)) {
        const auto [x, y] = study_at_level(st, N);
        by_N.push_back({{"N", N}, {"x", number_or_null(x)}, {"y", number_or_null(y)}});
      }
      c["points"].push_back({{"x", p.x},
                             {"y", p.y},
                             {"angle", number_or_null(p.angle)},
                             {"by_N", by_N},
                             {"extrapolated_from", st.extrapolated_from.empty() ? json(nullptr) : json(st.extrapolated_from)},
                             {"x_extrapolated", number_or_null(st.x_extrapolated)},
                             {"y_extrapolated", number_or_null(st.y_extrapolated)},
                             {"x_error_estimate", number_or_null(st.x_error_estimate)},
                             {"error_estimate", number_or_null(st.y_error_estimate)}});
    }
    c["codim2"] = json::array();
    for (const Codim2Point& q : curve.codim2)
      c["codim2"].push_back({{"kind", to_string(q)}, {"x", q.x}, {"y", q.y}, {"angle", q.angle}});
    j["curves"].push_back(c);
  }
  // Where the orbit is stable, when the search found it stable at y_from everywhere: below the
  // curves (the side of y_from). A grazing curve bounds the orbits in contact, not a stable region.
  const bool stability_curves = run.type != BifurcationType::grazing;
  j["stable_side"] = out.stable_below && stability_curves ? json("y_from") : json(nullptr);
  if (!out.failures.empty()) j["failure"] = out.failures;
  j["evaluations"] = out.evaluations;
  j["study_evaluations"] = out.study_evaluations;
  j["seconds"] = seconds;
  j["phase_seconds"] = {{"search", out.search_seconds}, {"trace", out.trace_seconds}, {"study", out.study_seconds}};
  return j;
}

// One row per point: its curve's index (from 1), then the point.
std::string boundary_csv(const std::string& header, const BoundaryRun& run, const BoundaryDiagram& out) {
  std::string text = header + "curve,x,y,angle,y_extrapolated,error_estimate,x_extrapolated,x_error_estimate";
  const std::vector<int> columns = reported_levels(run);
  for (int N : columns) text += ",x_N" + std::to_string(N) + ",y_N" + std::to_string(N);
  text += "\n";
  const auto cell = csv_number;  // (the shortest exact spelling, nan where there is none)
  for (size_t i = 0; i < out.curves.size(); ++i)
    for (size_t k = 0; k < out.curves[i].points.size(); ++k) {
      const BoundaryPoint& p = out.curves[i].points[k];
      const BoundaryPointStudy& study = out.studies[i][k];
      text += std::to_string(i + 1) + "," + cell(p.x) + "," + cell(p.y) + "," + cell(p.angle) + "," +
              cell(study.y_extrapolated) + "," + cell(study.y_error_estimate) + "," + cell(study.x_extrapolated) +
              "," + cell(study.x_error_estimate);
      for (int N : columns) {
        const auto [x, y] = study_at_level(study, N);
        text.append(",").append(cell(x)).append(",").append(cell(y));  // (append: GCC 12's false -Wrestrict)
      }
      text += "\n";
    }
  return text;
}

void print_boundary(std::ostream& os, const BoundaryRun& run, const BoundaryDiagram& out, double seconds) {
  char line[256];
  os << "delayspec boundary: model " << run.problem.model_label << ", " << out.curves.size() << " curve"
     << (out.curves.size() == 1 ? "" : "s") << " in (" << run.x_key << ", " << run.y_key << "), N = ";
  for (size_t i = 0; i < run.Ns.size(); ++i) os << (i ? "," : "") << run.Ns[i];
  os << "\n";
  for (size_t i = 0; i < out.curves.size(); ++i) {
    const BoundaryCurve& curve = out.curves[i];
    os << "curve " << i + 1 << ": " << to_string(out.types[i]) << ", " << curve.points.size() << " points, ended at `"
       << to_string(curve.end) << "`" << (curve.note.empty() ? "" : ": " + curve.note) << "\n";
    // The extrapolated point lies on the curve's normal through the point at the finest N, so
    // both of its coordinates move, on a lobe's steep side mostly x. On milling_lobes_curves.toml
    // (N = 100, 200, 400) by up to 3.4 rpm: the extrapolated depth read beside the finest N's
    // speed (the table before 2026-11-28) missed by 139 times its +- at the median point, and by
    // 1.3e-3 m on a flip lobe's side.
    std::snprintf(line, sizeof line, "  %-34s  %s\n", ("at N = " + std::to_string(run.Ns.back())).c_str(),
                  "extrapolated (N -> infinity)");
    os << line;
    std::snprintf(line, sizeof line, "  %16s  %16s  %18s  %8s  %18s  %8s  %8s\n", run.x_key.c_str(),
                  run.y_key.c_str(), run.x_key.c_str(), "+-", run.y_key.c_str(), "+-", "angle/pi");
    os << line;
    for (size_t k = 0; k < curve.points.size(); ++k) {
      const BoundaryPoint& p = curve.points[k];
      const BoundaryPointStudy& st = out.studies[i][k];
      std::snprintf(line, sizeof line, "  %16.10g  %16.10g  %18.12g  %8.2g  %18.12g  %8.2g  %8.4f\n", p.x, p.y,
                    st.x_extrapolated, st.x_error_estimate, st.y_extrapolated, st.y_error_estimate,
                    p.angle / std::numbers::pi);
      os << line;
    }
    // (located on the finest N's curve only: the coarser levels' curves are not followed, so
    // nothing says how far it is from N -> infinity)
    for (const Codim2Point& q : curve.codim2)
      os << "  codim 2: " << to_string(q) << " at " << run.x_key << " = " << format_number(q.x) << ", " << run.y_key
         << " = " << format_number(q.y) << " (at N = " << run.Ns.back() << ", no error estimate)\n";
  }
  os << "time: " << seconds << " s: the starts' search " << format_number(out.search_seconds, 2) << " s, tracing "
     << format_number(out.trace_seconds, 2) << " s (" << out.evaluations << " evaluations of the test function at N = "
     << run.Ns.back() << "), error bars " << format_number(out.study_seconds, 2) << " s (" << out.study_evaluations
     << " at the other N)\n";
}

}  // namespace

int command_boundary(Config& config, const Invocation& inv) {
  // boundary_object = equilibrium: Hopf curves of an equilibrium (boundary_equilibria.hpp)
  if (config.get_choice("boundary_object", "orbit", {"orbit", "equilibrium"}) == "equilibrium")
    return boundary_equilibria(config, inv);
  const auto start_time = std::chrono::steady_clock::now();
  const BoundaryRun run = read_boundary_run(config);
  if (const std::string note = autonomous_fixed_point_note(run.problem); !note.empty() && !inv.quiet)
    inv.err << "delayspec boundary: note: " << note << "\n";
  const BoundaryDiagram out = compute_boundary(run, inv);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time).count();
  const json j = boundary_json(run, out, seconds);
  if (inv.out_dir) {
    const std::filesystem::path dir(*inv.out_dir);
    OutputMetadata metadata = make_metadata("boundary", inv.scene, config, j, seconds);
    metadata.parameters.erase(run.x_key);
    metadata.parameters.erase(run.y_key);
    std::string header = metadata_comment_lines(metadata);
    if (!out.failures.empty()) header += "# INCOMPLETE: a curve ended in a failure: " + out.failures + "\n";
    write_output(inv, dir / "boundary.csv", boundary_csv(header, run, out));
    json file = j;
    file["metadata"] = metadata_json(metadata);
    write_output(inv, dir / "boundary.json", file.dump(2) + "\n");
  }
  if (!out.failures.empty()) {
    inv.err << "delayspec boundary: numerical failure: " << out.failures
            << (inv.out_dir ? "; the curves so far are in " + *inv.out_dir : std::string()) << "\n";
    return 3;
  }
  if (inv.json) {
    inv.out << j.dump(2) << "\n";
    return 0;
  }
  print_boundary(inv.out, run, out, seconds);
  return 0;
}

}  // namespace delayspec::cli
