#include "cli/plot_continuation.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "cli/plot_inputs.hpp"
#include "scene/output/metadata.hpp"

namespace delayspec::cli {

namespace {

// Two datablocks of (x, y) over the branch: one with the stable stretches, one with the unstable
// ones, each stretch a separate line (a blank line between stretches) and each ending on the
// first point of the next stretch so that the curve has no gap where stability changes.
void stable_and_unstable(const ResultTable& t, int x, int y, int stable, std::string& solid, std::string& dashed) {
  std::vector<const std::vector<double>*> rows;
  for (const auto& row : t.rows)
    if (!row.empty()) rows.push_back(&row);
  for (size_t i = 0; i < rows.size(); ++i) {
    const bool s = (*rows[i])[stable] != 0;
    const std::string line = gnuplot_number((*rows[i])[x]) + " " + gnuplot_number((*rows[i])[y]) + "\n";
    (s ? solid : dashed) += line;
    if (i + 1 < rows.size() && ((*rows[i + 1])[stable] != 0) != s) {
      (s ? solid : dashed) += gnuplot_number((*rows[i + 1])[x]) + " " + gnuplot_number((*rows[i + 1])[y]) + "\n\n";
      (s ? dashed : solid) += "\n";
    }
  }
}

// A bifurcation's label in a figure, at (x, y): to the right of the point, or to its left when
// the point is in the right quarter of the branch's range [x0, x1] (the label would be clipped).
std::string bifurcation_label(int index, const std::string& type, double x, double y, double x0, double x1) {
  const bool left = (x - std::min(x0, x1)) > 0.75 * std::abs(x1 - x0);
  return "set label " + std::to_string(index) + " " + gnuplot_string(type) + " at " + gnuplot_number(x) + "," +
         gnuplot_number(y) + (left ? " right offset -0.5,0.8" : " offset 0.5,0.8") + " font ',9'\n";
}

// The range of column 0 over the rows.
void parameter_range(const ResultTable& t, double& x0, double& x1) {
  x0 = INFINITY, x1 = -INFINITY;
  for (const auto& row : t.rows)
    if (!row.empty()) x0 = std::min(x0, row[0]), x1 = std::max(x1, row[0]);
}

// A row at the bifurcation (p, y in column `yc`, `extra` column set to `extra_value`) with the
// stability after it, so that the stable and unstable stretches meet there, not at the next point.
void insert_bifurcation_row(ResultTable& t, double p, int yc, double y, int extra, double extra_value) {
  for (size_t i = 1; i < t.rows.size(); ++i)
    if (!t.rows[i - 1].empty() && !t.rows[i].empty() && (p - t.rows[i - 1][0]) * (p - t.rows[i][0]) <= 0) {
      std::vector<double> row = t.rows[i];
      row[0] = p, row[static_cast<size_t>(yc)] = y;
      if (extra >= 0) row[static_cast<size_t>(extra)] = extra_value;
      t.rows.insert(t.rows.begin() + static_cast<long>(i), row);
      return;
    }
}

// One figure of a branch: column y of t against column 0, stable solid and unstable dashed, the
// bifurcations (`marks`, "x y" lines, with their `labels`), a reference line (a gnuplot
// expression with its legend) when given, and open circles on the points whose verdict is
// undecided (column `undecided`, continue with continue_Ns: branch_verdicts.hpp); a legend entry
// only for what is drawn.
struct BranchFigure {
  std::string name, title, key, ylabel, marks, labels, reference, reference_title;
  int y = 0, stable = 0, undecided = -1;
};
void branch_figure(FigureRenderer& renderer, const ResultTable& t, const BranchFigure& f) {
  std::string solid, dashed, open;
  stable_and_unstable(t, 0, f.y, f.stable, solid, dashed);
  size_t points = 0, undecided = 0;
  if (f.undecided >= 0)
    for (const auto& row : t.rows)
      if (!row.empty()) {
        ++points;
        if (row[static_cast<size_t>(f.undecided)] != 1) continue;
        ++undecided;
        open += gnuplot_number(row[0]) + " " + gnuplot_number(row[static_cast<size_t>(f.y)]) + "\n";
      }
  // Every point undecided (fewer than three levels): one word in the title, not a circle on each.
  const bool none_decided = points > 0 && undecided == points;
  if (none_decided) open.clear();
  std::ostringstream gp;
  gp << gnuplot_datablock("stable", solid.empty() ? "nan nan\n" : solid)
     << gnuplot_datablock("unstable", dashed.empty() ? "nan nan\n" : dashed)
     << gnuplot_datablock("marks", f.marks.empty() ? "nan nan\n" : f.marks)
     << gnuplot_datablock("undecided", open.empty() ? "nan nan\n" : open);
  const std::string styles = !solid.empty() && !dashed.empty() ? "stable solid, unstable dashed"
                             : !solid.empty()                  ? "stable throughout"
                                                               : "unstable throughout";
  gp << figure_title(
      t.metadata_text("title", ""),
      f.title + " (" + styles + (none_decided ? "; at this N: no N -> infinity verdict without continue_Ns)" : ")"));
  gp << "set xlabel " << gnuplot_label(f.key) << "\nset ylabel " << gnuplot_string(f.ylabel)
     << "\nset grid\nset key top left\n"
     << f.labels;
  // A legend entry only for what is drawn: a branch stable throughout has no dashed stretch.
  std::string plot = "plot ";
  const auto add = [&](const std::string& item) { plot += (plot == "plot " ? "" : ", \\\n     ") + item; };
  if (!solid.empty()) add("$stable using 1:2 with lines lw 2 dt 1 lc rgb '#000000' title 'stable'");
  if (!dashed.empty()) add("$unstable using 1:2 with lines lw 2 dt 2 lc rgb '#d62728' title 'unstable'");
  if (!f.marks.empty()) add("$marks using 1:2 with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'bifurcations'");
  if (!open.empty())
    add("$undecided using 1:2 with points pt 6 ps 1.2 lc rgb '#7f7f7f' title 'undecided as N -> infinity'");
  if (!f.reference.empty())
    add(f.reference + " with lines lc rgb '#2ca02c' title " + gnuplot_string(f.reference_title));
  gp << plot << "\n";
  renderer.figure(f.name, gp.str());
}

// The names of a branch file's d state components: its `# state_names` line (continue writes
// the model's names there), else y1, ..., yd (a file written before it did).
std::vector<std::string> state_names(const ResultTable& t, size_t d) {
  std::vector<std::string> names = t.state_names();
  if (names.size() == d) return names;
  names.clear();
  for (size_t c = 0; c < d; ++c) names.push_back("y" + std::to_string(c + 1));
  return names;
}

// The component a branch's figures show (0-based): plot's plot_component (`component`), else the
// one continue was given (the file records it), else the first.
size_t shown_component(const ResultTable& t, const std::string& component, const std::vector<std::string>& names) {
  return state_component("plot_component", component.empty() ? t.metadata_text("plot_component", "1") : component,
                         names);
}

// A figure's title: `what` of the model (as the files name it) against `key`.
std::string branch_title(const ResultTable& t, const std::string& what, const std::string& key) {
  return what + " of " + enhanced_text(t.model_label("?")) + " against " + enhanced_text(key);
}

// The figures of one branch of orbits: `name` (the max over the orbit of the component chosen
// by plot_component, `component`) and `name`_mu1 (|mu_1|) from its CSV, the bifurcations
// (`bifurcations`: continue.json's list for it, or null) marked.
void orbit_branch_figures(FigureRenderer& renderer, const std::filesystem::path& csv, const JsonField* bifurcations,
                          const std::string& name, const std::string& what, const std::string& component) {
  // max_H and contact_time are nan for models without switching; the multiplier columns for points
  // with fewer multipliers than nev.
  ResultTable t = read_result_table(csv, [](const std::string& c) {
    return c == "max_H" || c == "contact_time" || c.rfind("mu", 0) == 0 || c == "abs_mu1";
  });
  t.require_header({"parameter", "stable", "unstable", "abs_mu1", "max_y1"});
  t.require_rows();
  size_t d = 0;  // the columns max_y1 .. max_yd (docs/formats.md)
  while (t.column("max_y" + std::to_string(d + 1)) >= 0) ++d;
  const std::vector<std::string> names = state_names(t, d);
  const size_t c = shown_component(t, component, names);
  const int stable = t.column("stable"), mu1 = t.column("abs_mu1"), max_y = t.column("max_y" + std::to_string(c + 1));
  const int undecided = t.column("undecided");  // -1: no verdicts (one level, or a Hopf branch)
  const std::string key = t.metadata_text("continue_key", "parameter");
  // The bifurcations: parameter, the component's max at the point, |mu| (1 on the circle; grazing: none).
  std::string marks_y, marks_mu, labels_y, labels_mu;
  double x0, x1;
  parameter_range(t, x0, x1);
  if (bifurcations) {
    int index = 0;
    for (const JsonField& b : bifurcations->elements()) {
      const double p = b.at("parameter").number();
      const JsonField max_field = b.at("measures").at("max");
      const std::vector<JsonField> max = max_field.elements();
      if (max.size() != d)
        max_field.fail("has " + std::to_string(max.size()) + " entries, not " + std::to_string(d) +
                       " (the CSV's max_y columns)");
      const double y = max[c].number();
      const std::string type = b.at("type").text();
      if (type != "fold" && type != "period-doubling" && type != "neimark-sacker" && type != "grazing")
        b.at("type").fail("unknown bifurcation type");
      if (type != "grazing") insert_bifurcation_row(t, p, max_y, y, mu1, 1);
      marks_y += gnuplot_number(p) + " " + gnuplot_number(y) + "\n";
      labels_y += bifurcation_label(++index, type, p, y, x0, x1);
      if (type != "grazing") {
        marks_mu += gnuplot_number(p) + " 1\n";
        labels_mu += bifurcation_label(index, type, p, 1, x0, x1);
      }
    }
  }
  const std::string title = branch_title(t, what, key);
  branch_figure(renderer, t,
                {name, title, key, "max " + enhanced_text(names[c]) + " over the orbit", marks_y, labels_y, "", "",
                 max_y, stable, undecided});
  if (mu1 >= 0)
    branch_figure(renderer, t,
                  {name + "_mu1", title, key, "|{/Symbol m}_1|", marks_mu, labels_mu, "1", "|{/Symbol m}| = 1", mu1,
                   stable, undecided});
}

}  // namespace

void plot_continuation(FigureRenderer& renderer, const std::filesystem::path& dir, const std::string& component) {
  if (!std::filesystem::exists(dir / "continue.json")) {
    orbit_branch_figures(renderer, dir / "branch.csv", nullptr, "branch", "Branch", component);
    return;
  }
  const nlohmann::json doc = read_json_file(dir / "continue.json");
  const JsonField j(doc, "continue.json", "");
  const JsonField bifurcations = j.at("bifurcations");
  orbit_branch_figures(renderer, dir / "branch.csv", &bifurcations, "branch", "Branch", component);
}

void plot_equilibria(FigureRenderer& renderer, const std::filesystem::path& dir, const std::string& component) {
  // the root columns are nan where a point has fewer roots than nroots
  ResultTable t = read_result_table(dir / "equilibria.csv", [](const std::string& c) {
    return c.rfind("lambda", 0) == 0;
  });
  t.require_header({"parameter", "stable", "unstable"});
  t.require_rows();
  // the state components: the columns after parameter, stable, unstable, named by the model
  // (docs/formats.md), up to the roots'
  const int stable = t.column("stable"), re1 = t.require_column("lambda1_re", "the roots lambda1_re, lambda1_im, ...");
  if (re1 < 4) throw BadInput("`" + t.path.string() + "`: no state column before `lambda1_re`");
  const std::vector<std::string> names(t.columns.begin() + 3, t.columns.begin() + re1);
  const size_t c = shown_component(t, component, names);
  const int y = 3 + static_cast<int>(c);
  const std::string key = t.metadata_text("continue_key", "parameter");
  // The bifurcations of continue.json: marked at their state and on Re lambda = 0.
  std::string marks_y, marks_re, labels_y, labels_re;
  double x0, x1;
  parameter_range(t, x0, x1);
  if (std::filesystem::exists(dir / "continue.json")) {
    const nlohmann::json doc = read_json_file(dir / "continue.json");
    const JsonField j(doc, "continue.json", "");
    int index = 0;
    for (const JsonField& b : j.at("bifurcations").elements()) {
      const double p = b.at("parameter").number();
      const JsonField state_field = b.at("equilibrium");
      const std::vector<JsonField> state = state_field.elements();
      if (state.size() != names.size())
        state_field.fail("has " + std::to_string(state.size()) + " entries, not " + std::to_string(names.size()) +
                         " (the CSV's state columns)");
      const double at = state[c].number();
      const std::string type = b.at("type").text();
      if (type != "fold" && type != "hopf" && type != "branch_point") b.at("type").fail("unknown bifurcation type");
      insert_bifurcation_row(t, p, y, at, re1, 0);
      ++index;
      marks_y += gnuplot_number(p) + " " + gnuplot_number(at) + "\n";
      marks_re += gnuplot_number(p) + " 0\n";
      labels_y += bifurcation_label(index, type, p, at, x0, x1);
      labels_re += bifurcation_label(index, type, p, 0, x0, x1);
    }
  }
  const std::string title = branch_title(t, "Equilibria", key);
  branch_figure(renderer, t,
                {"equilibria", title, key, enhanced_text(names[c]) + " at the equilibrium", marks_y, labels_y, "", "",
                 y, stable});
  branch_figure(renderer, t,
                {"equilibria_re_lambda", title, key, "Re {/Symbol l}_1 (rightmost root)", marks_re, labels_re, "0",
                 "Re {/Symbol l} = 0", re1, stable});
  // continue_switch: the orbits born at each Hopf point, hopf_branch_K.csv with continue.json's
  // hopf_branches[K - 1]
  if (!std::filesystem::exists(dir / "hopf_branch_1.csv")) return;
  const bool has_json = std::filesystem::exists(dir / "continue.json");
  const nlohmann::json doc = has_json ? read_json_file(dir / "continue.json") : nlohmann::json();
  const JsonField j(doc, "continue.json", "");
  const std::vector<JsonField> branches = has_json ? j.at("hopf_branches").elements() : std::vector<JsonField>{};
  for (int k = 1; std::filesystem::exists(dir / ("hopf_branch_" + std::to_string(k) + ".csv")); ++k) {
    const std::string name = "hopf_branch_" + std::to_string(k);
    if (has_json && branches.size() < static_cast<size_t>(k))
      j.at("hopf_branches").fail("has " + std::to_string(branches.size()) + " entries, but " + name + ".csv exists");
    const std::optional<JsonField> bifurcations =
        has_json ? std::optional<JsonField>(branches[static_cast<size_t>(k - 1)].at("bifurcations")) : std::nullopt;
    orbit_branch_figures(renderer, dir / (name + ".csv"), bifurcations ? &*bifurcations : nullptr, name,
                         "Orbits from a Hopf point", component);
  }
}

}  // namespace delayspec::cli
