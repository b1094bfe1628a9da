// delayspec plot DIR: renders PNG and SVG figures with gnuplot from the result files in DIR
// (those `delayspec run` and the commands' --out write), into DIR/plots/. Each figure is a
// self-contained gnuplot script (DIR/plots/NAME.gp, data inline) so that it can be edited and
// re-run by hand: `gnuplot NAME.gp`. Images are written to temporary names and renamed, like
// every output file. The formats each figure reads are documented in docs/formats.md.
//
// Figures (input -> output):
//   floquet.json              -> multipliers: the complex plane, unit circle
//   chart.csv                 -> chart: spectral radius over the parameter plane, |mu_1| = 1 contour
//   basin.csv                 -> basin: attractor period over the initial-history plane, x = e line
//   converge.json             -> convergence: error against h, log-log, with h and h^2 guides;
//                                speed_error: seconds against error
//   bench.json                -> speed_error (bench rows)
//   exponents.csv (sweep)     -> exponents: against the swept parameter, error bars, zero line
//   section.csv (sweep)       -> bifurcation: Poincare-section x against the swept parameter
//   trajectory.csv, poincare.csv (simulate) -> phase: portrait with Poincare points and x = e
//   impacts.csv (simulate)    -> impacts: cumulative impact count against time
// Keys: plot_gnuplot (the program, default "gnuplot"), plot_width, plot_height (pixels of the PNG).
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "atomic_file.hpp"
#include "commands.hpp"
#include "delayspec/errors.hpp"

#include <nlohmann/json.hpp>

namespace delayspec::cli {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

struct PlotSettings {
  std::string gnuplot = "gnuplot";
  long width = 900, height = 700;
};

// A table read from one of delayspec's CSV files: "# key = value" metadata lines, a header line,
// rows of numbers; blank lines (grid-block separators) kept as empty rows.
struct Table {
  std::map<std::string, std::string> metadata;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;  // empty row = block separator
  int column(const std::string& name) const {
    for (size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return static_cast<int>(i);
    return -1;
  }
};

std::vector<std::string> split(const std::string& line, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string item;
  while (std::getline(ss, item, sep)) out.push_back(item);
  return out;
}

Table read_table(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw BadInput("cannot read `" + path.string() + "`");
  Table t;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("#", 0) == 0) {
      const auto eq = line.find(" = ");
      if (eq != std::string::npos) t.metadata[line.substr(2, eq - 2)] = line.substr(eq + 3);
      continue;
    }
    if (line.empty()) {
      if (!t.rows.empty() && !t.rows.back().empty()) t.rows.emplace_back();
      continue;
    }
    if (t.columns.empty()) {
      t.columns = split(line, ',');
      continue;
    }
    std::vector<double> row;
    for (const auto& cell : split(line, ',')) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      row.push_back(end == cell.c_str() ? NAN : v);
    }
    t.rows.push_back(row);
  }
  if (t.columns.empty()) throw BadInput("`" + path.string() + "`: no header line (expected column names)");
  return t;
}

Json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw BadInput("cannot read `" + path.string() + "`");
  try {
    return Json::parse(in);
  } catch (const Json::exception& e) {
    throw BadInput("`" + path.string() + "`: not JSON: " + e.what());
  }
}

std::string number(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

// gnuplot string literal in single quotes ('' escapes a quote).
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("''") : std::string(1, c);
  return out + "'";
}

// A datablock: $name << EOD ... EOD.
std::string datablock(const std::string& name, const std::string& rows) { return "$" + name + " << EOD\n" + rows + "EOD\n"; }

std::string parameter(const std::map<std::string, std::string>& p, const std::string& key, const std::string& fallback) {
  auto it = p.find(key);
  return it == p.end() ? fallback : it->second;
}

class Plotter {
 public:
  Plotter(fs::path dir, PlotSettings settings, const Invocation& inv)
      : dir_(std::move(dir)), plots_(fs::absolute(dir_) / "plots"), settings_(std::move(settings)), inv_(inv) {}

