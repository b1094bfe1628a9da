#pragma once
// The gnuplot scripts of `delayspec plot`: the literals through which values reach a script, and
// the renderer that writes one figure's script and runs gnuplot on it.
//
// Nothing read from a result file is pasted into a script: numbers go through gnuplot_number()
// (checked doubles printed by us), text (titles, axis labels) through gnuplot_string(), a
// single-quoted gnuplot string in which gnuplot substitutes nothing (no backquote command
// substitution, no @macro expansion: both happen only outside single quotes).
#include <filesystem>
#include <ostream>
#include <string>
#include <vector>

namespace delayspec::cli {

// A number for a script or a datablock: "%.10g" (drawing precision); "NaN" (gnuplot's undefined
// value: a missing point) when not finite.
std::string gnuplot_number(double value);

// `text` as a single-quoted gnuplot string: a quote becomes the typographic ’ (U+2019), since
// gnuplot's own escape, a doubled quote, is misread at the start of a string (gnuplot 5.4 reads
// '''a' as '' followed by 'a': a syntax error in a label that starts with a quote); control
// characters (newline, carriage return, NUL, ...) become spaces so that the literal stays on its
// line. Backslashes stay as they are: inside single quotes gnuplot reads them literally, and the
// literal never ends a line (its closing quote does).
std::string gnuplot_string(const std::string& text);
// The same for text drawn in enhanced mode (axis labels from key names): enhanced-text controls
// (_ ^ { } @ & ~) are escaped, so that `spindle_rpm` is not drawn as spindle with subscript r.
std::string gnuplot_label(const std::string& text);
// The escaping of gnuplot_label alone, for a name inside a string that has enhanced-text markup
// of its own (then quoted with gnuplot_string): "max u_v" must not subscript the v.
std::string enhanced_text(const std::string& text);

// A figure's title: the scene's own title (a run's `title`, from the result file's metadata) on
// top and `description` (enhanced text, what is drawn) in smaller type below it; the description
// alone when the scene has no title. gnuplot commands, each line ending in a newline.
std::string figure_title(const std::string& scene_title, const std::string& description);

// The axis label of a model key: gnuplot_label of the key with its unit where the key has one
// ("spindle_rpm (rpm)", "depth (m)"; the milling keys, whose units the key registry's meanings
// state), else of the key alone.
std::string key_axis_label(const std::string& key);

// A datablock: $name << EOD, the rows (numbers only), EOD.
std::string gnuplot_datablock(const std::string& name, const std::string& rows);

struct GnuplotSettings {
  std::string program = "gnuplot";  // key plot_gnuplot
  bool program_given = false;       // plot_gnuplot was set: a program that cannot run is bad input
  long width = 900, height = 700;   // pixels of the PNG (plot_width, plot_height)
};

// Renders figures into DIR/plots/: NAME.gp (self-contained, data inline), NAME.png, NAME.svg.
class FigureRenderer {
 public:
  // `progress`: where to say each figure written (nullptr: say nothing).
  FigureRenderer(const std::filesystem::path& dir, GnuplotSettings settings, std::ostream* progress);

  // Writes NAME.gp (`body` plots once; a header sets the PNG terminal, a footer replots as SVG),
  // runs gnuplot, renames the images into place. gnuplot missing: BadInput when plot_gnuplot was
  // given, else NumericalFailure (exit 3) saying to install it; gnuplot failing on the script:
  // NumericalFailure with gnuplot's messages. No image is left half-written either way.
  void figure(const std::string& name, const std::string& body);

  // The images written so far (PNG and SVG paths).
  const std::vector<std::string>& written() const { return written_; }

 private:
  std::filesystem::path plots_;
  GnuplotSettings settings_;
  std::ostream* progress_;
  std::vector<std::string> written_;
};

}  // namespace delayspec::cli
