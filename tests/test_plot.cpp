// The gnuplot wrapper: a PNG with the data beside it, and clear errors.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>

#include "semsegmap/core/atomic_file.h"
#include "semsegmap/io/image_io.h"
#include "semsegmap/viz/localization_png.h"
#include "semsegmap/viz/plot.h"
#include "temp_dir.h"

namespace semsegmap {
namespace {

using test_support::TempDir;

viz::Panel curvePanel(const std::string& title, double exponent) {
  viz::Panel p;
  p.title = title;
  p.xlabel = "k";
  p.ylabel = "fraction";
  p.log_x = true;
  for (const char* name : {"a", "b's"}) {  // a quote in a name must not break the script
    viz::Series s{name, {}, {}, {}};
    for (int k = 1; k <= 50; ++k) {
      s.x.push_back(k);
      s.y.push_back(std::pow(k / 50.0, exponent));
    }
    p.series.push_back(s);
    exponent *= 2;
  }
  return p;
}

TEST(Plot, WritesAPngAndItsDataAndScript) {
  TempDir tmp;
  const auto png = tmp.path() / "curves.png";
  viz::plotPanels(png, "two panels", {curvePanel("left", 0.5), curvePanel("right", 1.0)});
  const std::string bytes = readFileBytes(png);
  ASSERT_GT(bytes.size(), 8000u);  // two panels of curves, axes and legends
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  // Width: 2 panels of 520 px, from the IHDR chunk (big-endian at byte 16).
  const auto u8 = [&](size_t i) {
    return static_cast<uint32_t>(static_cast<unsigned char>(bytes[i]));
  };
  EXPECT_EQ((u8(16) << 24) | (u8(17) << 16) | (u8(18) << 8) | u8(19), 1040u);
  EXPECT_TRUE(std::filesystem::exists(tmp.path() / "curves.png.data" / "plot.gp"));
  std::ifstream data(tmp.path() / "curves.png.data" / "panel1_series1.dat");
  std::string header, first;
  std::getline(data, header);
  std::getline(data, first);
  EXPECT_EQ(header, "# b's");
  EXPECT_EQ(first, "1 0.0004");  // (1/50)^2
  EXPECT_FALSE(std::filesystem::exists(tmp.path() / "curves.png.tmp"));
}

TEST(Plot, MismatchedSeriesAndEmptyFiguresAreErrors) {
  TempDir tmp;
  viz::Panel bad = curvePanel("bad", 1.0);
  bad.series[0].y.pop_back();
  EXPECT_THROW(viz::plotPanels(tmp.path() / "bad.png", "bad", {bad}), std::invalid_argument);
  EXPECT_THROW(viz::plotPanels(tmp.path() / "none.png", "none", {}), std::invalid_argument);
}

TEST(Plot, BarsWithLabelsAndStepsAreDrawn) {
  TempDir tmp;
  viz::Panel bars;
  bars.style = viz::PlotStyle::kBars;
  bars.auto_y = true;
  for (const char* name : {"x", "y"}) {
    viz::Series s{name, {0.05, 0.15, 0.25}, {-10, 25, 40}, {"3", "7", "9"}};
    bars.series.push_back(s);
  }
  viz::Panel steps = curvePanel("steps", 1.0);
  steps.style = viz::PlotStyle::kSteps;
  const auto png = tmp.path() / "bars.png";
  viz::plotPanels(png, "bars", {bars, steps});
  EXPECT_GT(readFileBytes(png).size(), 8000u);
  const std::string script = readFileBytes(tmp.path() / "bars.png.data" / "plot.gp");
  // Two series of bars share each bin: slots 0.04 wide (0.8 of 0.1 / 2), at -0.02 and +0.02.
  EXPECT_NE(script.find("set boxwidth 0.04"), std::string::npos) << script;
  EXPECT_NE(script.find("($1+-0.020000)"), std::string::npos) << script;
  EXPECT_NE(script.find("with labels"), std::string::npos);
  EXPECT_NE(script.find("with steps"), std::string::npos);
  std::ifstream data(tmp.path() / "bars.png.data" / "panel0_series1.dat");
  std::string header, first;
  std::getline(data, header);
  std::getline(data, first);
  EXPECT_EQ(first, "0.05 -10 \"3\"");

  viz::Panel bad = bars;
  bad.series[0].labels.pop_back();
  EXPECT_THROW(viz::plotPanels(tmp.path() / "bad.png", "bad", {bad}), std::invalid_argument);
}

// The bird's-eye picture of a run along x with three localizations, and its legend's dots at
// the bottom left, top to bottom (rows - 70, rows - 50, rows - 30 px): their colours, RGB.
std::vector<std::array<uint8_t, 3>> legendDots(const std::filesystem::path& png,
                                               bool has_ground_truth) {
  viz::LocalizationPicture pic;
  pic.title = "legend";
  pic.has_ground_truth = has_ground_truth;
  for (int i = 0; i < 10; ++i) pic.trajectory.push_back(planarPose(10.0 * i, 0, 0, 0));
  const double unknown = -1.0;
  for (int i = 1; i < 4; ++i)
    pic.localizations.emplace_back(Eigen::Vector3d(20.0 * i, 0, 0),
                                   has_ground_truth ? 0.3 * i : unknown);
  viz::writeLocalizationPng(png, pic);
  const Image image = readPng(png);
  std::vector<std::array<uint8_t, 3>> dots;
  for (const int up : {70, 50, 30}) {
    const uint8_t* p = image.at(20, image.height - up);
    dots.push_back({p[0], p[1], p[2]});
  }
  return dots;
}

// Without ground truth every dot has the unknown-error colour: the legend shows that colour
// alone, named so, and no error scale whose green no dot could have.
TEST(LocalizationPng, TheLegendWithoutGroundTruthShowsNoErrorColours) {
  TempDir tmp;
  using Rgb = std::array<uint8_t, 3>;
  const Rgb unknown{80, 200, 255}, green{60, 220, 80}, red{230, 40, 40};
  const auto with = legendDots(tmp.path() / "with.png", true);
  EXPECT_EQ(with[0], green);
  EXPECT_EQ(with[2], red);
  const auto without = legendDots(tmp.path() / "without.png", false);
  EXPECT_EQ(without[2], unknown);
  EXPECT_NE(without[0], green);
  EXPECT_NE(without[1], green);
  EXPECT_NE(without[0], unknown);  // one entry only
}

}  // namespace
}  // namespace semsegmap