  // Writes NAME.gp (the body plots once; the header sets the PNG terminal, a footer replots as
  // SVG), runs gnuplot, renames the images into place.
  void figure(const std::string& name, const std::string& body) {
    const fs::path png = plots_ / (name + ".png"), svg = plots_ / (name + ".svg");
    const fs::path png_tmp = plots_ / ("." + name + ".png.tmp"), svg_tmp = plots_ / ("." + name + ".svg.tmp");
    std::ostringstream gp;
    gp << "# delayspec plot: " << name << " (run: gnuplot " << name << ".gp; writes " << name << ".png and " << name
       << ".svg)\n";
    gp << "png_file = " << quoted(png.filename().string()) << "\nsvg_file = " << quoted(svg.filename().string()) << "\n";
    gp << "if (exists('DELAYSPEC_PNG')) png_file = DELAYSPEC_PNG; svg_file = DELAYSPEC_SVG\n";
    gp << "set terminal pngcairo size " << settings_.width << "," << settings_.height
       << " enhanced font 'sans,12' background rgb 'white'\nset output png_file\n";
    gp << body;
    gp << "set terminal svg size " << settings_.width << "," << settings_.height
       << " enhanced font 'sans,12' background rgb 'white'\nset output svg_file\nreplot\nunset output\n";
    const fs::path script = plots_ / (name + ".gp");
    write_file_atomically(script, gp.str());
    // Run in plots/ so that the script's relative names work; the temporaries become the images.
    const std::string command = "cd " + shell_quoted(plots_.string()) + " && " + shell_quoted(settings_.gnuplot) +
                                " -e " + shell_quoted("DELAYSPEC_PNG=" + quoted(png_tmp.filename().string()) +
                                                      "; DELAYSPEC_SVG=" + quoted(svg_tmp.filename().string())) +
                                " " + shell_quoted(script.filename().string()) + " 2>" +
                                shell_quoted("." + name + ".log");  // relative to plots/ (the cd)
    const int status = std::system(command.c_str());
    const fs::path log = plots_ / ("." + name + ".log");
    std::string log_text;
    {
      std::ifstream in(log);
      std::stringstream ss;
      ss << in.rdbuf();
      log_text = ss.str();
    }
    std::error_code ec;
    fs::remove(log, ec);
    if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) == 127)
      throw BadInput("cannot run gnuplot (`plot_gnuplot = " + settings_.gnuplot +
                     "`): install it (Debian: gnuplot-nox, scripts/setup-debian.sh)");
    if (WEXITSTATUS(status) != 0 || !fs::exists(png_tmp) || !fs::exists(svg_tmp)) {
      fs::remove(png_tmp, ec);
      fs::remove(svg_tmp, ec);
      throw std::runtime_error("gnuplot failed on " + script.string() + ":\n" + log_text);
    }
    fs::rename(png_tmp, png);
    fs::rename(svg_tmp, svg);
    written_.push_back(png.string());
    written_.push_back(svg.string());
    if (!inv_.json) inv_.out << "plot: " << png.string() << " (and .svg, .gp)\n";
  }

  const std::vector<std::string>& written() const { return written_; }
  const fs::path& dir() const { return dir_; }

 private:
  static std::string shell_quoted(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
  }
  fs::path dir_, plots_;
  PlotSettings settings_;
  const Invocation& inv_;
  std::vector<std::string> written_;
};

// ---- the figures ----

