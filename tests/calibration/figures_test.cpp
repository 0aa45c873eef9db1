// The figures show a run's name as it was given: gnuplot's enhanced text would turn the
// underscore of a file's stem (granmem_seed1) into a subscript.
#include "granmem/calibration/figures.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

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

}  // namespace
}  // namespace granmem
