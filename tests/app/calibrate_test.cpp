#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

// A tiny pseudo-experiment and its twin: 60 grains in a 2 cm box, 3 cycles.
const std::vector<std::string> kTwin = {"--grains",   "60",    "--box",       "2cm",
                                        "--lid-mass", "0.2kg", "--amplitude", "5%",
                                        "--period",   "0.1s"};

class Calibrate : public GranmemTest {
 protected:
  void SetUp() override {
    GranmemTest::SetUp();
    // Another pour than the twin's seeds (1, 2): another realization of the packing.
    std::vector<std::string> sim{"simulate", "--cycles", "3",      "--seed",    "7", "--mu-s",
                                 "0.2",      "--out",    "exp.h5", "--threads", "1"};
    sim.insert(sim.end(), kTwin.begin(), kTwin.end());
    granmem_ok(sim);
  }
  std::vector<std::string> calibrate(const std::vector<std::string>& extra,
                                     std::vector<std::string> twin = kTwin) const {
    std::vector<std::string> a{"calibrate", "--experiment", "exp.h5", "--out", "cal"};
    a.insert(a.end(), twin.begin(), twin.end());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

TEST_F(Calibrate, RefusesBadInput) {
  expect_clean_failure(calibrate({"--mu-s", ""}), {"--mu-s", "empty"});
  expect_clean_failure(calibrate({"--mu-s", "0.1,0.2"}), {"--mu-s", "needs at least"});
  expect_clean_failure(calibrate({"--window", "2:9"}), {"exp.h5", "window 2:9", "cycles 0 to 3"});
  std::vector<std::string> other = kTwin;
  other[7] = "3%";  // the amplitude
  expect_clean_failure(calibrate({}, other), {"exp.h5", "amplitude 5%", "twin has 3%"});
  expect_clean_failure(calibrate({"--noise", "fit"}), {"--noise", "voxel size"});
}

TEST_F(Calibrate, WritesTheFitItsIntervalAndFigures) {
  const RunResult r = granmem_ok(calibrate({"--window", "1:3", "--mu-s", "0.05,0.1,0.2,0.4"}));
  EXPECT_NE(r.out.find("mu_s = "), std::string::npos) << r.out;
  std::ifstream in(in_work("cal/summary.json"));
  std::stringstream text;
  text << in.rdbuf();
  const std::string json = text.str();
  for (const char* key : {"\"mu_s\"", "\"mu_s_ci95\"", "\"n_simulations\": 9", "\"replicas\": 2",
                          "ks_dr", "wasserstein1_dr", "\"settings\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
  }
  // mu_s lies inside its interval, and inside the simulated range; the true 0.2 inside the
  // interval, made from the twin's scatter across its two packings.
  double mu = 0, lo = 0, hi = 0;
  std::sscanf(json.substr(json.find("\"mu_s\":")).c_str(), "\"mu_s\": %lf", &mu);
  std::sscanf(json.substr(json.find("\"mu_s_ci95\":")).c_str(), "\"mu_s_ci95\": [%lf, %lf]", &lo,
              &hi);
  EXPECT_LE(lo, mu);
  EXPECT_LE(mu, hi);
  EXPECT_GE(mu, 0.05);
  EXPECT_LE(mu, 0.4);
  EXPECT_LE(lo, 0.2);
  EXPECT_GE(hi, 0.2);
  EXPECT_NE(json.find("cross-validated across packings"), std::string::npos) << json;
  for (const char* f :
       {"cal/pdf_displacement.png", "cal/pdf_displacement.svg", "cal/field_translation.png",
        "cal/calibration.png", "cal/runs.csv", "cal/distances.csv", "cal/pdf_rotation_axes.png"}) {
    EXPECT_TRUE(std::filesystem::exists(in_work(f))) << f;
  }
  // Run again: the runs are reused, the answer is the same.
  const RunResult again = granmem_ok(calibrate({"--window", "1:3", "--mu-s", "0.05,0.1,0.2,0.4"}));
  EXPECT_NE(again.err.find("reusing"), std::string::npos);
  auto fit_line = [](const std::string& out) {
    const std::string from = out.substr(out.find("mu_s = "));
    return from.substr(0, from.find('\n'));
  };
  EXPECT_EQ(fit_line(again.out), fit_line(r.out));
}

TEST_F(Calibrate, CompareTwoRuns) {
  std::vector<std::string> sim{"simulate", "--cycles", "3",        "--seed",    "3", "--mu-s",
                               "0.4",      "--out",    "other.h5", "--threads", "1"};
  sim.insert(sim.end(), kTwin.begin(), kTwin.end());
  granmem_ok(sim);
  granmem_ok({"compare", "exp.h5", "other.h5", "--out", "cmp", "--window", "1:3"});
  std::ifstream in(in_work("cmp/distances.csv"));
  std::string line;
  int rows = 0;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#') ++rows;
  EXPECT_EQ(rows, 3);  // header, dr, rot_disp
  EXPECT_TRUE(std::filesystem::exists(in_work("cmp/pdf_displacement.png")));
  expect_clean_failure({"compare", "exp.h5", "other.h5", "--out", "cmp2", "--window", "1:7"},
                       {"window 1:7", "cycles 0 to 3"});
}

}  // namespace
}  // namespace granmem::testing
