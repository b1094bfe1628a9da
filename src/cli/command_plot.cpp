// delayspec plot DIR: renders PNG and SVG figures with gnuplot from the result files in DIR
// (those `delayspec run` and the commands' --out write), into DIR/plots/. Each figure is a
// self-contained gnuplot script (DIR/plots/NAME.gp, data inline) so that it can be edited and
// re-run by hand: `gnuplot NAME.gp`. Images are written to temporary names and renamed, like
// every output file. The formats each figure reads are documented in docs/formats.md.
//
// Figures (input -> output):
//   floquet.json              -> multipliers: the complex plane, unit circle
//   chart.csv                 -> chart: spectral radius over the parameter plane, |mu_1| = 1 contours
//                                by lobe type (period doubling, Neimark-Sacker, fold)
//   basin.csv                 -> basin: attractor period over the initial-history plane, x = e line
//   converge.json             -> convergence: relative error of mu_1 against h, log-log, with h and
//                                h^2 guides; speed_error: seconds against that error
//   bench.json                -> speed_error (bench rows: the fastest of the repeats, bars up to
//                                the slowest)
//   exponents.csv (sweep)     -> exponents: against the swept parameter, error bars, zero line
//   section.csv (sweep)       -> bifurcation: Poincare-section x against the swept parameter
//   trajectory.csv, poincare.csv (simulate) -> phase: portrait with Poincare points and x = e
//   impacts.csv (simulate)    -> impacts: cumulative impact count against time
//   branch.csv, continue.json (continue) -> branch, branch_mu1 (plot_continuation.hpp)
// Keys: plot_gnuplot (the program, default "gnuplot"), plot_width, plot_height (pixels of the PNG),
// plot_component (the state component of the branch figures).
//
// The inputs are read strictly (plot_inputs.hpp): a file of the wrong shape is bad input (exit 2)
// naming the file and the line or field; values reach the scripts only as numbers we print or as
// quoted gnuplot strings (gnuplot_script.hpp), so no text of a result file is ever executed.
// Exit status: 0 figures written, 2 bad input, 3 gnuplot failed or is not installed.
#include <cmath>
#include <complex>
#include <filesystem>
#include <iterator>
#include <map>
#include <sstream>
#include <vector>

#include "scene/commands/commands.hpp"
#include "delayspec/continuation.hpp"
#include "delayspec/errors.hpp"
#include "cli/gnuplot_script.hpp"
#include "cli/plot_boundary.hpp"
#include "cli/plot_continuation.hpp"
#include "cli/plot_inputs.hpp"

#include <nlohmann/json.hpp>

