#include "semsegmap/viz/plot.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "semsegmap/io/atomic_file.h"

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

}  // namespace

void plotPanels(const std::filesystem::path& png, const std::string& title,
                const std::vector<Panel>& panels) {
  if (panels.empty()) throw std::invalid_argument(png.string() + ": nothing to plot");
  const std::filesystem::path dir = png.string() + ".data";
  std::filesystem::create_directories(dir);
  std::ostringstream gp;
  const int width = 520 * static_cast<int>(panels.size());
  gp << "set terminal pngcairo size " << width << ",520 font 'sans,10'\n"
     << "set output " << quoted(png.string() + ".tmp") << "\n"
     << "set multiplot layout 1," << panels.size() << " title " << quoted(title) << "\n"
     << "set grid\nset key bottom right\n";
  for (size_t p = 0; p < panels.size(); ++p) {
    const Panel& panel = panels[p];
    gp << "set title " << quoted(panel.title) << "\nset xlabel " << quoted(panel.xlabel)
       << "\nset ylabel " << quoted(panel.ylabel) << "\nset yrange [" << panel.y_min << ":"
       << panel.y_max << "]\n"
       << (panel.log_x ? "set logscale x\n" : "unset logscale x\n") << "plot ";
    for (size_t s = 0; s < panel.series.size(); ++s) {
      const Series& series = panel.series[s];
      if (series.x.size() != series.y.size())
        throw std::invalid_argument(png.string() + ": series '" + series.name +
                                    "' has different numbers of x and y values");
      const std::filesystem::path data =
          dir / ("panel" + std::to_string(p) + "_series" + std::to_string(s) + ".dat");
      writeFileAtomically(data, [&](std::ostream& out) {
        out << "# " << series.name << "\n";
        for (size_t i = 0; i < series.x.size(); ++i)
          out << series.x[i] << ' ' << series.y[i] << '\n';
      });
      gp << (s ? ", " : "") << quoted(data.string()) << " using 1:2 with lines lw 2 title "
         << quoted(series.name);
    }
    gp << "\n";
  }
  gp << "unset multiplot\nset output\n";
  const std::filesystem::path script = dir / "plot.gp";
  writeBytesAtomically(script, gp.str());
  // The script writes <png>.tmp, renamed only when gnuplot succeeded.
  const std::string command =
      "gnuplot " + quoted(script.string()) + " 2>" + quoted((dir / "gnuplot.log").string());
  const int status = std::system(command.c_str());
  if (status != 0 || !std::filesystem::exists(png.string() + ".tmp"))
    throw std::runtime_error(png.string() + ": gnuplot failed (is gnuplot installed? see " +
                             (dir / "gnuplot.log").string() + ")");
  std::filesystem::rename(png.string() + ".tmp", png);
}

}  // namespace semsegmap::viz