void plot_multipliers(Plotter& plotter, const Json& j) {
  std::string rows;
  double radius = 1;
  for (const auto& m : j.at("multipliers")) {
    rows += number(m.at("re").get<double>()) + " " + number(m.at("im").get<double>()) + "\n";
    radius = std::max(radius, m.at("abs").get<double>());
  }
  const double r = 1.1 * radius;
  std::ostringstream gp;
  gp << datablock("mu", rows);
  gp << "set title " << quoted("Floquet multipliers: model " + j.value("model", std::string("?")) + ", N = " +
                               std::to_string(j.value("N", 0)) + ", solver " + j.value("solver", std::string("?")))
     << "\n";
  gp << "set size ratio -1\nset grid\nset xlabel 'Re {/Symbol m}'\nset ylabel 'Im {/Symbol m}'\n";
  gp << "set xrange [" << -r << ":" << r << "]\nset yrange [" << -r << ":" << r << "]\n";
  gp << "set parametric\nset trange [0:2*pi]\nset key top right\n";
  gp << "plot cos(t), sin(t) with lines lc rgb '#1f77b4' lw 1.5 title 'unit circle', \\\n"
        "     $mu using 1:2 with points pt 7 ps 1.2 lc rgb '#d62728' title 'multipliers'\n";
  plotter.figure("multipliers", gp.str());
}

void plot_chart(Plotter& plotter, const Table& t) {
  if (t.columns.size() < 3) throw BadInput("chart.csv: expected columns x,y,spectral_radius");
  std::string rows;
  for (const auto& row : t.rows)
    rows += row.empty() ? "\n" : number(row[0]) + " " + number(row[1]) + " " + number(row[2]) + "\n";
  std::ostringstream gp;
  gp << datablock("chart", rows);
  gp << "set table $boundary\nset contour base\nset cntrparam levels discrete 1.0\nunset surface\n"
        "splot $chart using 1:2:3 with lines\nunset table\nunset contour\nset surface\n";
  gp << "set title " << quoted("Spectral radius |{/Symbol m}_1|, model " + parameter(t.metadata, "model", "?") +
                               ", N = " + parameter(t.metadata, "N", "default") + " (white line: |{/Symbol m}_1| = 1)")
     << "\n";
  gp << "set xlabel " << quoted(t.columns[0]) << "\nset ylabel " << quoted(t.columns[1]) << "\n";
  gp << "set cblabel '|{/Symbol m}_1| (clipped at 2)'\nset cbrange [0:2]\n"
        "set palette defined (0 '#08306b', 0.5 '#4292c6', 0.999 '#c6dbef', 1.001 '#fee391', 1.5 '#fb6a4a', 2 '#67000d')\n";
  gp << "set autoscale fix\nset key off\n";
  gp << "plot $chart using 1:2:($3 > 2 ? 2 : $3) with image, $boundary using 1:2 with lines lc rgb 'white' lw 2\n";
  plotter.figure("chart", gp.str());
}

void plot_basin(Plotter& plotter, const Table& t) {
  if (t.columns.size() < 3) throw BadInput("basin.csv: expected columns x,y,period");
  // Fixed colours per period (an rgbimage, so that a period has the same colour in every figure):
  // 0 (no period found: chaotic or longer) black, then a qualitative palette.
  static const int rgb[10][3] = {{17, 17, 17},  {31, 119, 180}, {44, 160, 44},  {148, 103, 189}, {140, 86, 75},
                                 {214, 39, 40}, {255, 127, 14}, {188, 189, 34}, {227, 119, 194}, {127, 127, 127}};
  std::string rows;
  std::map<int, long> present;
  for (const auto& row : t.rows) {
    if (row.empty()) {
      rows += "\n";
      continue;
    }
    const int period = std::isfinite(row[2]) ? static_cast<int>(row[2]) : -1;
    const int* c = period >= 0 ? rgb[period % 10] : rgb[9];
    rows += number(row[0]) + " " + number(row[1]) + " " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " +
            std::to_string(c[2]) + "\n";
    ++present[period];
  }
  std::ostringstream gp;
  gp << datablock("basin", rows);
  gp << "set title " << quoted("Basins of attraction, model " + parameter(t.metadata, "model", "?") + ", k = " +
                               parameter(t.metadata, "k", "0") + ", N = " + parameter(t.metadata, "N", "default"))
     << "\n";
  gp << "set xlabel " << quoted(t.columns[0]) << "\nset ylabel " << quoted(t.columns[1]) << "\n";
  gp << "set autoscale fix\nset key outside right top box opaque\nset style fill solid 1.0\n";
  std::ostringstream legend;
  for (const auto& [period, n] : present) {
    const int* c = period >= 0 ? rgb[period % 10] : rgb[9];
    char colour[16];
    std::snprintf(colour, sizeof colour, "#%02x%02x%02x", c[0], c[1], c[2]);
    const std::string label = period < 0   ? "failed"
                              : period == 0 ? "no period (chaotic?)"
                                            : "period " + std::to_string(period);
    legend << ", \\\n     NaN with boxes lc rgb '" << colour << "' title " << quoted(label + " (" + std::to_string(n) + ")");
  }
  std::string impact_line;
  if (t.columns[0] == "x0" && parameter(t.metadata, "model", "impact") == "impact") {
    const std::string e = parameter(t.metadata, "e", "1.26");
    gp << "set arrow from " << e << ", graph 0 to " << e << ", graph 1 nohead lc rgb '#00bfff' lw 3 front\n";
    impact_line = ", \\\n     NaN with lines lc rgb '#00bfff' lw 3 title 'impact boundary x = e'";
  }
  gp << "plot $basin using 1:2:3:4:5 with rgbimage notitle" << legend.str() << impact_line << "\n";
  plotter.figure("basin", gp.str());
}

