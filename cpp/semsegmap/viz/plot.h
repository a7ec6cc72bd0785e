// Curves and histograms are drawn by gnuplot (Debian's gnuplot-nox, installed by
// scripts/setup.sh), fed with the numbers the evaluations also write as JSON: a real plotting
// tool with proper axes and legends, and no plotting library to link. gnuplot rather than
// PLplot or MathGL because it is a single command with no API to bind, its scripts can be
// rerun by hand on the data files, and its pngcairo terminal draws clean antialiased curves.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace semsegmap::viz {

struct Series {
  std::string name;
  std::vector<double> x, y;
  std::vector<std::string> labels;  // optional, one per point: printed above it (bars)
};

enum class PlotStyle {
  kLines,
  kSteps,  // cumulative counts: a step at every value
  kBars,   // histograms: the series side by side at each x (equally spaced x)
};

struct Panel {
  std::string title, xlabel, ylabel;
  std::vector<Series> series;
  PlotStyle style = PlotStyle::kLines;
  bool log_x = false;
  bool auto_y = false;  // gnuplot picks the y range instead of [y_min, y_max]
  double y_min = 0.0, y_max = 1.0;
};

// Panels side by side in one PNG. The data and the gnuplot script are written beside the PNG
// (`<png>.data/`), so the figure can be restyled without rerunning the experiment. Throws
// std::runtime_error naming the PNG when gnuplot is missing or fails.
void plotPanels(const std::filesystem::path& png, const std::string& title,
                const std::vector<Panel>& panels);

}  // namespace semsegmap::viz