namespace delayspec::cli {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Whether DIR/NAME is there to plot. Something that is not a regular file (a directory, a FIFO
// that would block the read) is bad input.
bool present(const fs::path& dir, const std::string& name) {
  std::error_code ec;
  const fs::file_status status = fs::status(dir / name, ec);
  if (!fs::exists(status)) return false;
  if (!fs::is_regular_file(status)) throw BadInput("`" + (dir / name).string() + "`: not a regular file");
  return true;
}

// "N = 200" of a title from a table's metadata (the `# N = ...` line of a given N), else "default".
std::string title_N(const ResultTable& t) {
  const double N = t.metadata_number("N", NAN);
  return std::isnan(N) ? std::string("default") : gnuplot_number(N);
}

// ---- the figures ----

// The scene's title of a JSON result (the `title` key among its metadata's parameters), "" when
// it has none.
std::string json_scene_title(const JsonField& j) {
  const auto metadata = j.find("metadata");
  if (!metadata) return "";
  const auto parameters = metadata->find("parameters");
  return parameters ? parameters->text_or("title", "") : "";
}

// The model as titles name it: the metadata's model_label (an [equations] model by its scene),
// else the result's `model`.
std::string json_model_label(const JsonField& j) {
  const auto metadata = j.find("metadata");
  const std::string label = metadata ? metadata->text_or("model_label", "") : "";
  return label.empty() ? j.text_or("model", "?") : label;
}

// floquet.json: multipliers [{re, im, ...}] -> the complex plane with the unit circle.
void plot_multipliers(FigureRenderer& renderer, const JsonField& j) {
  std::string rows;
  double radius = 1;
  const JsonField multipliers = j.at("multipliers");
  for (const JsonField& m : multipliers.elements()) {
    if (m.at("re").is_null()) continue;  // not resolved (floquet: no value, a bound): not drawn
    const double re = m.at("re").number(), im = m.at("im").number();
    rows += gnuplot_number(re) + " " + gnuplot_number(im) + "\n";
    radius = std::max(radius, std::hypot(re, im));
  }
  if (!(radius < 1e300)) multipliers.fail("a modulus of " + format_number(radius) + " is too large to draw");
  const double r = 1.1 * radius;
  const double N = j.number_or("N", NAN);
  std::ostringstream gp;
  gp << gnuplot_datablock("mu", rows);
  gp << figure_title(json_scene_title(j), "Floquet multipliers: model " + enhanced_text(json_model_label(j)) +
                                              ", N = " + (std::isnan(N) ? std::string("?") : gnuplot_number(N)) +
                                              ", solver " + j.text_or("solver", "?"));
  gp << "set size ratio -1\nset grid\nset xlabel 'Re {/Symbol m}'\nset ylabel 'Im {/Symbol m}'\n";
  gp << "set xrange [" << gnuplot_number(-r) << ":" << gnuplot_number(r) << "]\nset yrange [" << gnuplot_number(-r)
     << ":" << gnuplot_number(r) << "]\n";
  gp << "set parametric\nset trange [0:2*pi]\nset key top right\n";
  gp << "plot cos(t), sin(t) with lines lc rgb '#1f77b4' lw 1.5 title 'unit circle', \\\n"
        "     $mu using 1:2 with points pt 7 ps 1.2 lc rgb '#d62728' title 'multipliers'\n";
  renderer.figure("multipliers", gp.str());
}

// The lobes of a chart by the bifurcation at their boundary: the type of the leading multiplier
// where it is outside the circle (crossing_type), with the colour and the words of its line.
struct LobeType {
  BifurcationType type;
  const char* colour;
  const char* dash;
  const char* words;
};
const LobeType kLobeTypes[] = {
    {BifurcationType::neimark_sacker, "white", "1", "Neimark-Sacker (Hopf) lobes, complex {/Symbol m}_1"},
    {BifurcationType::period_doubling, "#00e5ff", "2", "period-doubling (flip) lobes, {/Symbol m}_1 < -1"},
    {BifurcationType::fold, "#7fff00", "3", "fold lobes, {/Symbol m}_1 > 1"}};

// chart.csv: X,Y,spectral_radius[,error_estimate,undecided][,angle] (nan: a failed point, left
// blank) -> image with the |mu_1| = 1 contours, one per lobe type present, and the undecided
// points marked.
void plot_chart(FigureRenderer& renderer, const fs::path& file) {
  const ResultTable t = read_result_table(file, [](const std::string& c) {
    return c == "spectral_radius" || c == "error_estimate" || c == "undecided" || c == "angle";
  });
  t.require_header({"X", "Y", "spectral_radius"});
  t.require_rows();
  t.require_grid();
  const int undecided_column = t.column("undecided");  // charts with error bars (command_chart.cpp)
  const int angle_column = t.column("angle");          // |arg mu_1|: the lobes' types (older charts: none)
  // Columns of the data block: x, y, |mu_1|, undecided (0 without error bars), then per lobe type
  // |mu_1| where the point is stable or unstable by that type, else NaN: the |mu_1| = 1 contour of
  // that column is the boundary of that type's lobes alone (gnuplot's contours skip NaN cells).
  std::string rows;
  bool any_radius = false, any_undecided = false;
  std::vector<bool> type_present(std::size(kLobeTypes), false);
  for (const auto& row : t.rows) {
    if (row.empty()) {
      rows += "\n";
      continue;
    }
    const double radius = row[2];
    const double undecided = undecided_column >= 0 ? row[undecided_column] : 0;
    rows += gnuplot_number(row[0]) + " " + gnuplot_number(row[1]) + " " + gnuplot_number(radius) + " " +
            gnuplot_number(undecided);
    if (angle_column >= 0) {
      const double angle = row[angle_column];
      for (size_t k = 0; k < std::size(kLobeTypes); ++k) {
        const bool unstable_by_type =
            radius > 1 && !std::isnan(angle) && crossing_type(std::polar(1.0, angle)) == kLobeTypes[k].type;
        type_present[k] = type_present[k] || unstable_by_type;
        rows += " " + gnuplot_number(radius <= 1 || unstable_by_type ? radius : NAN);
      }
    }
    rows += "\n";
    any_radius = any_radius || !std::isnan(radius);
    any_undecided = any_undecided || undecided == 1;
  }
  // gnuplot cannot draw a chart without one value: say why instead of its "all points undefined".
  if (!any_radius)
    throw NumericalFailure("`" + file.string() + "`: every point failed (spectral_radius nan): nothing to draw");
  std::ostringstream gp, lines;
  gp << gnuplot_datablock("chart", rows);
  gp << "set contour base\nset cntrparam levels discrete 1.0\nunset surface\n";
  const auto contour = [&](const std::string& name, int column) {
    gp << "set table $" << name << "\nsplot $chart using 1:2:" << column << " with lines\nunset table\n";
  };
  bool typed = false;
  int entries = any_undecided ? 1 : 0;  // of the legend
  for (size_t k = 0; k < std::size(kLobeTypes); ++k) {
    if (!type_present[k]) continue;  // a line and a legend entry only for the lobes there are
    const std::string name = "lobes" + std::to_string(k);
    contour(name, 5 + static_cast<int>(k));
    lines << ", $" << name << " using 1:2 with lines lc rgb '" << kLobeTypes[k].colour << "' lw 2 dt "
          << kLobeTypes[k].dash << " title " << gnuplot_string(kLobeTypes[k].words);
    typed = true;
    ++entries;
  }
  if (!typed) {  // no unstable point, or a chart without angles: one line, |mu_1| = 1
    contour("boundary", 3);
    lines << ", $boundary using 1:2 with lines lc rgb 'white' lw 2 notitle";
  }
  gp << "unset contour\nset surface\n";
  gp << figure_title(t.metadata_text("title", ""), "Spectral radius |{/Symbol m}_1|, model " +
                                                       enhanced_text(t.model_label("?")) + ", N = " + title_N(t) +
                                                       (typed ? "" : " (white line: |{/Symbol m}_1| = 1)"));
  gp << "set xlabel " << key_axis_label(t.columns[0]) << "\nset ylabel " << key_axis_label(t.columns[1]) << "\n";
  gp << "set cblabel '|{/Symbol m}_1| (clipped at 2)'\nset cbrange [0:2]\n"
        "set palette defined (0 '#08306b', 0.5 '#4292c6', 0.999 '#c6dbef', 1.001 '#fee391', 1.5 '#fb6a4a', 2 '#67000d')\n";
  // The legend below the graph, one entry per line, on a grey box (its white line must show), with
  // room made for it under the axis label: gnuplot's own margin let the two overlap.
  gp << "set autoscale fix\n";
  if (entries > 0)
    gp << "set key outside bottom center vertical maxcols 1 box opaque fc rgb '#bbbbbb'\nset bmargin "
       << 4 + entries << "\n";
  else gp << "set key off\n";
  gp << "plot $chart using 1:2:($3 > 2 ? 2 : $3) with image notitle" << lines.str();
  // Points whose error bar holds the unit circle: no verdict there (error_bars.hpp). The others get
  // an undefined y, which gnuplot skips (a third `using` column does not: it drew every point).
  if (any_undecided)
    gp << ", \\\n     $chart using 1:($4 == 1 ? $2 : NaN) with points pt 6 ps 0.5 lc rgb 'black' "
          "title 'undecided (no error bar, or |{/Symbol m}_1| = 1 within it)'";
  gp << "\n";
  renderer.figure("chart", gp.str());
}

// basin.csv: X,Y,period,max_section_x (nan, nan: a failed point) -> period colours over the
// initial-history plane.
void plot_basin(FigureRenderer& renderer, const fs::path& file) {
  const ResultTable t =
      read_result_table(file, [](const std::string& c) { return c == "period" || c == "max_section_x"; });
  t.require_header({"X", "Y", "period"});
  t.require_rows();
  t.require_grid();
  // Fixed colours per period (an rgbimage, so that a period has the same colour in every figure):
  // 0 (no period found: chaotic or longer) black, then a qualitative palette.
  static const int rgb[10][3] = {{17, 17, 17},  {31, 119, 180}, {44, 160, 44},  {148, 103, 189}, {140, 86, 75},
                                 {214, 39, 40}, {255, 127, 14}, {188, 189, 34}, {227, 119, 194}, {127, 127, 127}};
  std::string rows;
  std::map<long, long> present;  // period (-1: failed) -> points
  for (size_t i = 0; i < t.rows.size(); ++i) {
    const auto& row = t.rows[i];
    if (row.empty()) {
      rows += "\n";
      continue;
    }
    if (!std::isnan(row[2]) && !(row[2] >= 0 && row[2] <= 1e9 && row[2] == std::floor(row[2])))
      throw BadInput(t.where(i) + ": period `" + format_number(row[2]) + "`: expected a whole number >= 0 (or nan)");
    const long period = std::isnan(row[2]) ? -1 : static_cast<long>(row[2]);
    const int* c = period >= 0 ? rgb[period % 10] : rgb[9];
    rows += gnuplot_number(row[0]) + " " + gnuplot_number(row[1]) + " " + std::to_string(c[0]) + " " +
            std::to_string(c[1]) + " " + std::to_string(c[2]) + "\n";
    ++present[period];
  }
  std::ostringstream gp;
  gp << gnuplot_datablock("basin", rows);
  gp << figure_title(t.metadata_text("title", ""), "Basins of attraction, model " + enhanced_text(t.model_label("?")) +
                                                       ", k = " + gnuplot_number(t.metadata_number("k", 0)) +
                                                       ", N = " + title_N(t));
  gp << "set xlabel " << key_axis_label(t.columns[0]) << "\nset ylabel " << key_axis_label(t.columns[1]) << "\n";
  gp << "set autoscale fix\nset key outside right top box opaque\nset style fill solid 1.0\n";
  std::ostringstream legend;
  for (const auto& [period, n] : present) {
    const int* c = period >= 0 ? rgb[period % 10] : rgb[9];
    char colour[16];
    std::snprintf(colour, sizeof colour, "#%02x%02x%02x", c[0], c[1], c[2]);
    const std::string label = period < 0    ? "failed"
                              : period == 0 ? "no period (chaotic?)"
                                            : "period " + std::to_string(period);
    legend << ", \\\n     NaN with boxes lc rgb '" << colour << "' title "
           << gnuplot_string(label + " (" + std::to_string(n) + ")");
  }
  std::string impact_line;
  if (t.columns[0] == "x0" && t.metadata_text("model", "impact") == "impact") {
    const std::string e = gnuplot_number(t.metadata_number("e", 1.26));
    gp << "set arrow from " << e << ", graph 0 to " << e << ", graph 1 nohead lc rgb '#00bfff' lw 3 front\n";
    impact_line = ", \\\n     NaN with lines lc rgb '#00bfff' lw 3 title 'impact boundary x = e'";
  }
  gp << "plot $basin using 1:2:3:4:5 with rgbimage notitle" << legend.str() << impact_line << "\n";
  renderer.figure("basin", gp.str());
}

// The leading multiplier's error of a converge/bench row: `error`, a number or a list whose first
// entry is plotted; NaN when absent or null (no error to draw).
double first_error(const JsonField& row) {
  const auto e = row.find("error");
  if (!e) return NAN;
  if (!e->is_array()) return e->number();
  const std::vector<JsonField> errors = e->elements();
  return errors.empty() || errors[0].is_null() ? NAN : errors[0].number();
}

// The studies of a converge result: one per events variant ("by_events"), else the top level.
std::vector<std::pair<std::string, JsonField>> convergence_studies(const JsonField& j) {
  std::vector<std::pair<std::string, JsonField>> out;
  if (const auto by_events = j.find("by_events")) {
    for (const JsonField& s : by_events->elements()) out.emplace_back("events = " + s.text_or("events", "?"), s);
  } else {
    const auto events = j.find("events");
    out.emplace_back(events ? "events = " + events->text() : "error", j);
  }
  return out;
}

// converge.json -> relative error of mu_1 against h, log-log, with slope-1 and slope-2 guides.
void plot_convergence(FigureRenderer& renderer, const JsonField& j) {
  const char* colours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd"};
  std::ostringstream gp, plot;
  double h0 = NAN, e0 = NAN;
  bool has_h = true;
  int block = 0;
  for (const auto& [label, study] : convergence_studies(j)) {
    std::string rows;
    for (const JsonField& row : study.at("rows").elements()) {
      const auto h_field = row.find("h");
      has_h = has_h && h_field.has_value();
      double h;
      if (h_field) {
        h = h_field->number();
      } else {
        const double N = row.at("N").number();
        if (!(N > 0)) row.at("N").fail("must be > 0 (h = 1/N is drawn when a row has no h)");
        h = 1.0 / N;
      }
      const double e = first_error(row);
      if (!(e > 0) || !(h > 0)) continue;  // a log-log figure: zero or negative cannot be drawn
      rows += gnuplot_number(h) + " " + gnuplot_number(e) + "\n";
      if (std::isnan(h0) || e > e0) h0 = h, e0 = e;  // guides through the largest error
    }
    if (rows.empty()) continue;
    std::string name("c");
    name.append(std::to_string(block));
    gp << gnuplot_datablock(name, rows);
    plot << (block == 0 ? "plot " : ", \\\n     ") << "$" << name << " using 1:2 with linespoints pt 7 lw 2 lc rgb '"
         << colours[block % 4] << "' title " << gnuplot_string(label);
    ++block;
  }
  if (block == 0) throw BadInput("`converge.json`: no row with a positive error and h to plot");
  gp << figure_title(json_scene_title(j),
                     "Convergence of the leading multiplier (reference: " + j.text_or("reference", "?") + ")");
  gp << "set logscale xy\nset grid\nset format y '10^{%L}'\nset key bottom right\n";
  gp << "set xlabel " << gnuplot_string(has_h ? "h" : "1/N (h = tau/N)")
     << "\nset ylabel 'relative error of complex {/Symbol m}_1'\n";
  gp << "h0 = " << gnuplot_number(h0) << "; e0 = " << gnuplot_number(e0) << "\n";
  gp << plot.str() << ", \\\n     e0*(x/h0) with lines dt 2 lc rgb '#555555' title 'slope 1 (h)', \\\n"
     << "     e0*(x/h0)**2 with lines dt 3 lc rgb '#000000' title 'slope 2 (h^2)'\n";
  renderer.figure("convergence", gp.str());
}

// converge.json and bench.json -> seconds against the relative error of mu_1, one line per solver
// (bench) or events variant (converge).
void plot_speed_error(FigureRenderer& renderer, const std::vector<std::pair<std::string, JsonField>>& sources) {
  std::ostringstream gp, plot;
  int block = 0;
  bool any_spread = false;
  for (const auto& [source, whole] : sources) {
    std::vector<std::pair<std::string, JsonField>> parts;
    if (source == "converge") parts = convergence_studies(whole);
    else parts.emplace_back(source, whole);
    for (const auto& [label, j] : parts) {
      std::map<std::string, std::string> by_solver;
      std::map<std::string, bool> spread;  // a series with repeats: bars from the fastest to the slowest
      for (const JsonField& row : j.at("rows").elements()) {
        const double e = first_error(row);
        const double s = row.number_or("seconds", NAN);
        if (!(e > 0) || !(s > 0)) continue;
        const double slowest = row.number_or("seconds_slowest", NAN);  // bench with repeats
        const std::string solver = source + ": " + row.text_or("solver", label);
        by_solver[solver] += gnuplot_number(e) + " " + gnuplot_number(s) + " " +
                             gnuplot_number(row.number_or("N", 0)) + " " +
                             gnuplot_number(slowest >= s ? slowest : s) + "\n";
        spread[solver] = spread[solver] || slowest > s;
      }
      for (const auto& [solver, rows] : by_solver) {
        std::string name("s");  // (append: GCC 12 warns falsely on "s" + string)
        name.append(std::to_string(block++));
        gp << gnuplot_datablock(name, rows);
        plot << (plot.tellp() > 0 ? ", \\\n     " : "plot ") << "$" << name
             << (spread[solver] ? " using 1:2:2:4 with yerrorlines" : " using 1:2 with linespoints")
             << " pt 7 lw 2 title " << gnuplot_string(solver);
        any_spread = any_spread || spread[solver];
      }
    }
  }
  if (block == 0) return;
  gp << figure_title(json_scene_title(sources.front().second),
                     any_spread ? "Speed against error: the fastest of the repeats, bars up to the slowest"
                                : "Speed against error (one solve per point)")
     << "set logscale xy\nset grid\nset format x '10^{%L}'\nset format y '10^{%L}'\n"
        "set xlabel 'relative error of complex {/Symbol m}_1'\nset ylabel 'seconds'\nset key top right\n";
  gp << plot.str() << "\n";
  renderer.figure("speed_error", gp.str());
}

// The swept key of a sweep's tables, for the x axis: the `# sweep_key = K` metadata line of the
// CSV (sweep writes it), else sweep.json's sweep_key, else "parameter" (older files).
std::string sweep_label(const fs::path& dir, const ResultTable& t) {
  const std::string from_csv = t.metadata_text("sweep_key", "");
  if (!from_csv.empty()) return from_csv;
  if (!present(dir, "sweep.json")) return "parameter";
  const Json doc = read_json_file(dir / "sweep.json");
  return JsonField(doc, "sweep.json", "").text_or("sweep_key", "parameter");
}

// exponents.csv (sweep): parameter,lambda1..k,se1..k,... (nan: a failed point) -> exponents
// against the swept parameter with standard-error bars and the zero line.
void plot_exponents(FigureRenderer& renderer, const fs::path& dir) {
  const ResultTable t = read_result_table(dir / "exponents.csv", [](const std::string& c) { return c != "parameter"; });
  std::vector<int> lambda, se;
  for (int i = 1;; ++i) {
    const int l = t.column("lambda" + std::to_string(i));
    if (l < 0) break;
    lambda.push_back(l);
    se.push_back(t.column("se" + std::to_string(i)));  // -1: no error bars
  }
  t.require_header({"parameter", "lambda1"});
  t.require_rows();
  const std::string label = sweep_label(dir, t);
  std::ostringstream gp, plot;
  const char* colours[] = {"#000000", "#d62728", "#1f77b4", "#9467bd", "#8c564b", "#e377c2"};
  for (size_t i = 0; i < lambda.size(); ++i) {
    std::string rows;
    for (const auto& row : t.rows)  // (every row has every column: read_result_table checks)
      if (!row.empty())
        rows += gnuplot_number(row[0]) + " " + gnuplot_number(row[lambda[i]]) + " " +
                gnuplot_number(se[i] >= 0 ? row[se[i]] : 0) + "\n";
    std::string name("l");  // (append: GCC 12 warns falsely on "l" + string)
    name.append(std::to_string(i + 1));
    gp << gnuplot_datablock(name, rows);
    plot << (i == 0 ? "plot " : ", \\\n     ") << "$" << name << " using 1:2:3 with yerrorlines pt 7 ps 0.5 lc rgb '"
         << colours[i % 6] << "' title '{/Symbol l}_" << i + 1 << "'";
  }
  gp << figure_title(t.metadata_text("title", ""), "Lyapunov exponents per period against " + label + " (zero line green)");
  gp << "set xlabel " << gnuplot_label(label) << "\nset ylabel 'exponent per period'\nset grid\nset key bottom right\n";
  gp << plot.str() << ", \\\n     0 with lines lc rgb '#2ca02c' lw 2 title 'zero'\n";
  renderer.figure("exponents", gp.str());
}

// section.csv (sweep): parameter,x -> bifurcation diagram.
void plot_bifurcation(FigureRenderer& renderer, const fs::path& dir) {
  const ResultTable t = read_result_table(dir / "section.csv");
  t.require_header({"parameter", "x"});
  t.require_rows();
  const std::string label = sweep_label(dir, t);
  std::string rows;
  for (const auto& row : t.rows)
    if (!row.empty()) rows += gnuplot_number(row[0]) + " " + gnuplot_number(row[1]) + "\n";
  std::ostringstream gp;
  gp << gnuplot_datablock("section", rows);
  // the column x is the first state component: named as the model names it where the file says
  const std::vector<std::string> names = t.state_names();
  const std::string x = enhanced_text(names.empty() ? "x" : names.front());
  gp << figure_title(t.metadata_text("title", ""),
                     "Bifurcation diagram: " + x + " on the Poincare section against " + enhanced_text(label));
  gp << "set xlabel " << gnuplot_label(label) << "\nset ylabel " << gnuplot_string(x + "(t_0 + jT)")
     << "\nset grid\nset key off\n";
  gp << "plot $section using 1:2 with points pt 7 ps 0.3 lc rgb '#000000'\n";
  renderer.figure("bifurcation", gp.str());
}

// The impact boundary e of a simulate result: from DIR/simulate.json's metadata (run) or the
// CSV's metadata lines, else the paper's 1.26. Always parsed as a number (a hex float included).
double impact_boundary(const fs::path& dir, const ResultTable& t) {
  if (present(dir, "simulate.json")) {
    const Json doc = read_json_file(dir / "simulate.json");
    const JsonField j(doc, "simulate.json", "");
    if (const auto metadata = j.find("metadata"))
      if (const auto parameters = metadata->find("parameters"))
        if (const auto e = parameters->find("e")) {
          // The parameters are recorded as text; a JSON number is accepted too.
          if (e->is_number()) return e->number();
          const auto value = parse_number(e->text());
          if (!value || !std::isfinite(*value)) e->fail("`" + e->text().substr(0, 60) + "`: not a finite number");
          return *value;
        }
  }
  return t.metadata_number("e", 1.26);
}

// Rows of columns (a, b), at most max_rows of them (evenly thinned: a figure, not the data).
std::string thinned(const ResultTable& t, int a, int b, size_t max_rows, bool* was_thinned) {
  const size_t n = t.data_rows();
  const size_t stride = n > max_rows ? (n + max_rows - 1) / max_rows : 1;
  if (was_thinned) *was_thinned = stride > 1;
  std::string rows;
  size_t i = 0;
  for (const auto& row : t.rows) {
    if (row.empty()) continue;
    if (i++ % stride == 0) rows += gnuplot_number(row[a]) + " " + gnuplot_number(row[b]) + "\n";
  }
  return rows;
}

// trajectory.csv + poincare.csv (simulate: t,x,v) -> phase portrait with the section points and
// the impact boundary x = e.
void plot_phase(FigureRenderer& renderer, const fs::path& dir) {
  const ResultTable trajectory = read_result_table(dir / "trajectory.csv");
  const int x = trajectory.column("x"), v = trajectory.column("v");
  if (x < 0 || v < 0) return;  // a scalar model: no phase plane
  trajectory.require_rows();
  bool thin = false;
  std::ostringstream gp;
  gp << gnuplot_datablock("trajectory", thinned(trajectory, x, v, 200000, &thin));
  std::string section_plot;
  if (present(dir, "poincare.csv")) {
    const ResultTable poincare = read_result_table(dir / "poincare.csv");
    const int px = poincare.require_column("x", "t,x,v"), pv = poincare.require_column("v", "t,x,v");
    if (poincare.data_rows() > 0) {
      gp << gnuplot_datablock("section", thinned(poincare, px, pv, 200000, nullptr));
      section_plot = ", \\\n     $section using 1:2 with points pt 7 ps 0.8 lc rgb '#000000' title 'Poincare points'";
    }
  }
  gp << figure_title(trajectory.metadata_text("title", ""),
                     std::string("Phase portrait") + (thin ? " (trajectory thinned for drawing)" : ""));
  gp << "set xlabel 'x'\nset ylabel 'v = dx/dt'\nset grid\nset key outside bottom center horizontal\n";
  // The impact boundary only for the impact model (the default): mathieu and milling have x, v too,
  // and no boundary to draw or list in the legend.
  std::string boundary_plot;
  if (trajectory.metadata_text("model", "impact") == "impact") {
    const std::string e = gnuplot_number(impact_boundary(dir, trajectory));
    gp << "set arrow from " << e << ", graph 0 to " << e << ", graph 1 nohead lc rgb '#1f77b4' lw 2 front\n";
    boundary_plot =
        ", \\\n     NaN with lines lc rgb '#1f77b4' lw 2 title " + gnuplot_string("impact boundary x = e = " + e);
  }
  gp << "plot $trajectory using 1:2 with lines lc rgb '#999999' title 'trajectory'" << section_plot << boundary_plot
     << "\n";
  renderer.figure("phase", gp.str());
}

// impacts.csv (simulate: t,count) -> cumulative impacts against time (paper Fig. 6.3).
void plot_impacts(FigureRenderer& renderer, const fs::path& dir) {
  const ResultTable t = read_result_table(dir / "impacts.csv");
  t.require_header({"t", "count"});
  std::ostringstream gp;
  // No impact at all is a result (a flat line at 0), not an error.
  gp << gnuplot_datablock("impacts", t.data_rows() > 0 ? thinned(t, 0, 1, 200000, nullptr) : "0 0\n");
  gp << figure_title(t.metadata_text("title", ""), "Number of impacts against time");
  gp << "set xlabel 't'\nset ylabel 'impacts (cumulative)'\nset grid\nset key off\n";
  gp << "plot $impacts using 1:2 with steps lw 2 lc rgb '#d62728'\n";
  renderer.figure("impacts", gp.str());
}

}  // namespace

int command_plot(Config& config, const Invocation& inv) {
  GnuplotSettings settings;
  settings.program_given = config.has("plot_gnuplot");
  settings.program = config.get_string("plot_gnuplot", settings.program);
  settings.width = static_cast<int>(config.get_int_in_range("plot_width", settings.width, 100, 10000));
  settings.height = static_cast<int>(config.get_int_in_range("plot_height", settings.height, 100, 10000));
  if (settings.program.empty()) throw BadInput("`plot_gnuplot = `: empty (the gnuplot program to run)");
  // checked against the branch file's state names when a branch is drawn (plot_continuation.hpp)
  const std::string component = config.get_string("plot_component", "");
  config.check_all_used();
  // The directory: `delayspec plot DIR` (the positional argument) or --out DIR.
  std::string dir_text = inv.scene.value_or(inv.out_dir.value_or(""));
  if (dir_text.empty()) throw BadInput("`delayspec plot` needs a results directory: delayspec plot DIR");
  const fs::path dir = dir_text;
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw BadInput("`" + dir.string() + "`: not a directory (expected a results directory)");

  FigureRenderer renderer(dir, settings, inv.json ? nullptr : &inv.out);
  // The JSON documents live here; JsonFields and the speed sources point into them.
  Json floquet, converge, bench;
  std::vector<std::pair<std::string, JsonField>> speed_sources;
  if (present(dir, "floquet.json")) {
    floquet = read_json_file(dir / "floquet.json");
    plot_multipliers(renderer, JsonField(floquet, "floquet.json", ""));
  }
  if (present(dir, "chart.csv")) plot_chart(renderer, dir / "chart.csv");
  if (present(dir, "basin.csv")) plot_basin(renderer, dir / "basin.csv");
  if (present(dir, "exponents.csv")) plot_exponents(renderer, dir);
  if (present(dir, "section.csv")) plot_bifurcation(renderer, dir);
  if (present(dir, "trajectory.csv")) plot_phase(renderer, dir);
  if (present(dir, "impacts.csv")) plot_impacts(renderer, dir);
  if (present(dir, "branch.csv")) plot_continuation(renderer, dir, component);
  if (present(dir, "equilibria.csv")) plot_equilibria(renderer, dir, component);
  if (present(dir, "boundary.csv")) plot_boundary(renderer, dir);
  if (present(dir, "hopf_curves.csv") || present(dir, "fold_curves.csv")) plot_hopf_curves(renderer, dir);
  if (present(dir, "converge.json")) {
    converge = read_json_file(dir / "converge.json");
    const JsonField j(converge, "converge.json", "");
    plot_convergence(renderer, j);
    speed_sources.emplace_back("converge", j);
  }
  if (present(dir, "bench.json")) {
    bench = read_json_file(dir / "bench.json");
    speed_sources.emplace_back("bench", JsonField(bench, "bench.json", ""));
  }
  if (!speed_sources.empty()) plot_speed_error(renderer, speed_sources);

  if (renderer.written().empty())
    throw BadInput("`" + dir.string() +
                   "`: nothing to plot (looked for floquet.json, chart.csv, basin.csv, converge.json, bench.json, "
                   "exponents.csv, section.csv, trajectory.csv, impacts.csv, branch.csv, equilibria.csv, boundary.csv, "
                   "hopf_curves.csv, fold_curves.csv; see docs/formats.md)");
  if (inv.json) inv.out << Json{{"directory", dir.string()}, {"files", renderer.written()}}.dump(2) << "\n";
  return 0;
}

}  // namespace delayspec::cli