// The first multiplier's error of a converge/bench row: a number, or the first of an array.
double first_error(const Json& row) {
  if (!row.contains("error") || row["error"].is_null()) return NAN;
  const Json& e = row["error"];
  if (e.is_number()) return e.get<double>();
  if (e.is_array() && !e.empty() && e[0].is_number()) return e[0].get<double>();
  return NAN;
}

// The studies of a converge result: one per events variant ("by_events"), else the top level.
std::vector<std::pair<std::string, Json>> convergence_studies(const Json& j) {
  std::vector<std::pair<std::string, Json>> out;
  if (j.contains("by_events") && j["by_events"].is_array()) {
    for (const auto& s : j["by_events"]) out.emplace_back("events = " + s.value("events", std::string("?")), s);
  } else {
    out.emplace_back(j.contains("events") && j["events"].is_string() ? "events = " + j["events"].get<std::string>()
                                                                      : "error",
                     j);
  }
  return out;
}

void plot_convergence(Plotter& plotter, const Json& j) {
  const char* colours[] = {"#d62728", "#1f77b4", "#2ca02c", "#9467bd"};
  std::ostringstream gp, plot;
  double h0 = NAN, e0 = NAN;
  bool has_h = true;
  int block = 0;
  for (const auto& [label, study] : convergence_studies(j)) {
    std::string rows;
    for (const auto& row : study.at("rows")) {
      const double N = row.at("N").get<double>();
      has_h = has_h && row.contains("h");
      const double h = row.contains("h") ? row["h"].get<double>() : 1.0 / N;
      const double e = first_error(row);
      if (!(e > 0)) continue;
      rows += number(h) + " " + number(e) + "\n";
      if (std::isnan(h0) || e > e0) h0 = h, e0 = e;  // guides through the largest error
    }
    if (rows.empty()) continue;
    std::string name("c");
    name.append(std::to_string(block));
    gp << datablock(name, rows);
    plot << (block == 0 ? "plot " : ", \\\n     ") << "$" << name << " using 1:2 with linespoints pt 7 lw 2 lc rgb '"
         << colours[block % 4] << "' title " << quoted(label);
    ++block;
  }
  if (block == 0) throw BadInput("converge.json: no row with a positive error to plot");
  gp << "set title " << quoted("Convergence of the leading multiplier (reference: " +
                               j.value("reference", std::string("?")) + ")")
     << "\n";
  gp << "set logscale xy\nset grid\nset format y '10^{%L}'\nset key bottom right\n";
  gp << "set xlabel " << quoted(has_h ? "h" : "1/N (h = tau/N)") << "\nset ylabel 'error of {/Symbol m}_1'\n";
  gp << "h0 = " << number(h0) << "; e0 = " << number(e0) << "\n";
  gp << plot.str() << ", \\\n     e0*(x/h0) with lines dt 2 lc rgb '#555555' title 'slope 1 (h)', \\\n"
     << "     e0*(x/h0)**2 with lines dt 3 lc rgb '#000000' title 'slope 2 (h^2)'\n";
  plotter.figure("convergence", gp.str());
}

