// The figures show a run's name as it was given: gnuplot's enhanced text would turn the
// underscore of a file's stem (granmem_seed1) into a subscript.
#include "granmem/calibration/figures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "granmem/core/error.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

class Figures : public testing::TempDirTest {};

std::string read_all(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST_F(Figures, RunNamesAreShownAsGiven) {
  const std::vector<Sample> samples{{"granmem_seed1", {0.001, 0.002, 0.004, 0.01}},
                                    {"a^b{c}", {0.002, 0.003, 0.005}}};
  plot_log_pdfs(dir_, "pdf", samples, "displacement", "pdfs", 5);
  // The SVG holds each name as one piece of text (a subscript would split it in two).
  const std::string svg = read_all(dir_ / "pdf.svg");
  EXPECT_NE(svg.find("granmem_seed1"), std::string::npos) << svg.substr(0, 2000);
  EXPECT_NE(svg.find("a^b{c}"), std::string::npos);
  // The script a user draws again keeps the escapes.
  EXPECT_NE(read_all(dir_ / "pdf.gp").find("granmem\\\\_seed1"), std::string::npos);
}

// An observable that cannot bound the friction gives an interval reaching 0 and infinity:
// the figure is still drawn, over the design's frictions, the band to its edges.
TEST_F(Figures, AnUnboundedIntervalIsDrawnToTheEdges) {
  ObservablePanel panel;
  panel.label = "rotational displacement (d)";
  panel.run_mu_s = {0.05, 0.1, 0.2, 0.4};
  panel.run_value = {0.04, 0.04, 0.038, 0.039};
  panel.run_packing = {0, 0, 0, 0};
  panel.curve_mu_s = panel.run_mu_s;
  panel.curve = panel.run_value;
  panel.experiment = 0.034;
  panel.experiment_error = 0.012;
  const auto written =
      plot_observable_fit(dir_, "fit", {panel}, 0.075, {0, std::numeric_limits<double>::infinity()},
                          std::nan(""), "unbounded");
  EXPECT_TRUE(std::filesystem::exists(dir_ / "fit.png"));
  const std::string gp = read_all(dir_ / "fit.gp");
  EXPECT_EQ(gp.find("inf"), std::string::npos) << gp;
  EXPECT_NE(gp.find("set xrange [0.04:0.5]"), std::string::npos) << gp;
  // The key in the slot after the panels, not beside the last of them.
  EXPECT_NE(gp.find("set multiplot layout 1,2"), std::string::npos) << gp;
  EXPECT_NE(gp.find("set key center center"), std::string::npos) << gp;
}

// Fits made apart (one per cycle): each point with its error in the figure's table, the
// mean's interval as the band, a pseudo-experiment's truth drawn; an unknown truth is not.
TEST_F(Figures, FitsApartShowTheirPointsBandAndTruth) {
  plot_fits_apart(dir_, "apart", {3, 4, 5}, {0.44, 0.47, 0.46}, {0.006, 0.005, 0.007}, 0.457,
                  {0.43, 0.48}, 0.46, "cycle", "each cycle's fit");
  EXPECT_TRUE(std::filesystem::exists(dir_ / "apart.png"));
  EXPECT_NE(read_all(dir_ / "apart.dat").find("4 0.47 0.005"), std::string::npos);
  const std::string gp = read_all(dir_ / "apart.gp");
  EXPECT_NE(gp.find("first 0.43 to graph 1, first 0.48"), std::string::npos) << gp;
  EXPECT_NE(gp.find("0.46 with lines lw 2 dt 2"), std::string::npos) << gp;
  plot_fits_apart(dir_, "unknown", {3, 4, 5}, {0.44, 0.47, 0.46}, {0.006, 0.005, 0.007}, 0.457,
                  {0.43, 0.48}, std::nan(""), "cycle", "each cycle's fit");
  EXPECT_EQ(read_all(dir_ / "unknown.gp").find("true mu_s"), std::string::npos);
  EXPECT_THROW(plot_fits_apart(dir_, "none", {}, {}, {}, 0.4, {0.3, 0.5}, 0.4, "cycle", ""), Error);
}

// The frictions' tics are the design's own, but no two labels nearer than a label's width
// across the panel: the refined runs' 0.246 (four packings) keeps its label, the design's
// 0.35 beside it does not (1.42x apart on an axis of 0.04-0.75).
TEST_F(Figures, TicsOfFrictionsDoNotOverlap) {
  ObservablePanel panel;
  panel.label = "packing fraction";
  panel.run_mu_s = {0.05, 0.05, 0.13, 0.13, 0.246, 0.246, 0.246, 0.246, 0.35, 0.35, 0.6, 0.6};
  panel.run_value.assign(panel.run_mu_s.size(), 0.56);
  panel.run_packing.assign(panel.run_mu_s.size(), 0);
  panel.curve_mu_s = panel.run_mu_s;
  panel.curve = panel.run_value;
  panel.experiment = 0.56;
  panel.experiment_error = 0.001;
  plot_observable_fit(dir_, "fit", {panel}, 0.236, {0.217, 0.256}, 0.23, "tics");
  const std::string gp = read_all(dir_ / "fit.gp");
  EXPECT_NE(gp.find("set xtics (\"0.05\" 0.05, \"0.13\" 0.13, \"0.246\" 0.246, \"0.6\" 0.6)"),
            std::string::npos)
      << gp;
}

}  // namespace
}  // namespace granmem
