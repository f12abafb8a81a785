// dynid/io/plot.hpp -- figures (PNG or SVG) drawn with PLplot (Debian's libplplot, cairo drivers).
#pragma once

#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace dynid::plot {

/// kSegments: separate line segments between points 0-1, 2-3, ... (a structure drawn member by member).
enum class Kind { kLine, kMarkers, kLineMarkers, kBars, kStems, kSegments };

struct Series {
  std::string label;
  std::vector<double> x, y;
  Kind kind = Kind::kLine;
  int color = -1;        ///< palette index 0..9 (-1: next in the panel)
  double width = 1.6;    ///< line width
  double bar_width = 0.8;
  std::vector<double> yerr;  ///< optional symmetric error bars (one per point; NaN = none)
  double dx = 0;             ///< horizontal offset (to place grouped markers side by side)
  int symbol = 17;           ///< PLplot marker code for markers (17 filled dot, 4 circle, 2 plus, 5 cross, 7 triangle)
  double symbol_scale = 1.0;
};

struct Panel {
  std::string title, xlabel, ylabel;
  bool log_y = false;    ///< values <= 0 are drawn at the bottom of the axis
  std::vector<Series> series;
  std::vector<std::pair<double, std::string>> xticks;  ///< categorical labels at positions (empty: numeric)
  double xmin = std::numeric_limits<double>::quiet_NaN(), xmax = xmin, ymin = xmin, ymax = xmin;
  std::vector<std::pair<double, std::string>> hlines;  ///< horizontal reference lines (value, label)
  bool legend = true;
  /// Series on a second y axis at the right (drawn first, behind the others), e.g. an FRF behind a
  /// stabilization diagram.
  std::vector<Series> right;
  std::string ylabel_right;
  bool log_right = true;
};

struct Figure {
  std::string title;
  int rows = 1, cols = 1;
  int width = 1400, height = 900;  ///< pixels
  std::vector<Panel> panels;       ///< row by row
};

/// Draws the figure to `path` (.png or .svg by extension), written atomically; refuses to replace an existing
/// file unless `overwrite`. Throws InputError (bad path or extension) or std::runtime_error (plotting failed).
void save(const Figure& figure, const std::string& path, bool overwrite);

}  // namespace dynid::plot
