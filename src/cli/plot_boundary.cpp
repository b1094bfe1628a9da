#include "cli/plot_boundary.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli/plot_inputs.hpp"
#include "delayspec/errors.hpp"

namespace delayspec::cli {

namespace {

// The lowest curve point above each of `samples` values of x (linear between a curve's points;
// y_to where no curve passes): the edge of the region on the y_from side of every curve.
std::string lower_envelope(const std::vector<std::vector<std::pair<double, double>>>& curves, double x0, double x1,
                           double y_from, double y_to, int samples) {
  std::string rows;
  const bool up = y_to > y_from;
  for (int i = 0; i < samples; ++i) {
    const double x = x0 + (x1 - x0) * i / (samples - 1);
    double edge = y_to;
    for (const auto& c : curves)
      for (size_t k = 1; k < c.size(); ++k) {
        const auto &a = c[k - 1], &b = c[k];
        if ((x - a.first) * (x - b.first) > 0 || a.first == b.first) continue;
        const double y = a.second + (b.second - a.second) * (x - a.first) / (b.first - a.first);
        edge = up ? std::min(edge, y) : std::max(edge, y);
      }
    rows += gnuplot_number(x) + " " + gnuplot_number(y_from) + " " + gnuplot_number(edge) + "\n";
  }
  return rows;
}

// What the figure draws, read from boundary.csv and boundary.json.
struct BoundaryFigure {
  std::string x_key, y_key, N, title;
  double x0 = 0, x1 = 0, y_from = 0, y_to = 0;  // the run's ranges
  std::vector<std::vector<std::pair<double, double>>> points;  // by curve
  std::vector<std::string> types;                              // by curve
  std::string bars;                                            // "x y dx dy" of the extrapolated points
  std::string marks, labels;                                   // the codim-2 points, each once
  bool stable_below = false;
};

BoundaryFigure read_boundary_figure(const std::filesystem::path& dir) {
  const ResultTable t = read_result_table(dir / "boundary.csv", [](const std::string& column) {
    return column != "curve" && column != "x" && column != "y";  // (no extrapolation, no level: nan)
  });
  t.require_header({"curve", "x", "y", "angle", "y_extrapolated", "error_estimate", "x_extrapolated", "x_error_estimate"});
  t.require_rows();
  const nlohmann::json j = read_json_file(dir / "boundary.json");
  const JsonField root(j, "boundary.json", "");
  BoundaryFigure f;
  f.x_key = root.at("boundary_x").text();
  f.y_key = root.at("boundary_y").text();
  f.N = std::to_string(static_cast<long>(root.at("N").number()));
  f.title = t.metadata_text("title", "");
  const std::vector<JsonField> x_range = root.at("x_range").elements(), y_range = root.at("y_range").elements();
  f.x0 = std::min(x_range.at(0).number(), x_range.at(1).number());
  f.x1 = std::max(x_range.at(0).number(), x_range.at(1).number());
  f.y_from = y_range.at(0).number();
  f.y_to = y_range.at(1).number();
  const std::vector<JsonField> curves = root.at("curves").elements();
  f.points.resize(curves.size());
  for (size_t r = 0; r < t.rows.size(); ++r) {  // (rows in order, column `curve` from 1)
    const auto& row = t.rows[r];
    if (row.empty()) continue;
    const double index = row[0];
    if (!(index >= 1 && index <= static_cast<double>(curves.size()) && index == std::floor(index)))
      throw BadInput(t.where(r) + ": `curve` = " + gnuplot_number(index) + " is not a curve of boundary.json (1.." +
                     std::to_string(curves.size()) + ")");
    f.points[static_cast<size_t>(index) - 1].emplace_back(row[1], row[2]);
    if (std::isfinite(row[4]) && std::isfinite(row[5]) && std::isfinite(row[6]) && std::isfinite(row[7]))
      f.bars += gnuplot_number(row[6]) + " " + gnuplot_number(row[4]) + " " + gnuplot_number(row[7]) + " " +
                gnuplot_number(row[5]) + "\n";
  }
  // The curves that meet at a codim-2 point both report it: one mark (within 1 % of the ranges).
  std::vector<std::pair<double, double>> marked;
  for (const JsonField& c : curves) {
    f.types.push_back(c.at("type").text());
    for (const JsonField& q : c.at("codim2").elements()) {
      const double x = q.at("x").number(), y = q.at("y").number();
      bool seen = false;
      for (const auto& [px, py] : marked)
        seen = seen || (std::abs(px - x) <= 0.01 * (f.x1 - f.x0) && std::abs(py - y) <= 0.01 * std::abs(f.y_to - f.y_from));
      if (seen) continue;
      marked.emplace_back(x, y);
      f.marks += gnuplot_number(x) + " " + gnuplot_number(y) + "\n";
      f.labels += "set label " + std::to_string(marked.size()) + " " + gnuplot_string(q.at("kind").text()) + " at " +
                  gnuplot_number(x) + "," + gnuplot_number(y) + " offset 1,-1 front boxed font ',9'\n";
    }
  }
  const auto side = root.find("stable_side");
  f.stable_below = side && side->text() == "y_from";
  return f;
}

}  // namespace

void plot_hopf_curves(FigureRenderer& renderer, const std::filesystem::path& dir) {
  const nlohmann::json j = read_json_file(dir / "boundary.json");
  const JsonField root(j, "boundary.json", "");
  // Points by criticality, a blank line where a run of one kind ends (gnuplot breaks the line
  // there); consecutive points of different kinds share their meeting point so the curve is whole.
  std::map<std::string, std::string> by_kind;
  std::string marks, labels;
  int label = 0;
  for (const JsonField& c : root.at("curves").elements()) {
    std::string previous;
    std::pair<double, double> last{NAN, NAN};
    for (const JsonField& p : c.at("points").elements()) {
      const double x = p.at("x").number(), y = p.at("y").number();
      const auto kind = p.find("criticality");
      const std::string k = kind ? kind->text() : c.at("type").text() == "fold" ? "fold" : "degenerate";
      if (k != previous) {
        if (!previous.empty()) by_kind[previous] += "\n";
        if (std::isfinite(last.first))
          by_kind[k] += gnuplot_number(last.first) + " " + gnuplot_number(last.second) + "\n";
      }
      by_kind[k] += gnuplot_number(x) + " " + gnuplot_number(y) + "\n";
      previous = k;
      last = {x, y};
    }
    for (auto& [kind, block] : by_kind) block += "\n";
    for (const JsonField& g : c.at("codim2").elements()) {
      const double x = g.at("x").number(), y = g.at("y").number();
      const std::string kind = g.at("kind").text();
      marks += gnuplot_number(x) + " " + gnuplot_number(y) + "\n";
      labels += "set label " + std::to_string(++label) + " " +
                gnuplot_string(kind == "generalised_hopf" ? "GH" : kind == "double_hopf" ? "HH" : "ZH") + " at " +
                gnuplot_number(x) + "," + gnuplot_number(y) + " offset 1,-1 front boxed font ',9'\n";
    }
  }
  std::ostringstream gp;
  for (const auto& [kind, block] : by_kind) gp << gnuplot_datablock(kind, block);
  gp << gnuplot_datablock("marks", marks.empty() ? "nan nan\n" : marks);
  // the scene's title above, as on every figure (boundary.json's metadata.parameters)
  const auto metadata = root.find("metadata");
  const auto parameters = metadata ? metadata->find("parameters") : std::nullopt;
  gp << figure_title(parameters ? parameters->text_or("title", "") : "", "Curves of the equilibrium's bifurcations");
  gp << "set xlabel " << key_axis_label(root.at("boundary_x").text()) << "\nset ylabel "
     << key_axis_label(root.at("boundary_y").text())
     << "\nset grid\nset key outside bottom center horizontal\nset style textbox opaque noborder\n" << labels;
  const std::vector<JsonField> x_range = root.at("x_range").elements(), y_range = root.at("y_range").elements();
  gp << "set xrange [" << gnuplot_number(std::min(x_range.at(0).number(), x_range.at(1).number())) << ":"
     << gnuplot_number(std::max(x_range.at(0).number(), x_range.at(1).number())) << "]\nset yrange ["
     << gnuplot_number(std::min(y_range.at(0).number(), y_range.at(1).number())) << ":"
     << gnuplot_number(std::max(y_range.at(0).number(), y_range.at(1).number())) << "]\n";
  std::string plot = "plot ";
  const auto add = [&](const std::string& item) { plot += (plot == "plot " ? "" : ", \\\n     ") + item; };
  const std::map<std::string, std::string> style = {
      {"supercritical", "lw 2 lc rgb '#1f77b4' title 'Hopf, supercritical (l1 < 0)'"},
      {"subcritical", "lw 2 dt 2 lc rgb '#d62728' title 'Hopf, subcritical (l1 > 0)'"},
      {"degenerate", "lw 2 dt 3 lc rgb '#7f7f7f' title 'Hopf, l1 = 0 within its bar'"},
      {"fold", "lw 2 lc rgb '#2ca02c' title 'fold'"}};
  for (const auto& [kind, block] : by_kind) add("$" + kind + " using 1:2 with lines " + style.at(kind));
  if (!marks.empty()) add("$marks using 1:2 with points pt 6 ps 1.5 lc rgb '#000000' title 'codim 2 (GH: l1 = 0, HH: double Hopf, ZH: zero-Hopf)'");
  gp << plot << "\n";
  renderer.figure("hopf_curves", gp.str());
}

void plot_boundary(FigureRenderer& renderer, const std::filesystem::path& dir) {
  const BoundaryFigure f = read_boundary_figure(dir);
  // One datablock per type (curves separated by blank lines): one colour and one legend entry each.
  std::map<std::string, std::string> by_type;
  for (size_t i = 0; i < f.points.size(); ++i) {
    std::string& block = by_type[f.types[i]];
    for (const auto& [x, y] : f.points[i]) block += gnuplot_number(x) + " " + gnuplot_number(y) + "\n";
    block += "\n";
  }
  // The stable side, shaded when the run found the orbit stable at y_from wherever it searched.
  const std::string region = f.stable_below ? lower_envelope(f.points, f.x0, f.x1, f.y_from, f.y_to, 600) : "";
  std::ostringstream gp;
  int block_index = 0;
  for (const auto& [type, block] : by_type) gp << gnuplot_datablock("curves" + std::to_string(++block_index), block);
  gp << gnuplot_datablock("bars", f.bars.empty() ? "nan nan nan nan\n" : f.bars)
     << gnuplot_datablock("marks", f.marks.empty() ? "nan nan\n" : f.marks)
     << gnuplot_datablock("region", region.empty() ? "nan nan nan\n" : region);
  gp << figure_title(f.title, "Stability boundary, N = " + f.N);
  gp << "set xlabel " << key_axis_label(f.x_key) << "\nset ylabel " << key_axis_label(f.y_key)
     << "\nset grid\nset key outside bottom center horizontal\nset style textbox opaque noborder\n"
     // The ranges the run searched (error bars may reach past them), and bars without end caps:
     // a bar as long as its estimate, invisible where it is below the line's width.
     << "set xrange [" << gnuplot_number(f.x0) << ":" << gnuplot_number(f.x1) << "]\nset yrange ["
     << gnuplot_number(std::min(f.y_from, f.y_to)) << ":" << gnuplot_number(std::max(f.y_from, f.y_to))
     << "]\nset bars 0\n"
     << f.labels;
  // A legend entry only for what is drawn.
  std::string plot = "plot ";
  const auto add = [&](const std::string& item) { plot += (plot == "plot " ? "" : ", \\\n     ") + item; };
  if (!region.empty()) add("$region using 1:2:3 with filledcurves lc rgb '#c7e9c0' title 'stable'");
  const char* colours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};
  block_index = 0;
  for (const auto& [type, block] : by_type) {
    add("$curves" + std::to_string(block_index + 1) + " using 1:2 with lines lw 2 lc rgb '" + colours[block_index % 4] +
        "' title " + gnuplot_string(type));
    ++block_index;
  }
  if (!f.bars.empty())
    add("$bars using 1:2:3:4 with xyerrorbars pt 7 ps 0.25 lc rgb '#000000' title " +
        gnuplot_string("extrapolated, with its error estimate"));
  if (!f.marks.empty()) add("$marks using 1:2 with points pt 6 ps 1.5 lc rgb '#000000' title 'codim 2'");
  gp << plot << "\n";
  renderer.figure("boundary", gp.str());
}

}  // namespace delayspec::cli
