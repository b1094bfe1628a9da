#include "cli/gnuplot_script.hpp"

#include <string_view>

#include <sys/wait.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <map>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "scene/output/atomic_file.hpp"
#include "delayspec/errors.hpp"

namespace delayspec::cli {

namespace fs = std::filesystem;

std::string gnuplot_number(double value) { return std::isfinite(value) ? format_number(value, 10) : "NaN"; }

std::string gnuplot_string(const std::string& text) {
  std::string out = "'";
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\'') out += "\u2019";  // (not gnuplot's '' escape: see the header)
    else if (byte < 0x20 || byte == 0x7f) out += ' ';
    else out += c;
  }
  return out + "'";
}

std::string enhanced_text(const std::string& text) {
  std::string escaped;
  for (const char c : text) {
    if (std::string_view("_^{}@&~").find(c) != std::string_view::npos) escaped += '\\';
    escaped += c;
  }
  return escaped;
}

std::string gnuplot_label(const std::string& text) { return gnuplot_string(enhanced_text(text)); }

std::string figure_title(const std::string& scene_title, const std::string& description) {
  if (scene_title.empty()) return "set title " + gnuplot_string(description) + "\n";
  // gnuplot sets the title just above the graph: the description there, the scene's title above it.
  return "set title " + gnuplot_string(description) + " font ',10'\nset label 99 " + gnuplot_label(scene_title) +
         " at screen 0.5, screen 0.955 center front font ',13'\nset tmargin 5\n";
}

std::string key_axis_label(const std::string& key) {
  static const std::map<std::string, std::string> units = {
      {"spindle_rpm", "rpm"}, {"depth", "m"}, {"omega_n", "rad/s"}, {"Kt", "N/m^2"}, {"Kn", "N/m^2"}, {"mass", "kg"}};
  const auto it = units.find(key);
  return gnuplot_label(it == units.end() ? key : key + " (" + it->second + ")");
}

std::string gnuplot_datablock(const std::string& name, const std::string& rows) {
  return "$" + name + " << EOD\n" + rows + "EOD\n";
}

namespace {

// `s` as one single-quoted word of sh.
std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (const char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The last `n` characters of gnuplot's messages (its error is at the end).
std::string tail(const std::string& text, size_t n) {
  return text.size() <= n ? text : "..." + text.substr(text.size() - n);
}

}  // namespace

FigureRenderer::FigureRenderer(const fs::path& dir, GnuplotSettings settings, std::ostream* progress)
    : plots_(fs::absolute(dir) / "plots"), settings_(std::move(settings)), progress_(progress) {}

void FigureRenderer::figure(const std::string& name, const std::string& body) {
  const fs::path png = plots_ / (name + ".png"), svg = plots_ / (name + ".svg");
  const fs::path png_tmp = plots_ / ("." + name + ".png.tmp"), svg_tmp = plots_ / ("." + name + ".svg.tmp");
  std::ostringstream gp;
  gp << "# delayspec plot: " << name << " (run: gnuplot " << name << ".gp; writes " << name << ".png and " << name
     << ".svg)\n";
  gp << "png_file = " << gnuplot_string(png.filename().string())
     << "\nsvg_file = " << gnuplot_string(svg.filename().string()) << "\n";
  gp << "if (exists('DELAYSPEC_PNG')) png_file = DELAYSPEC_PNG; svg_file = DELAYSPEC_SVG\n";
  gp << "set terminal pngcairo size " << settings_.width << "," << settings_.height
     << " enhanced font 'sans,12' background rgb 'white'\nset output png_file\n";
  gp << body;
  gp << "set terminal svg size " << settings_.width << "," << settings_.height
     << " enhanced font 'sans,12' background rgb 'white'\nset output svg_file\nreplot\nunset output\n";
  const fs::path script = plots_ / (name + ".gp");
  write_file_atomically(script, gp.str());
  // Run in plots/ so that the script's relative names work; the temporaries become the images.
  const std::string log_name = "." + name + ".log";  // relative to plots/ (the cd)
  const std::string command = "cd " + shell_quoted(plots_.string()) + " && " + shell_quoted(settings_.program) +
                              " -e " +
                              shell_quoted("DELAYSPEC_PNG=" + gnuplot_string(png_tmp.filename().string()) +
                                           "; DELAYSPEC_SVG=" + gnuplot_string(svg_tmp.filename().string())) +
                              " " + shell_quoted(script.filename().string()) + " 2>" + shell_quoted(log_name);
  const int status = std::system(command.c_str());
  const int system_errno = errno;
  std::string log_text;
  {
    std::ifstream in(plots_ / log_name);
    std::stringstream ss;
    ss << in.rdbuf();
    log_text = ss.str();
  }
  std::error_code ec;
  fs::remove(plots_ / log_name, ec);
  const bool images = fs::exists(png_tmp, ec) && fs::exists(svg_tmp, ec);
  if (status != 0 || !images) {
    fs::remove(png_tmp, ec);
    fs::remove(svg_tmp, ec);
  }
  if (status == -1)
    throw NumericalFailure("cannot start gnuplot (no shell): " + std::string(std::strerror(system_errno)));
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  if (code == 126 || code == 127) {  // sh: found but not executable / not found
    const std::string what = "cannot run gnuplot (`plot_gnuplot = " + settings_.program + "`)";
    if (settings_.program_given) throw BadInput(what + ": not a program that can run");
    throw NumericalFailure(what + ": install it (Debian: gnuplot-nox, scripts/setup-debian.sh) or set plot_gnuplot");
  }
  if (code != 0)
    throw NumericalFailure("gnuplot failed (exit status " + std::to_string(code) + ") on " + script.string() + ":\n" +
                           tail(log_text, 2000));
  if (!images) throw NumericalFailure("gnuplot wrote no image from " + script.string() + ":\n" + tail(log_text, 2000));
  for (const auto& [from, to] : {std::pair{png_tmp, png}, std::pair{svg_tmp, svg}}) {
    fs::rename(from, to, ec);
    if (ec) throw BadInput("cannot write `" + to.string() + "`: " + ec.message());
  }
  written_.push_back(png.string());
  written_.push_back(svg.string());
  if (progress_) *progress_ << "plot: " << png.string() << " (and .svg, .gp)\n";
}

}  // namespace delayspec::cli
