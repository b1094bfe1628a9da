#include "scene/commands/boundary_equilibria.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <numbers>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "delayspec/equilibrium_boundary.hpp"
#include "delayspec/family_equilibria.hpp"
#include "delayspec/errors.hpp"
#include "scene/output/metadata.hpp"
#include "scene/output/output.hpp"
#include "scene/output/output_directory.hpp"
#include "scene/problem/boundary_settings.hpp"
#include "scene/problem/equilibrium_settings.hpp"
#include "scene/problem/problem.hpp"

namespace delayspec::cli {

namespace {

using nlohmann::json;

struct EquilibriaBoundaryRun {
  BoundarySettings settings;
  bool folds = false;  // boundary_type = fold (default hopf)
  EquilibriumSettings eq;
  Problem problem;  // at (x_from, y_from)
  int x_index = -1, y_index = -1;  // the keys' parameters in problem.family
};

EquilibriaBoundaryRun read_run(Config& config) {
  EquilibriaBoundaryRun run;
  run.settings = read_boundary_settings(config);
  run.folds = config.get_enum("boundary_type", false, {{"hopf", false}, {"fold", true}});
  const BoundaryOptions& o = run.settings.options;
  run.problem = read_problem(config, 100, ModelNeed::autonomous);
  run.eq = read_equilibrium_settings(config, run.problem);
  run.problem = starting_problem(run.problem, config,
                                 {{"boundary_x", run.settings.x_key, o.x_from, "boundary_x_from"},
                                  {"boundary_y", run.settings.y_key, o.y_from, "boundary_y_from"}});
  run.x_index = family_parameter(run.problem, "boundary_x", run.settings.x_key);
  run.y_index = family_parameter(run.problem, "boundary_y", run.settings.y_key);
  config.check_all_used();
  require_autonomous(run.problem);
  return run;
}

std::vector<double> state_values(const Eigen::VectorXd& y) { return {y.data(), y.data() + y.size()}; }

json point_json(const HopfCurvePoint& p) {
  json j;
  j["x"] = p.x;
  j["y"] = p.y;
  j["omega"] = p.root.value.imag();
  j["period"] = 2 * std::numbers::pi / p.root.value.imag();
  j["equilibrium"] = state_values(p.state);
  if (p.normal_form) {
    j["l1"] = std::isfinite(p.normal_form->l1) ? json(p.normal_form->l1) : json(nullptr);
    j["l1_bound"] = std::isfinite(p.normal_form->l1_bound) ? json(p.normal_form->l1_bound) : json(nullptr);
    j["criticality"] = to_string(p.normal_form->criticality);
  }
  return j;
}

// What every result of this command starts with: the model, the keys and the ranges.
json run_json(const EquilibriaBoundaryRun& run) {
  json j;
  j["model"] = run.problem.model_name;
  j["boundary_object"] = "equilibrium";
  j["boundary_type"] = run.folds ? "fold" : "hopf";
  j["boundary_x"] = run.settings.x_key;
  j["boundary_y"] = run.settings.y_key;
  const BoundaryOptions& o = run.settings.options;
  j["x_range"] = {o.x_from, o.x_to};
  j["y_range"] = {o.y_from, o.y_to};
  j["curves"] = json::array();
  return j;
}

// A curve's own fields but its points and codim-2 points.
json curve_json(const char* type, BoundaryEnd end, const std::string& note, const std::vector<std::string>& notes) {
  json cj;
  cj["type"] = type;
  cj["end"] = to_string(end);
  if (!note.empty()) cj["note"] = note;
  cj["points"] = json::array();
  cj["codim2"] = json::array();
  cj["notes"] = notes;
  return cj;
}

json fold_curves_json(const EquilibriaBoundaryRun& run, const FoldCurves& r, double seconds) {
  json j = run_json(run);
  for (const FoldCurve& c : r.curves) {
    json cj = curve_json("fold", c.end, c.note, c.notes);
    for (const FoldCurvePoint& p : c.points)
      cj["points"].push_back({{"x", p.x}, {"y", p.y}, {"equilibrium", state_values(p.state)}});
    for (const FoldCodim2Point& b : c.codim2)
      cj["codim2"].push_back({{"kind", to_string(b.kind)},
                              {"x", b.x},
                              {"y", b.y},
                              {"bound", b.bound},
                              {"equilibrium", state_values(b.state)},
                              {"evaluations", b.evaluations}});
    j["curves"].push_back(cj);
  }
  j["notes"] = r.notes;
  j["seconds"] = seconds;
  return j;
}

std::string fold_curves_csv(const std::string& header, const Problem& problem, const FoldCurves& r) {
  std::ostringstream rows;
  rows << header << "curve,x,y";
  for (const std::string& name : problem.state_names) rows << "," << name;
  rows << "\n";
  for (size_t k = 0; k < r.curves.size(); ++k)
    for (const FoldCurvePoint& p : r.curves[k].points) {
      rows << k + 1 << "," << csv_number(p.x) << "," << csv_number(p.y);
      for (long i = 0; i < p.state.size(); ++i) rows << "," << csv_number(p.state[i]);
      rows << "\n";
    }
  return rows.str();
}

json curves_json(const EquilibriaBoundaryRun& run, const HopfCurves& r, double seconds) {
  json j = run_json(run);
  for (const HopfCurve& c : r.curves) {
    json cj = curve_json("hopf", c.end, c.note, c.notes);
    for (const HopfCurvePoint& p : c.points) cj["points"].push_back(point_json(p));
    for (const HopfCodim2Point& g : c.codim2) {
      json gj = {{"kind", to_string(g.kind)}, {"x", g.x},         {"y", g.y},
                 {"bound", g.bound},         {"omega", g.omega}, {"evaluations", g.evaluations}};
      if (g.kind != HopfCodim2Kind::generalised_hopf)
        gj["second_root"] = {{"re", g.second_root.real()}, {"im", g.second_root.imag()}};
      cj["codim2"].push_back(gj);
    }
    j["curves"].push_back(cj);
  }
  j["notes"] = r.notes;
  j["seconds"] = seconds;
  return j;
}

std::string curves_csv(const std::string& header, const HopfCurves& r) {
  std::ostringstream rows;
  rows << header << "curve,x,y,omega,period,l1,l1_bound,criticality\n";
  for (size_t k = 0; k < r.curves.size(); ++k)
    for (const HopfCurvePoint& p : r.curves[k].points) {
      const HopfNormalForm* n = p.normal_form ? &*p.normal_form : nullptr;
      rows << k + 1 << "," << csv_number(p.x) << "," << csv_number(p.y) << "," << csv_number(p.root.value.imag()) << ","
           << csv_number(2 * std::numbers::pi / p.root.value.imag()) << "," << csv_number(n ? n->l1 : NAN) << ","
           << csv_number(n ? n->l1_bound : NAN) << "," << (n ? to_string(n->criticality) : "") << "\n";
    }
  return rows.str();
}

void print_curves(std::ostream& os, const EquilibriaBoundaryRun& run, const HopfCurves& r, double seconds) {
  const std::string &x = run.settings.x_key, &y = run.settings.y_key;
  const BoundaryOptions& o = run.settings.options;
  os << "delayspec boundary: model " << run.problem.model_label << ", Hopf curves of the equilibrium in (" << x << ", "
     << y << ") over [" << format_number(o.x_from) << ", " << format_number(o.x_to) << "] x ["
     << format_number(o.y_from) << ", " << format_number(o.y_to)
     << "], on the exact characteristic function\ncurves: " << r.curves.size() << "\n";
  for (size_t k = 0; k < r.curves.size(); ++k) {
    const HopfCurve& c = r.curves[k];
    os << "  curve " << k + 1 << ": " << c.points.size() << " points, ended at `" << to_string(c.end) << "`"
       << (c.note.empty() ? "" : " (" + c.note + ")") << "\n";
    if (!c.points.empty()) {
      const HopfCurvePoint &a = c.points.front(), &b = c.points.back();
      os << "    from (" << format_number(a.x) << ", " << format_number(a.y) << ") to (" << format_number(b.x) << ", "
         << format_number(b.y) << "), omega " << format_number(a.root.value.imag(), 6) << " .. "
         << format_number(b.root.value.imag(), 6) << "\n";
    }
    for (const HopfCodim2Point& g : c.codim2) {
      const char* what = g.kind == HopfCodim2Kind::generalised_hopf ? "generalised Hopf point (l1 = 0)"
                         : g.kind == HopfCodim2Kind::double_hopf    ? "double Hopf point (a second pair on the axis)"
                                                                    : "zero-Hopf point (a real root at 0)";
      os << "    " << what << " at " << x << " = " << format_number(g.x) << ", " << y << " = " << format_number(g.y)
         << " +- " << format_number(g.bound, 2) << ", omega = " << format_number(g.omega);
      if (g.kind == HopfCodim2Kind::double_hopf) os << " and " << format_number(std::abs(g.second_root.imag()));
      os << "\n";
    }
    for (const std::string& n : c.notes) os << "    note: " << n << "\n";
  }
  for (const std::string& n : r.notes) os << "note: " << n << "\n";
  os << "time: " << seconds << " s\n";
}

void print_fold_curves(std::ostream& os, const EquilibriaBoundaryRun& run, const FoldCurves& r, double seconds) {
  const BoundaryOptions& o = run.settings.options;
  os << "delayspec boundary: model " << run.problem.model_label << ", fold curves of the equilibrium in ("
     << run.settings.x_key << ", " << run.settings.y_key << ") over [" << format_number(o.x_from) << ", "
     << format_number(o.x_to) << "] x [" << format_number(o.y_from) << ", " << format_number(o.y_to)
     << "], on the extended system (f = 0, J singular)\ncurves: " << r.curves.size() << "\n";
  for (size_t k = 0; k < r.curves.size(); ++k) {
    const FoldCurve& c = r.curves[k];
    os << "  curve " << k + 1 << ": " << c.points.size() << " points, ended at `" << to_string(c.end) << "`"
       << (c.note.empty() ? "" : " (" + c.note + ")") << "\n";
    if (!c.points.empty())
      os << "    from (" << format_number(c.points.front().x) << ", " << format_number(c.points.front().y) << ") to ("
         << format_number(c.points.back().x) << ", " << format_number(c.points.back().y) << ")\n";
    for (const FoldCodim2Point& b : c.codim2)
      os << "    " << (b.kind == FoldCodim2Kind::bogdanov_takens ? "Bogdanov-Takens point (a double zero root)"
                                                                 : "cusp point (two folds meet)")
         << " at " << run.settings.x_key << " = " << format_number(b.x)
         << ", " << run.settings.y_key << " = " << format_number(b.y) << " +- " << format_number(b.bound, 2) << "\n";
    for (const std::string& n : c.notes) os << "    note: " << n << "\n";
  }
  for (const std::string& n : r.notes) os << "note: " << n << "\n";
  os << "time: " << seconds << " s\n";
}

}  // namespace

int boundary_equilibria(Config& config, const Invocation& inv) {
  const auto start = std::chrono::steady_clock::now();
  const EquilibriaBoundaryRun run = read_run(config);
  const EquilibriumOptions& eq = run.eq.options;
  const EquilibriumFamily2 family = equilibria_over(run.problem.family, run.problem.parameter_values, run.x_index,
                                                    run.y_index, run.problem.map_settings(), eq);
  HopfCurveOptions o;
  o.boundary = run.settings.options;
  o.equilibrium = eq;
  o.scan_lines = std::max(1, run.settings.scan_points);
  HopfCurves curves;
  FoldCurves folds;
  if (run.folds)
    folds = fold_curves(family, run.eq.guess, o);
  else
    curves = hopf_curves(family, run.eq.guess, o);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const json j = run.folds ? fold_curves_json(run, folds, seconds) : curves_json(run, curves, seconds);
  std::string failures;
  for (const HopfCurve& c : curves.curves)
    if (c.end == BoundaryEnd::failure) failures += (failures.empty() ? "" : "; ") + c.note;
  for (const FoldCurve& c : folds.curves)
    if (c.end == BoundaryEnd::failure) failures += (failures.empty() ? "" : "; ") + c.note;
  const size_t count = run.folds ? folds.curves.size() : curves.curves.size();
  const char* kind = run.folds ? "fold" : "Hopf";
  if (inv.out_dir) {
    const std::filesystem::path dir(*inv.out_dir);
    const OutputMetadata metadata = make_metadata("boundary", inv.scene, config, j, seconds);
    std::string header = metadata_comment_lines(metadata);
    if (!failures.empty()) header += "# INCOMPLETE: a curve ended in a failure: " + failures + "\n";
    if (run.folds)
      write_output(inv, dir / "fold_curves.csv", fold_curves_csv(header, run.problem, folds));
    else
      write_output(inv, dir / "hopf_curves.csv", curves_csv(header, curves));
    json file = j;
    file["metadata"] = metadata_json(metadata);
    write_output(inv, dir / "boundary.json", file.dump(2) + "\n");
  }
  if (!failures.empty()) {
    inv.err << "delayspec boundary: numerical failure: " << failures
            << (inv.out_dir ? "; the curves so far are in " + *inv.out_dir : std::string()) << "\n";
    return 3;
  }
  if (count == 0) {
    inv.err << "delayspec boundary: numerical failure: no " << kind << " point of the equilibrium for " << run.settings.y_key
            << " in [" << format_number(o.boundary.y_from) << ", " << format_number(o.boundary.y_to) << "] at "
            << run.settings.x_key << " = " << format_number(o.boundary.x_from)
            << (o.scan_lines > 1 ? " .. " + format_number(o.boundary.x_to) : std::string()) << "\n";
    return 3;
  }
  if (inv.json)
    inv.out << j.dump(2) << "\n";
  else if (run.folds)
    print_fold_curves(inv.out, run, folds, seconds);
  else
    print_curves(inv.out, run, curves, seconds);
  return 0;
}

}  // namespace delayspec::cli