void plot_speed_error(Plotter& plotter, const std::vector<std::pair<std::string, Json>>& sources) {
  std::ostringstream gp, plot;
  int block = 0;
  for (const auto& [source, whole] : sources) {
    std::vector<std::pair<std::string, Json>> parts;
    if (source == "converge") parts = convergence_studies(whole);
    else parts.emplace_back(source, whole);
    for (const auto& [label, j] : parts) {
      std::map<std::string, std::string> by_solver;
      for (const auto& row : j.at("rows")) {
        const double e = first_error(row);
        const double s = row.value("seconds", NAN);
        if (!(e > 0) || !(s > 0)) continue;
        const std::string solver = row.contains("solver") && row["solver"].is_string()
                                       ? source + ": " + row["solver"].get<std::string>()
                                       : source + ": " + label;
        by_solver[solver] += number(e) + " " + number(s) + " " + number(row.value("N", 0.0)) + "\n";
      }
      for (const auto& [solver, rows] : by_solver) {
        std::string name("s");  // (append: GCC 12 warns falsely on "s" + string)
        name.append(std::to_string(block++));
        gp << datablock(name, rows);
        plot << (plot.tellp() > 0 ? ", \\\n     " : "plot ") << "$" << name
             << " using 1:2 with linespoints pt 7 lw 2 title " << quoted(solver);
      }
    }
  }
  if (block == 0) return;
  gp << "set title 'Speed against error'\nset logscale xy\nset grid\nset format x '10^{%L}'\n"
        "set xlabel 'error of |{/Symbol m}_1|'\nset ylabel 'seconds'\nset key top right\n";
  gp << plot.str() << "\n";
  plotter.figure("speed_error", gp.str());
}

std::string sweep_label(const fs::path& dir) {
  if (!fs::exists(dir / "sweep.json")) return "parameter";
  const Json j = read_json(dir / "sweep.json");
  return j.contains("sweep_key") && j["sweep_key"].is_string() ? j["sweep_key"].get<std::string>() : "parameter";
}

// exponents.csv (sweep): parameter,lambda1..k,se1..k,... -> exponents against the parameter with
// standard-error bars and the zero line.
void plot_exponents(Plotter& plotter, const Table& t, const std::string& label) {
  std::vector<int> lambda, se;
  for (int i = 1;; ++i) {
    const int l = t.column("lambda" + std::to_string(i));
    if (l < 0) break;
    lambda.push_back(l);
    se.push_back(t.column("se" + std::to_string(i)));
  }
  if (lambda.empty() || t.column("parameter") != 0) throw BadInput("exponents.csv: expected columns parameter,lambda1,...");
  std::ostringstream gp, plot;
  const char* colours[] = {"#000000", "#d62728", "#1f77b4", "#9467bd", "#8c564b", "#e377c2"};
  for (size_t i = 0; i < lambda.size(); ++i) {
    std::string rows;
    for (const auto& row : t.rows)
      if (!row.empty() && static_cast<int>(row.size()) > lambda[i])
        rows += number(row[0]) + " " + number(row[lambda[i]]) + " " + number(se[i] >= 0 ? row[se[i]] : 0) + "\n";
    std::string name("l");  // (append: GCC 12 warns falsely on "l" + string)
    name.append(std::to_string(i + 1));
    gp << datablock(name, rows);
    plot << (i == 0 ? "plot " : ", \\\n     ") << "$" << name << " using 1:2:3 with yerrorlines pt 7 ps 0.5 lc rgb '"
         << colours[i % 6] << "' title '{/Symbol l}_" << i + 1 << "'";
  }
  gp << "set title " << quoted("Lyapunov exponents per period against " + label + " (zero line green)") << "\n";
  gp << "set xlabel " << quoted(label) << "\nset ylabel 'exponent per period'\nset grid\nset key bottom right\n";
  gp << plot.str() << ", \\\n     0 with lines lc rgb '#2ca02c' lw 2 title 'zero'\n";
  plotter.figure("exponents", gp.str());
}

