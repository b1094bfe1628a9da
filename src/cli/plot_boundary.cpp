#include "cli/plot_boundary.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "cli/plot_inputs.hpp"

namespace delayspec::cli {

void plot_boundary(FigureRenderer& renderer, const std::filesystem::path& dir) {
  const ResultTable t = read_result_table(dir / "boundary.csv", [](const std::string& column) {
    return column != "x" && column != "y";  // (no extrapolation, no level: nan)
  });
  t.require_header({"x", "y", "angle", "y_extrapolated", "error_estimate"});
  t.require_rows();
  const nlohmann::json j = read_json_file(dir / "boundary.json");
  const JsonField root(j, "boundary.json", "");
  const std::string x_key = root.at("boundary_x").text(), y_key = root.at("boundary_y").text();
  const JsonField curve = root.at("curves").elements().at(0);
  const std::string type = curve.at("type").text();
  std::string line, bars, marks, labels;
  int bar_count = 0;
  for (const auto& row : t.rows) {
    if (row.empty()) continue;
    line += gnuplot_number(row[0]) + " " + gnuplot_number(row[1]) + "\n";
    if (std::isfinite(row[3]) && std::isfinite(row[4])) {
      bars += gnuplot_number(row[0]) + " " + gnuplot_number(row[3]) + " " + gnuplot_number(row[4]) + "\n";
      ++bar_count;
    }
  }
  int index = 0;
  for (const JsonField& q : curve.at("codim2").elements()) {
    const double x = q.at("x").number(), y = q.at("y").number();
    marks += gnuplot_number(x) + " " + gnuplot_number(y) + "\n";
    labels += "set label " + std::to_string(++index) + " " + gnuplot_string(q.at("kind").text()) + " at " +
              gnuplot_number(x) + "," + gnuplot_number(y) + " offset 1,-1 font ',9'\n";
  }
  const std::string N = std::to_string(static_cast<long>(root.at("N").number()));
  std::ostringstream gp;
  gp << gnuplot_datablock("curve", line) << gnuplot_datablock("bars", bars.empty() ? "nan nan nan\n" : bars)
     << gnuplot_datablock("marks", marks.empty() ? "nan nan\n" : marks);
  gp << "set title " << gnuplot_string("Stability boundary: " + type + " curve") << "\n";
  gp << "set xlabel " << gnuplot_label(x_key) << "\nset ylabel " << gnuplot_label(y_key)
     << "\nset grid\nset key top left\n"
     << labels;
  // A legend entry only for what is drawn.
  gp << "plot $curve using 1:2 with lines lw 2 lc rgb '#1f77b4' title " << gnuplot_string("N = " + N);
  if (bar_count > 0)
    gp << ", \\\n     $bars using 1:2:3 with yerrorbars pt 7 ps 0.4 lc rgb '#d62728' title "
       << gnuplot_string("extrapolated, with its error estimate");
  if (!marks.empty())
    gp << ", \\\n     $marks using 1:2 with points pt 6 ps 1.5 lc rgb '#000000' title 'codim 2'";
  gp << "\n";
  renderer.figure("boundary", gp.str());
}

}  // namespace delayspec::cli
