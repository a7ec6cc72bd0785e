#include "semsegmap/viz/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "semsegmap/core/atomic_file.h"

namespace semsegmap::viz {

namespace {

// gnuplot strings are single-quoted; a quote inside is doubled.
std::string quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) {
    out += c;
    if (c == '\'') out += '\'';
  }
  return out + "'";
}

// The distance between neighbouring x values of bars (1 when there is only one).
double barSpacing(const Panel& panel) {
  double spacing = 1.0;
  for (const Series& s : panel.series)
    if (s.x.size() >= 2) spacing = std::abs(s.x[1] - s.x[0]);
  return spacing;
}

// Bars of several series share each x: each gets a slot of 0.8 of the spacing.
double barWidth(const Panel& panel) {
  return 0.8 * barSpacing(panel) / static_cast<double>(std::max<size_t>(1, panel.series.size()));
}

void checkPanels(const std::filesystem::path& png, const std::vector<Panel>& panels) {
  if (panels.empty()) throw std::invalid_argument(png.string() + ": nothing to plot");
  for (const Panel& panel : panels)
    for (const Series& series : panel.series) {
      if (series.x.size() != series.y.size())
        throw std::invalid_argument(png.string() + ": series '" + series.name +
                                    "' has different numbers of x and y values");
      if (!series.labels.empty() && series.labels.size() != series.x.size())
        throw std::invalid_argument(png.string() + ": series '" + series.name +
                                    "' has a label count that differs from its points");
    }
}

// Titles, axes and the style of one panel.
std::string panelSettings(const Panel& panel) {
  std::ostringstream gp;
  gp << "set title " << quoted(panel.title) << "\nset xlabel " << quoted(panel.xlabel)
     << "\nset ylabel " << quoted(panel.ylabel) << "\n";
  if (panel.auto_y)
    gp << "set autoscale y\n";
  else
    gp << "set yrange [" << panel.y_min << ":" << panel.y_max << "]\n";
  gp << (panel.log_x ? "set logscale x\n" : "unset logscale x\n");
  if (panel.style != PlotStyle::kBars) {
    gp << "unset xzeroaxis\nset key bottom right\nset offsets 0, 0, 0, 0\nset autoscale x\n";
    return gp.str();
  }
  // The x range spans the bins exactly; autoscaled y gets headroom for the labels.
  double lo = 0, hi = 0;
  bool any = false;
  for (const Series& s : panel.series)
    for (double x : s.x) {
      lo = any ? std::min(lo, x) : x;
      hi = any ? std::max(hi, x) : x;
      any = true;
    }
  const double half = 0.5 * barSpacing(panel);
  gp << "set boxwidth " << barWidth(panel) << " absolute\nset style fill solid 0.75 border -1\n"
     << "set xzeroaxis lt -1\nset key top right\nset offsets 0, 0, graph 0.1, graph 0.05\n";
  if (any) gp << "set xrange [" << lo - half << ":" << hi + half << "]\n";
  return gp.str();
}

void writeSeriesData(const std::filesystem::path& data, const Series& series) {
  writeFileAtomically(data, [&](std::ostream& out) {
    out << "# " << series.name << "\n";
    for (size_t i = 0; i < series.x.size(); ++i) {
      out << series.x[i] << ' ' << series.y[i];
      if (!series.labels.empty()) out << " \"" << series.labels[i] << '"';
      out << '\n';
    }
  });
}

// The plot command of panel p: each series' data file is written into `dir`.
std::string panelPlot(const std::filesystem::path& dir, size_t p, const Panel& panel) {
  std::ostringstream gp;
  gp << "plot ";
  for (size_t s = 0; s < panel.series.size(); ++s) {
    const Series& series = panel.series[s];
    const std::filesystem::path data =
        dir / ("panel" + std::to_string(p) + "_series" + std::to_string(s) + ".dat");
    writeSeriesData(data, series);
    // Bars of series s sit at their slot beside x; the data file keeps the true x.
    const double shift =
        panel.style == PlotStyle::kBars
            ? (static_cast<double>(s) - 0.5 * static_cast<double>(panel.series.size() - 1)) *
                  barWidth(panel)
            : 0.0;
    const std::string x = "($1+" + std::to_string(shift) + ")";
    const char* style = panel.style == PlotStyle::kBars    ? "boxes"
                        : panel.style == PlotStyle::kSteps ? "steps lw 2"
                                                           : "lines lw 2";
    gp << (s ? ", " : "") << quoted(data.string()) << " using " << x << ":2 with " << style
       << " title " << quoted(series.name);
    if (!series.labels.empty())
      // Above the bar, or above the zero line for a negative one.
      gp << ", " << quoted(data.string()) << " using " << x
         << ":($2 > 0 ? $2 : 0):3 with labels offset 0,0.6 font ',8' notitle";
  }
  gp << "\n";
  return gp.str();
}

// Runs the script, which writes <png>.tmp, renamed only when gnuplot succeeded.
void runGnuplot(const std::filesystem::path& png, const std::filesystem::path& dir,
                const std::string& script_text) {
  const std::filesystem::path script = dir / "plot.gp";
  writeBytesAtomically(script, script_text);
  const std::string command = quoted(SEMSEGMAP_GNUPLOT) + " " + quoted(script.string()) + " 2>" +
                              quoted((dir / "gnuplot.log").string());
  const int status = std::system(command.c_str());
  if (status != 0 || !std::filesystem::exists(png.string() + ".tmp"))
    throw std::runtime_error(png.string() + ": gnuplot failed (is gnuplot installed? see " +
                             (dir / "gnuplot.log").string() + ")");
  std::filesystem::rename(png.string() + ".tmp", png);
}

}  // namespace

void plotPanels(const std::filesystem::path& png, const std::string& title,
                const std::vector<Panel>& panels) {
  checkPanels(png, panels);
  const std::filesystem::path dir = png.string() + ".data";
  std::filesystem::create_directories(dir);
  std::ostringstream gp;
  const int width = 520 * static_cast<int>(panels.size());
  // noenhanced: names such as kitti_odometry_00 are printed as they are, not as subscripts.
  gp << "set terminal pngcairo noenhanced size " << width << ",520 font 'sans,10'\n"
     << "set output " << quoted(png.string() + ".tmp") << "\n"
     << "set multiplot layout 1," << panels.size() << " title " << quoted(title) << "\n"
     << "set grid\nset key bottom right\n";
  for (size_t p = 0; p < panels.size(); ++p)
    gp << panelSettings(panels[p]) << panelPlot(dir, p, panels[p]);
  gp << "unset multiplot\nset output\n";
  runGnuplot(png, dir, gp.str());
}

}  // namespace semsegmap::viz