// section.csv (sweep): parameter,x -> bifurcation diagram.
void plot_bifurcation(Plotter& plotter, const Table& t, const std::string& label) {
  if (t.columns.size() < 2) throw BadInput("section.csv: expected columns parameter,x");
  std::string rows;
  for (const auto& row : t.rows)
    if (row.size() >= 2) rows += number(row[0]) + " " + number(row[1]) + "\n";
  std::ostringstream gp;
  gp << datablock("section", rows);
  gp << "set title " << quoted("Bifurcation diagram: x on the Poincare section against " + label) << "\n";
  gp << "set xlabel " << quoted(label) << "\nset ylabel 'x(t_0 + jT)'\nset grid\nset key off\n";
  gp << "plot $section using 1:2 with points pt 7 ps 0.3 lc rgb '#000000'\n";
  plotter.figure("bifurcation", gp.str());
}

// The impact boundary e of a simulate result: from DIR/simulate.json's metadata (run) or the
// CSV's metadata lines, else the paper's 1.26.
std::string impact_boundary(const fs::path& dir, const Table& t) {
  if (fs::exists(dir / "simulate.json")) {
    const Json j = read_json(dir / "simulate.json");
    if (j.contains("metadata") && j["metadata"].contains("parameters") && j["metadata"]["parameters"].contains("e"))
      return j["metadata"]["parameters"]["e"].get<std::string>();
  }
  return parameter(t.metadata, "e", "1.26");
}

// Rows of columns (a, b), at most max_rows of them (evenly thinned: a figure, not the data).
std::string thinned(const Table& t, int a, int b, size_t max_rows, bool* was_thinned) {
  size_t n = 0;
  for (const auto& row : t.rows) n += !row.empty();
  const size_t stride = n > max_rows ? (n + max_rows - 1) / max_rows : 1;
  if (was_thinned) *was_thinned = stride > 1;
  std::string rows;
  size_t i = 0;
  for (const auto& row : t.rows) {
    if (row.empty() || static_cast<int>(row.size()) <= std::max(a, b)) continue;
    if (i++ % stride == 0) rows += number(row[a]) + " " + number(row[b]) + "\n";
  }
  return rows;
}

// trajectory.csv + poincare.csv (simulate: t,x,v) -> phase portrait with the section points and
// the impact boundary x = e.
void plot_phase(Plotter& plotter, const fs::path& dir) {
  const Table trajectory = read_table(dir / "trajectory.csv");
  const int x = trajectory.column("x"), v = trajectory.column("v");
  if (x < 0 || v < 0) return;  // a scalar model: no phase plane
  bool thin = false;
  std::ostringstream gp;
  gp << datablock("trajectory", thinned(trajectory, x, v, 200000, &thin));
  std::string section_plot;
  if (fs::exists(dir / "poincare.csv")) {
    const Table poincare = read_table(dir / "poincare.csv");
    gp << datablock("section", thinned(poincare, poincare.column("x"), poincare.column("v"), 200000, nullptr));
    section_plot = ", \\\n     $section using 1:2 with points pt 7 ps 0.8 lc rgb '#000000' title 'Poincare points'";
  }
  const std::string e = impact_boundary(dir, trajectory);
  gp << "set title " << quoted(std::string("Phase portrait") + (thin ? " (trajectory thinned for drawing)" : "")) << "\n";
  gp << "set xlabel 'x'\nset ylabel 'v = dx/dt'\nset grid\nset key outside bottom center horizontal\n";
  gp << "set arrow from " << e << ", graph 0 to " << e << ", graph 1 nohead lc rgb '#1f77b4' lw 2 front\n";
  gp << "plot $trajectory using 1:2 with lines lc rgb '#999999' title 'trajectory'" << section_plot
     << ", \\\n     NaN with lines lc rgb '#1f77b4' lw 2 title 'impact boundary x = e = " << e << "'\n";
  plotter.figure("phase", gp.str());
}

