#pragma once
/// Benchmark figures drawn by gnuplot: a figure's data goes to FILE.dat (plain columns, one block per series)
/// and a gnuplot script to FILE.gp beside FILE.png; palpate runs gnuplot on the script (pngcairo) and writes the
/// PNG atomically. The script reads its data and writes its PNG beside itself, so `gnuplot FILE.gp` redraws the
/// figure after the script was edited, from any folder.

#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// How a series is drawn.
enum class PlotStyle {
  kPoints,       ///< markers only
  kLines,        ///< a polyline through the points in order
  kLinesPoints,  ///< both
  kBoxes,        ///< histogram bars centred on x, PlotSeries::width wide, from the bottom of the graph
};

/// A column written to the data file beside x and y, for the reader (not drawn).
struct PlotColumn {
  std::string name;            ///< header name (no spaces)
  std::vector<double> values;  ///< one per point
};

/// One data set. Plain data.
struct PlotSeries {
  std::string label;                ///< legend text (empty: not in the legend)
  std::string colour = "#000000";   ///< "#rrggbb"
  PlotStyle style = PlotStyle::kPoints;
  int point_type = 7;               ///< gnuplot point type (7 filled circle, 5 filled square, 9 triangle, 13 diamond)
  bool dashed = false;              ///< dashed line
  std::vector<double> x, y;         ///< data (same length); rows not finite, or not positive on a log axis, are left out
  std::vector<double> width;        ///< kBoxes: bar widths in x units (same length as x)
  std::vector<PlotColumn> extra;    ///< more columns for the data file
};

/// A whole figure. Plain data.
struct PlotSpec {
  int width = 800, height = 500;     ///< pixels
  std::string title, x_label, y_label;  ///< axis labels with units
  std::string x_column = "x", y_column = "y";  ///< the data file's column names (no spaces)
  std::string what;                  ///< one line for the data file header: the command that measured it
  bool log_x = true, log_y = true;
  double x_min = 0.0, y_min = 0.0;   ///< > 0: the axis starts here instead of autoscaling
  std::string key = "top right";     ///< legend position inside the graph, gnuplot `set key` words
  bool key_outside = false;          ///< the legend right of the graph instead (never over a point)
  std::vector<PlotSeries> series;
};

/// The three files of a plot: FILE.png as given, FILE.dat and FILE.gp beside it.
struct PlotPaths {
  std::string png, data, script;
};

/// The paths for `png_path`; errors when it does not end in ".png" (the data and script take its stem).
Result<PlotPaths> plot_paths(const std::string& png_path);

/// Checks before a benchmark runs that all three may be written: the name ends in ".png" and none of the three is
/// a symbolic link or anything but a regular file. Errors read "plot '<path>': ...".
Status check_plot_targets(const std::string& png_path);

/// The data file's text: a header comment, then one block per series with points (blocks separated by two blank
/// lines, gnuplot `index N`), columns x, y, [width], extra... at full double precision.
std::string plot_data_text(const PlotSpec& spec);

/// The gnuplot script's text; `data_name` and `png_name` are file names in the script's folder.
std::string plot_script_text(const PlotSpec& spec, const std::string& data_name, const std::string& png_name);

/// Runs gnuplot (found on PATH, no shell) on `script_path` with its standard output in the temporary of an
/// AtomicFile for `png_path`, stops it after timeout_s, and renames the temporary to png_path once gnuplot exited 0
/// and left a PNG there. Errors read "plot '<png_path>': ..." and name gnuplot: not found (with the Debian package),
/// its exit status and error lines, or the timeout; no PNG or temporary is left then.
Status render_with_gnuplot(const std::string& script_path, const std::string& png_path, double timeout_s = 30.0);

/// Writes the data and script (atomically), then renders the PNG. Errors name the file that failed; when only the
/// rendering failed they add that the data and script were written and how to render them later.
Status write_plot(const PlotSpec& spec, const std::string& png_path);

/// write_plot for the command line: prints where the files went and the restyle command on stdout, or the error
/// (prefixed "palpate: ") on stderr. Returns the exit code: 0, or 1 when anything was not written.
int write_plot_and_report(const PlotSpec& spec, const std::string& png_path);

}  // namespace palpate
