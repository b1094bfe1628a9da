#include "cli/plot_continuation.hpp"

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "delayspec/errors.hpp"
#include "cli/plot_inputs.hpp"

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

// A bifurcation's label in a figure, at (x, y).
std::string bifurcation_label(int index, const std::string& type, double x, double y) {
  return "set label " + std::to_string(index) + " " + gnuplot_string(type) + " at " + gnuplot_number(x) + "," +
         gnuplot_number(y) + " offset 0.5,0.8 font ',9'\n";
}

// One figure of a branch: column y of t against column 0, stable solid and unstable dashed, the
// bifurcations (`marks`, "x y" lines, with their `labels`) and a reference line (a gnuplot
// expression with its legend) when given; a legend entry only for what is drawn.
struct BranchFigure {
  std::string name, title, key, ylabel, marks, labels, reference, reference_title;
  int y = 0, stable = 0;
};
void branch_figure(FigureRenderer& renderer, const ResultTable& t, const BranchFigure& f) {
  std::string solid, dashed;
  stable_and_unstable(t, 0, f.y, f.stable, solid, dashed);
  std::ostringstream gp;
  gp << gnuplot_datablock("stable", solid.empty() ? "nan nan\n" : solid)
     << gnuplot_datablock("unstable", dashed.empty() ? "nan nan\n" : dashed)
     << gnuplot_datablock("marks", f.marks.empty() ? "nan nan\n" : f.marks);
  gp << "set title " << gnuplot_string(f.title + " (stable solid, unstable dashed)") << "\n";
  gp << "set xlabel " << gnuplot_label(f.key) << "\nset ylabel " << gnuplot_string(f.ylabel)
     << "\nset grid\nset key top left\n"
     << f.labels;
  gp << "plot $stable using 1:2 with lines lw 2 dt 1 lc rgb '#000000' title 'stable', \\\n"
     << "     $unstable using 1:2 with lines lw 2 dt 2 lc rgb '#d62728' title 'unstable'"
     << (f.marks.empty() ? "" : ", \\\n     $marks using 1:2 with points pt 7 ps 1.2 lc rgb '#1f77b4' title 'bifurcations'")
     << (f.reference.empty() ? "" : ", \\\n     " + f.reference + " with lines lc rgb '#2ca02c' title '" +
                                        f.reference_title + "'")
     << "\n";
  renderer.figure(f.name, gp.str());
}

}  // namespace

void plot_continuation(FigureRenderer& renderer, const std::filesystem::path& dir) {
  // max_H and contact_time are nan for models without switching; the multiplier columns for points
  // with fewer multipliers than nev.
  const ResultTable t = read_result_table(dir / "branch.csv", [](const std::string& c) {
    return c == "max_H" || c == "contact_time" || c.rfind("mu", 0) == 0 || c == "abs_mu1";
  });
  t.require_header({"parameter", "stable", "unstable", "abs_mu1", "max_y1"});
  t.require_rows();
  const int stable = t.column("stable"), mu1 = t.column("abs_mu1"), max_y1 = t.column("max_y1");
  const std::string key = t.metadata_text("continue_key", "parameter");
  // The bifurcations: parameter, max y1 at the point, |mu| (1 on the circle; grazing: none).
  std::string marks_y, marks_mu, labels_y, labels_mu;
  if (std::filesystem::exists(dir / "continue.json")) {
    const nlohmann::json doc = read_json_file(dir / "continue.json");
    const JsonField j(doc, "continue.json", "");
    int index = 0;
    for (const JsonField& b : j.at("bifurcations").elements()) {
      const double p = b.at("parameter").number();
      const double y = b.at("measures").at("max").elements().at(0).number();
      const std::string type = b.at("type").text();
      if (type != "fold" && type != "period-doubling" && type != "neimark-sacker" && type != "grazing")
        b.at("type").fail("unknown bifurcation type");
      marks_y += gnuplot_number(p) + " " + gnuplot_number(y) + "\n";
      labels_y += bifurcation_label(++index, type, p, y);
      if (type != "grazing") {
        marks_mu += gnuplot_number(p) + " 1\n";
        labels_mu += bifurcation_label(index, type, p, 1);
      }
    }
  }
  const std::string title = "Branch of " + t.metadata_text("model", "?") + " against " + key;
  branch_figure(renderer, t, {"branch", title, key, "max y_1 over the orbit", marks_y, labels_y, "", "", max_y1, stable});
  if (mu1 >= 0)
    branch_figure(renderer, t,
                  {"branch_mu1", title, key, "|{/Symbol m}_1|", marks_mu, labels_mu, "1", "|{/Symbol m}| = 1", mu1,
                   stable});
}

void plot_equilibria(FigureRenderer& renderer, const std::filesystem::path& dir) {
  // the root columns are nan where a point has fewer roots than nroots
  ResultTable t = read_result_table(dir / "equilibria.csv", [](const std::string& c) {
    return c.rfind("lambda", 0) == 0;
  });
  t.require_header({"parameter", "stable", "unstable"});
  t.require_rows();
  // the first state component: the column after parameter, stable, unstable (docs/formats.md)
  const int stable = t.column("stable"), y1 = 3, re1 = t.require_column("lambda1_re", "the roots lambda1_re, lambda1_im, ...");
  const std::string key = t.metadata_text("continue_key", "parameter"), y1_name = t.columns.at(3);
  // The bifurcations of continue.json: marked at their state and on Re lambda = 0.
  std::string marks_y, marks_re, labels_y, labels_re;
  if (std::filesystem::exists(dir / "continue.json")) {
    const nlohmann::json doc = read_json_file(dir / "continue.json");
    const JsonField j(doc, "continue.json", "");
    int index = 0;
    for (const JsonField& b : j.at("bifurcations").elements()) {
      const double p = b.at("parameter").number();
      const double y = b.at("equilibrium").elements().at(0).number();
      const std::string type = b.at("type").text();
      if (type != "fold" && type != "hopf" && type != "branch_point") b.at("type").fail("unknown bifurcation type");
      // a row at the bifurcation, with the stability after it: the stretches meet there, not at
      // the next branch point
      for (size_t i = 1; i < t.rows.size(); ++i)
        if (!t.rows[i - 1].empty() && !t.rows[i].empty() && (p - t.rows[i - 1][0]) * (p - t.rows[i][0]) <= 0) {
          std::vector<double> row = t.rows[i];
          row[0] = p, row[y1] = y, row[re1] = 0;
          t.rows.insert(t.rows.begin() + static_cast<long>(i), row);
          break;
        }
      ++index;
      marks_y += gnuplot_number(p) + " " + gnuplot_number(y) + "\n";
      marks_re += gnuplot_number(p) + " 0\n";
      labels_y += bifurcation_label(index, type, p, y);
      labels_re += bifurcation_label(index, type, p, 0);
    }
  }
  const std::string title = "Equilibria of " + t.metadata_text("model", "?") + " against " + key;
  branch_figure(renderer, t,
                {"equilibria", title, key, y1_name + " at the equilibrium", marks_y, labels_y, "", "", y1, stable});
  branch_figure(renderer, t,
                {"equilibria_re_lambda", title, key, "Re {/Symbol l}_1 (rightmost root)", marks_re, labels_re, "0",
                 "Re {/Symbol l} = 0", re1, stable});
}

}  // namespace delayspec::cli