// impacts.csv (simulate: t,count) -> cumulative impacts against time (paper Fig. 6.3).
void plot_impacts(Plotter& plotter, const fs::path& dir) {
  const Table t = read_table(dir / "impacts.csv");
  if (t.columns.size() < 2) throw BadInput("impacts.csv: expected columns t,count");
  std::ostringstream gp;
  gp << datablock("impacts", thinned(t, 0, 1, 200000, nullptr));
  gp << "set title 'Number of impacts against time'\nset xlabel 't'\nset ylabel 'impacts (cumulative)'\n"
        "set grid\nset key off\n";
  gp << "plot $impacts using 1:2 with steps lw 2 lc rgb '#d62728'\n";
  plotter.figure("impacts", gp.str());
}

}  // namespace

int command_plot(Config& config, const Invocation& inv) {
  PlotSettings settings;
  settings.gnuplot = config.get_string("plot_gnuplot", settings.gnuplot);
  settings.width = config.get_int("plot_width", settings.width);
  settings.height = config.get_int("plot_height", settings.height);
  if (settings.width < 100 || settings.width > 10000)
    throw BadInput("`plot_width = " + std::to_string(settings.width) + "`: must be between 100 and 10000");
  if (settings.height < 100 || settings.height > 10000)
    throw BadInput("`plot_height = " + std::to_string(settings.height) + "`: must be between 100 and 10000");
  config.check_all_used();
  // The directory: `delayspec plot DIR` (the positional argument) or --out DIR.
  std::string dir_text = inv.scene.value_or(inv.out_dir.value_or(""));
  if (dir_text.empty()) throw BadInput("`delayspec plot` needs a results directory: delayspec plot DIR");
  const fs::path dir = dir_text;
  if (!fs::is_directory(dir)) throw BadInput("`" + dir.string() + "`: not a directory (expected a results directory)");

  Plotter plotter(dir, settings, inv);
  std::vector<std::pair<std::string, Json>> speed_sources;
  if (fs::exists(dir / "floquet.json")) plot_multipliers(plotter, read_json(dir / "floquet.json"));
  if (fs::exists(dir / "chart.csv")) plot_chart(plotter, read_table(dir / "chart.csv"));
  if (fs::exists(dir / "basin.csv")) plot_basin(plotter, read_table(dir / "basin.csv"));
  if (fs::exists(dir / "exponents.csv")) plot_exponents(plotter, read_table(dir / "exponents.csv"), sweep_label(dir));
  if (fs::exists(dir / "section.csv")) plot_bifurcation(plotter, read_table(dir / "section.csv"), sweep_label(dir));
  if (fs::exists(dir / "trajectory.csv")) plot_phase(plotter, dir);
  if (fs::exists(dir / "impacts.csv")) plot_impacts(plotter, dir);
  if (fs::exists(dir / "converge.json")) {
    Json j = read_json(dir / "converge.json");
    plot_convergence(plotter, j);
    speed_sources.emplace_back("converge", j);
  }
  if (fs::exists(dir / "bench.json")) speed_sources.emplace_back("bench", read_json(dir / "bench.json"));
  if (!speed_sources.empty()) plot_speed_error(plotter, speed_sources);

  if (plotter.written().empty())
    throw BadInput("`" + dir.string() +
                   "`: nothing to plot (looked for floquet.json, chart.csv, basin.csv, converge.json, bench.json, "
                   "exponents.csv, section.csv, trajectory.csv, impacts.csv; see docs/formats.md)");
  if (inv.json) inv.out << Json{{"directory", dir.string()}, {"files", plotter.written()}}.dump(2) << "\n";
  return 0;
}

}  // namespace delayspec::cli
