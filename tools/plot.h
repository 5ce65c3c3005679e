#pragma once
/// A small PNG plotter: scatter points and polylines on linear or log axes, decade ticks, a legend, and
/// labels drawn with a built-in 5x7 bitmap font. Enough for benchmark figures; no dependencies beyond libpng.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/result.h"

namespace palpate {

/// One data set: points (drawn as filled squares) and/or a polyline through them in order.
struct PlotSeries {
  std::string label;                   ///< legend text (empty: not in the legend)
  std::array<uint8_t, 3> rgb{0, 0, 0}; ///< colour
  std::vector<double> x, y;            ///< data (same length); non-positive values are skipped on log axes
  bool points = true;                  ///< draw markers
  bool line = false;                   ///< draw a polyline
};

/// A whole figure. Plain data.
struct PlotSpec {
  int width = 900, height = 600;  ///< pixels
  std::string title, x_label, y_label;
  bool log_x = true, log_y = true;
  std::vector<PlotSeries> series;
};

/// Renders the figure and writes it as PNG (atomically). Errors name the path, or say there is nothing to plot.
Status write_plot_png(const PlotSpec& spec, const std::string& path);

}  // namespace palpate
