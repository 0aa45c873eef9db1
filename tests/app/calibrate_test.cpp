#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "granmem/core/trajectory_store.hpp"
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
    // Two packings, half the steady-state default's runs: enough for what these test.
    if (std::find(extra.begin(), extra.end(), "--replicas") == extra.end())
      a.insert(a.end(), {"--replicas", "2"});
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  }
};

double json_value(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 3, nullptr);
}

// summary.json's mu_s lies inside its interval and the simulated range 0.05-0.4; returns
// the interval.
std::array<double, 2> expect_fit_in_its_interval(const std::string& json) {
  const double mu = json_value(json, "mu_s");
  double lo = 0, hi = 0;
  std::sscanf(json.substr(json.find("\"mu_s_ci95\":")).c_str(), "\"mu_s_ci95\": [%lf, %lf]", &lo,
              &hi);
  EXPECT_LE(lo, mu);
  EXPECT_LE(mu, hi);
  EXPECT_GE(mu, 0.05);
  EXPECT_LE(mu, 0.4);
  return {lo, hi};
}

// A fit compared with the experiment: at the twin's run nearest the fit where one lies inside
// its interval (said, no simulation more), else at a run more, at the fit.
void expect_compared_at_a_run_inside(const std::string& json, const std::string& report,
                                     int design_runs) {
  const auto [lo, hi] = expect_fit_in_its_interval(json);
  bool inside = false;
  std::istringstream simulated(json.substr(json.find("\"mu_s_simulated\": [") + 19));
  for (double mu = 0; simulated >> mu; simulated.ignore(1))
    inside = inside || (mu >= lo && mu <= hi);
  EXPECT_EQ(json_value(json, "n_simulations"), design_runs + (inside ? 0 : 1)) << report;
  EXPECT_EQ(report.find("compared at the twin's run nearest the fit") != std::string::npos, inside)
      << report;
}

TEST_F(Calibrate, RefusesBadInput) {
  expect_clean_failure(calibrate({"--mu-s", ""}), {"--mu-s", "empty"});
  expect_clean_failure(calibrate({"--mu-s", "0.1,0.2"}), {"--mu-s", "needs at least"});
  expect_clean_failure(calibrate({"--window", "2:9"}), {"exp.h5", "window 2:9", "cycles 0 to 3"});
  std::vector<std::string> other = kTwin;
  other[7] = "3%";  // the amplitude
  expect_clean_failure(calibrate({}, other), {"exp.h5", "amplitude 5%", "twin has 3%"});
  expect_clean_failure(calibrate({"--noise", "fit", "--observables", "displacements"}),
                       {"--noise", "voxel size"});
  expect_clean_failure(calibrate({"--fit-only", "--observables", "displacements"}),
                       {"--fit-only", "steady-state"});
  // What only the displacements' fit reads is refused under the default, not ignored.
  expect_clean_failure(calibrate({"--summaries", "per-cycle"}),
                       {"--summaries per-cycle", "--observables displacements"});
  expect_clean_failure(calibrate({"--noise", "0.05"}),
                       {"--noise 0.05", "--observables displacements"});
  // A config's [simulate] is the caller's: checked against the store, not replaced by it.
  write_text(in_work("grains.toml"), "[simulate]\ngrains = \"50\"\n");
  std::vector<std::string> configured = calibrate({}, {});
  configured.insert(configured.begin(), {"--config", "grains.toml"});
  expect_clean_failure(configured, {"exp.h5", "--grains 60", "the twin has 50"});
  expect_clean_failure(calibrate({"--window", "auto", "--observables", "displacements"}),
                       {"--window auto", "steady-state"});
  expect_clean_failure(
      calibrate({"--window", "auto", "--observables", "steady-state", "--replicas", "1"}),
      {"--window auto", "--replicas 2"});
}

TEST_F(Calibrate, WritesTheFitItsIntervalAndFigures) {
  const std::vector<std::string> fit{"--window",         "1:3",           "--mu-s",
                                     "0.05,0.1,0.2,0.4", "--observables", "displacements"};
  const RunResult r = granmem_ok(calibrate(fit));
  EXPECT_NE(r.out.find("mu_s = "), std::string::npos) << r.out;
  const std::string json = read_text(in_work("cal/summary.json"));
  for (const char* key : {"\"mu_s\"", "\"mu_s_ci95\"", "\"n_simulations\": 9", "\"replicas\": 2",
                          "ks_dr", "wasserstein1_dr", "\"settings\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
  }
  // The true 0.2 inside the interval, made from the twin's scatter across its two packings.
  const auto [lo, hi] = expect_fit_in_its_interval(json);
  EXPECT_LE(lo, 0.2);
  EXPECT_GE(hi, 0.2);
  EXPECT_NE(json.find("cross-validated across packings"), std::string::npos) << json;
  for (const char* f :
       {"cal/pdf_displacement.png", "cal/pdf_displacement.svg", "cal/field_translation.png",
        "cal/calibration.png", "cal/runs.csv", "cal/distances.csv", "cal/pdf_rotation_axes.png"}) {
    EXPECT_TRUE(std::filesystem::exists(in_work(f))) << f;
  }
  // Run again: the runs are reused, the answer is the same.
  const RunResult again = granmem_ok(calibrate(fit));
  EXPECT_NE(again.err.find("reusing"), std::string::npos);
  auto fit_line = [](const std::string& out) {
    const std::string from = out.substr(out.find("mu_s = "));
    return from.substr(0, from.find('\n'));
  };
  EXPECT_EQ(fit_line(again.out), fit_line(r.out));
}

// The steady-state fit: the pseudo-experiment's wall force is used beside the observables
// from positions (the packing's height standing for its lid's), its true friction is
// reported, the figure drawn.
TEST_F(Calibrate, FitsOnSteadyStateObservables) {
  const RunResult r = granmem_ok(calibrate({"--window", "2:3", "--mu-s", "0.05,0.1,0.2,0.4",
                                            "--observables", "steady-state", "--fit-only"}));
  EXPECT_NE(r.out.find("true 0.2"), std::string::npos) << r.out;
  const std::string json = read_text(in_work("cal/summary.json"));
  for (const char* key : {"\"height_packing_fraction\"", "\"wall_force_full_compression\"",
                          "\"n_simulations\": 8", "\"settings\""}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
  }
  EXPECT_DOUBLE_EQ(json_value(json, "mu_s_true"), 0.2);
  expect_fit_in_its_interval(json);
  for (const char* f : {"cal/observable_fit.png", "cal/observable_fit.svg",
                        "cal/observable_fit.dat", "cal/steady_state_runs.csv"}) {
    EXPECT_TRUE(std::filesystem::exists(in_work(f))) << f;
  }
  // The window from the runs themselves: three cycles after the deposit are no steady state
  // at this size, and it says so. The runs it chooses from start before the first cycle
  // (the window is not known before them), not after the given window's cycle 1.
  const RunResult chosen = granmem_ok(calibrate({"--window", "auto", "--mu-s", "0.05,0.1,0.2,0.4",
                                                 "--observables", "steady-state", "--fit-only"}));
  EXPECT_NE(chosen.err.find("cycles 1-3 (window 1:3), mu_s 0.05,0.1,0.2,0.4"), std::string::npos)
      << chosen.err;
  EXPECT_NE(chosen.err.find("placed where the experiment's frame of cycle 0"), std::string::npos)
      << chosen.err;
  EXPECT_EQ(chosen.err.find("reusing"), std::string::npos) << chosen.err;
  EXPECT_NE(chosen.out.find("window from the twin's runs: cycles "), std::string::npos)
      << chosen.out;
  expect_fit_in_its_interval(read_text(in_work("cal/summary.json")));
  // A scan has no lid: asked by name for what the experiment lacks is one clear error.
  expect_clean_failure(calibrate({"--window", "2:3", "--mu-s", "0.05,0.1,0.2,0.4", "--observables",
                                  "steady-state", "--only", "lid_angle"}),
                       {"--only", "lid_angle", "not measured", "exp.h5"});
  // A scan's axis error added to the twin's axes (the same runs): the experiment's own
  // rotation is measured as it is; the twin's rotations grow.
  granmem_ok(calibrate({"--window", "2:3", "--mu-s", "0.05,0.1,0.2,0.4", "--observables",
                        "steady-state", "--fit-only"}));
  const std::string exact = read_text(in_work("cal/summary.json"));
  granmem_ok(calibrate({"--window", "2:3", "--mu-s", "0.05,0.1,0.2,0.4", "--observables",
                        "steady-state", "--fit-only", "--axis-noise", "2"}));
  const std::string noisy = read_text(in_work("cal/summary.json"));
  EXPECT_DOUBLE_EQ(json_value(noisy, "axis_noise_deg"), 2);
  const auto rotation = [](const std::string& json, const char* key) {
    const std::size_t at = json.find("\"rot_disp\"");
    return json_value(json.substr(at), key);
  };
  EXPECT_DOUBLE_EQ(rotation(noisy, "experiment"), rotation(exact, "experiment"));
  EXPECT_GT(rotation(noisy, "model_at_fit"), rotation(exact, "model_at_fit"));
  expect_clean_failure(calibrate({"--mu-s", "0.05,0.1,0.2,0.4", "--axis-noise", "1",
                                  "--observables", "displacements"}),
                       {"--axis-noise", "steady-state"});
  expect_clean_failure(calibrate({"--mu-s", "0.05,0.1,0.2,0.4", "--observables", "steady-state",
                                  "--axis-noise", "-1"}),
                       {"--axis-noise", ">= 0"});
  // The truth given for a pseudo-experiment whose store says another.
  expect_clean_failure(calibrate({"--mu-s", "0.05,0.1,0.2,0.4", "--observables", "steady-state",
                                  "--true-mu-s", "0.3"}),
                       {"--true-mu-s 0.3", "the experiment's store says 0.2"});
  expect_clean_failure(calibrate({"--mu-s", "0.05,0.1,0.2,0.4", "--observables", "steady-state",
                                  "--true-mu-s", "0.1,0.2"}),
                       {"--true-mu-s", "one friction"});
  expect_clean_failure(calibrate({"--mu-s", "0.05,0.1,0.2,0.4", "--true-mu-s", "0.2",
                                  "--observables", "displacements"}),
                       {"--true-mu-s", "steady-state"});
  expect_clean_failure(calibrate({"--mu-s", "0.05,0.1,0.2,0.4", "--observables", "steady-state",
                                  "--true-mu-r", "0.01"}),
                       {"--true-mu-r", "--fit mu_s,mu_r"});
}

// A twin that stops short of the experiment's friction holds the fit at its edge: said, with
// what to simulate.
TEST_F(Calibrate, SaysWhenTheFitIsAtTheDesignsEdge) {
  // A straight trend (--degree 1): its misfit falls all the way to the edge.
  const RunResult r =
      granmem_ok(calibrate({"--window", "2:3", "--mu-s", "0.02,0.03,0.05", "--degree", "1",
                            "--observables", "steady-state", "--fit-only"}));
  const std::string json = read_text(in_work("cal/summary.json"));
  if (json_value(json, "mu_s") > 0.05 / 1.01) {
    EXPECT_NE(r.out.find("the fit is at the twin's highest mu_s, 0.05: the experiment's may lie "
                         "beyond it; simulate past it (--mu-s with 0.1)"),
              std::string::npos)
        << r.out;
  } else {
    ADD_FAILURE() << "the true 0.2 fitted inside 0.02-0.05: " << r.out;
  }
}

// --noise scans: the locating noise is the scans' own, the RMS of the position standard
// errors in the store, not fitted. The pseudo-experiment as scans of 0.1 mm voxels (0.15
// along z) would store it: each centre known to 0.05, 0.05 and 0.075 mm (half a voxel).
TEST_F(Calibrate, TakesTheLocatingNoiseFromTheScansStandardErrors) {
  Trajectories run = read_trajectories(in_work("exp.h5"));
  run.header.voxel_size = Eigen::Vector3d(1e-4, 1e-4, 1.5e-4);
  run.header.has_position_error = true;
  for (Frame& f : run.frames)
    f.position_error = Eigen::RowVector3d(5e-5, 5e-5, 7.5e-5).replicate(f.position.rows(), 1);
  write_trajectories(in_work("scans.h5"), run);
  std::vector<std::string> a{
      "calibrate", "--experiment",     "scans.h5", "--out", "cal",           "--window",     "1:3",
      "--mu-s",    "0.05,0.1,0.2,0.4", "--noise",  "scans", "--observables", "displacements"};
  a.insert(a.end(), kTwin.begin(), kTwin.end());
  granmem_ok(a);
  const std::string json = read_text(in_work("cal/summary.json"));
  EXPECT_NE(json.find("\"noise_model\": \"scans\""), std::string::npos) << json;
  EXPECT_NEAR(json_value(json, "noise_sigma_voxel"), 0.5, 1e-12);
  EXPECT_EQ(json_value(json, "noise_sigma_error"), 0);  // given, not fitted
  // auto takes them too where the store has them (the same runs, reused).
  std::vector<std::string> automatic{
      "calibrate", "--experiment", "scans.h5",         "--out",         "cal",          "--window",
      "1:3",       "--mu-s",       "0.05,0.1,0.2,0.4", "--observables", "displacements"};
  automatic.insert(automatic.end(), kTwin.begin(), kTwin.end());
  granmem_ok(automatic);
  const std::string json_auto = read_text(in_work("cal/summary.json"));
  EXPECT_NE(json_auto.find("\"noise_model\": \"scans\""), std::string::npos) << json_auto;
  EXPECT_NEAR(json_value(json_auto, "noise_sigma_voxel"), 0.5, 1e-12);
  // A store without them: one clear error.
  expect_clean_failure(calibrate({"--window", "1:3", "--mu-s", "0.05,0.1,0.2,0.4", "--noise",
                                  "scans", "--observables", "displacements"}),
                       {"--noise scans", "no position standard errors"});
}

// --refine: the design's fit, then packings of new seeds about it, and the fit again on all
// runs, their held-out runs at the refined frictions counted in the cross-validation.
TEST_F(Calibrate, RefinesTheDesignWithNewPackingsAboutItsFit) {
  expect_clean_failure(
      calibrate({"--refine", "2", "--mu-s", "0.05,0.1,0.4", "--observables", "displacements"}),
      {"--refine", "steady-state"});
  const std::vector<std::string> design{
      "--window", "2:3", "--mu-s", "0.05,0.1,0.4", "--observables", "steady-state", "--fit-only"};
  const RunResult first = granmem_ok(calibrate(design));
  std::vector<std::string> refined = design;
  refined.insert(refined.end(), {"--refine", "2"});
  const RunResult r = granmem_ok(calibrate(refined));
  EXPECT_NE(r.err.find("reusing 6 finished runs"), std::string::npos) << r.err;
  const std::string json = read_text(in_work("cal/summary.json"));
  expect_fit_in_its_interval(json);
  // The design's fit is the fit of the call without --refine, to the digits printed.
  const std::string design_fit = first.out.substr(first.out.find("mu_s = ") + 7, 5);
  EXPECT_NE(r.out.find("the design's fit: mu_s = " + design_fit), std::string::npos)
      << first.out << r.out;
  // Placed from the simulation's frame: one a factor 1.15 below the fit, one above (each at
  // most halfway in ln mu_s to the design's end beyond it).
  const std::size_t from = r.out.find("packing(s) more at mu_s ") + 24;
  const std::size_t comma = r.out.find(", ", from);
  const std::string below = r.out.substr(from, comma - from);
  const std::string above = r.out.substr(comma + 2, r.out.find(", seeds", from) - comma - 2);
  const double fit = std::stod(design_fit);
  EXPECT_LT(std::stod(below), fit);
  EXPECT_GE(std::stod(below), fit / 1.15 - 0.0051);
  EXPECT_GT(std::stod(above), fit);
  EXPECT_LE(std::stod(above), fit * 1.15 + 0.0051);
  EXPECT_NE(r.out.find("seeds 3-4"), std::string::npos) << r.out;
  EXPECT_NE(json.find("\"n_simulations\": 8"), std::string::npos) << json;
  for (const std::string& run :
       {"cal/runs/mu_s_" + below + "_seed_3.h5", "cal/runs/mu_s_" + above + "_seed_4.h5"})
    EXPECT_TRUE(std::filesystem::exists(in_work(run))) << run;
  // Both new packings are interior runs of the cross-validation, beside the design's two
  // at 0.1.
  EXPECT_NE(r.out.find("from 4 runs"), std::string::npos) << r.out;
  // Packings deposited once per seed (--deposit shared): the added seeds get theirs.
  std::vector<std::string> shared{"calibrate", "--experiment", "exp.h5",     "--out", "shared",
                                  "--deposit", "shared",       "--replicas", "2"};
  shared.insert(shared.end(), kTwin.begin(), kTwin.end());
  shared.insert(shared.end(), refined.begin(), refined.end());
  const RunResult from_shared = granmem_ok(shared);
  EXPECT_NE(from_shared.out.find("8 simulations"), std::string::npos) << from_shared.out;
  EXPECT_TRUE(std::filesystem::exists(in_work("shared/packing_seed_4.checkpoint.h5")));
}

// The "name": value pairs of summary.json's object under `key` (one level, numbers only).
std::map<std::string, double> json_numbers_under(const std::string& json, const std::string& key) {
  std::map<std::string, double> values;
  const auto at = json.find("\"" + key + "\":");
  if (at == std::string::npos) return values;
  const auto open = json.find('{', at), close = json.find('}', open);
  if (open == std::string::npos || close == std::string::npos) return values;
  for (auto q = json.find('"', open); q < close; q = json.find('"', json.find(',', q))) {
    const auto end = json.find('"', q + 1);
    if (end == std::string::npos || end + 2 >= json.size()) break;
    values[json.substr(q + 1, end - q - 1)] = std::strtod(json.c_str() + end + 2, nullptr);
    if (json.find(',', q) > close) break;
  }
  return values;
}

// --deposit experiment: every run starts from the experiment's own packing, the grains of
// its frame before the window jittered by the run's seed and settled at the run's friction,
// and drives the cycles after it: at the true friction the twin starts where the experiment
// stands, its pour's scatter gone. The default (auto) does so for a simulation's packing
// and for fine scans that locate nearly every grain, and pours for other scans.
TEST_F(Calibrate, StartsTheTwinFromTheExperimentsOwnPacking) {
  const std::vector<std::string> design{"--window",      "2:3",          "--mu-s",    "0.1,0.2,0.4",
                                        "--observables", "steady-state", "--fit-only"};
  const RunResult r = granmem_ok(calibrate(design));
  EXPECT_NE(r.err.find("cycles 2-3 (window 2:3)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("placed where the experiment's frame of cycle 1 has its 60 grains, moved "
                       "by 0.0005 mm RMS"),
            std::string::npos)
      << r.err;
  const std::string json = read_text(in_work("cal/summary.json"));
  EXPECT_NE(json.find("\"deposit\": \"experiment\""), std::string::npos) << json;
  EXPECT_EQ(json_value(json, "placed_cycle"), 1) << json;
  expect_fit_in_its_interval(json);
  // The placed packing read back at its frame, over every packing at the friction nearest the
  // fit, less the experiment's: carried as the experiment's systematic errors, their share of
  // the fit's error said.
  EXPECT_NE(r.out.find("carried as the experiment's systematic errors"), std::string::npos)
      << r.out;
  EXPECT_EQ(json_value(json, "placed_frame_runs"), 2) << json;
  EXPECT_GT(json_value(json, "systematic_sigma"), 0) << json;
  EXPECT_LE(json_value(json, "systematic_sigma"), json_value(json, "gls_sigma")) << json;
  // Where the runs start, the packing's height: the twin's placed packings at the true
  // friction against the experiment's there (after cycle 1, numbered so), and poured
  // packings against the experiment's before its first cycle.
  const double d = 0.005;
  auto height_at = [](const std::string& file, std::int64_t cycle) {
    const Observable lid = TrajectoryReader(file).observables().at("lid_height");
    const auto at = std::find(lid.step.begin(), lid.step.end(), cycle);
    return at == lid.step.end() ? std::nan("") : lid.value[std::size_t(at - lid.step.begin())];
  };
  for (const char* seed : {"1", "2"}) {
    const std::string run = in_work(std::string("cal/runs/mu_s_0.2_seed_") + seed + ".h5");
    EXPECT_EQ(TrajectoryReader(run).steps().front(), 1) << run;
    EXPECT_NEAR(height_at(run, 1), height_at(in_work("exp.h5"), 1), 0.01 * d) << run;
  }
  // From the packing before the first cycle (--placed-cycle 0): the runs drive cycles 1-3,
  // other runs than those placed after cycle 1.
  std::vector<std::string> from_start = calibrate(design);
  from_start[4] = "start";
  from_start.insert(from_start.end(), {"--placed-cycle", "0"});
  const RunResult started = granmem_ok(from_start);
  EXPECT_NE(started.err.find("cycles 1-3 (window 2:3)"), std::string::npos) << started.err;
  const std::string started_run = in_work("start/runs/mu_s_0.2_seed_1.h5");
  EXPECT_EQ(TrajectoryReader(started_run).steps().front(), 0);
  EXPECT_NEAR(height_at(started_run, 0), height_at(in_work("exp.h5"), 0), 0.01 * d);
  // Placed before the frame before the window, the twin and the experiment share their start
  // there: the packing's height at that frame is compared too, and the runs at the true
  // friction read the experiment's far nearer than those at half or twice it. Placed from
  // that frame itself (the design above), it is not compared.
  const std::string before = "height_packing_fraction_before_window";
  const double experiment_before =
      json_numbers_under(read_text(in_work("start/summary.json")), before).at("experiment");
  const Table runs = read_columns(in_work("start/steady_state_runs.csv"), {"mu_s", before});
  double off_at_truth = 0, off_elsewhere = 1;
  for (std::size_t k = 0; k < runs["mu_s"].values.size(); ++k) {
    const double off = std::abs(runs[before].values[k] - experiment_before);
    if (runs["mu_s"].values[k] == 0.2)
      off_at_truth = std::max(off_at_truth, off);
    else
      off_elsewhere = std::min(off_elsewhere, off);
  }
  EXPECT_LT(off_at_truth, 0.2 * off_elsewhere) << off_at_truth << " " << off_elsewhere;
  EXPECT_EQ(csv_header(in_work("cal/steady_state_runs.csv")).find(before), std::string::npos);
  from_start.back() = "2";
  expect_clean_failure(from_start, {"--placed-cycle 2", "before the window"});
  from_start.back() = "first";
  expect_clean_failure(from_start, {"--placed-cycle 'first'", "a cycle, 0 or later"});
  expect_clean_failure(
      calibrate({"--window", "auto", "--mu-s", "0.1,0.2,0.4", "--fit-only", "--placed-cycle", "0"}),
      {"--placed-cycle", "not with --window auto"});
  // Placed runs are reused only for the same packing placed the same way.
  std::vector<std::string> again = design;
  EXPECT_NE(granmem_ok(calibrate(again)).err.find("reusing 6 finished runs"), std::string::npos);
  // Compared with the experiment: the truth, 0.2, is a run of this design.
  again.erase(std::find(again.begin(), again.end(), "--fit-only"));
  const RunResult compared_design = granmem_ok(calibrate(again));
  expect_compared_at_a_run_inside(read_text(in_work("cal/summary.json")), compared_design.out, 6);
  // No relaxation fitted to the twin's run: it relaxes from its placing.
  EXPECT_NE((compared_design.out + compared_design.err)
                .find(": placed after cycle 1, it relaxes from there, not from a preparation"),
            std::string::npos)
      << compared_design.err;
  again.push_back("--fit-only");
  again.insert(again.end(), {"--placed-jitter", "1um"});
  EXPECT_EQ(granmem_ok(calibrate(again)).err.find("reusing"), std::string::npos);
  again.back() = "0um";
  expect_clean_failure(calibrate(again), {"--placed-jitter", "> 0"});
  // The design left out: a placed twin's own, 2 packings x 0.05, 0.13, 0.35, 0.6, then 4
  // packings of new seeds where those 8 fit (unless at the range's edge). The protocol left
  // out too (the default observables, the steady state's): the pseudo-experiment's own.
  std::vector<std::string> staged{"calibrate", "--experiment", "exp.h5", "--out",
                                  "staged",    "--window",     "2:3",    "--fit-only"};
  const RunResult own = granmem_ok(staged);
  EXPECT_NE(own.err.find("the twin's protocol from the experiment's store: --grains 60, --box "
                         "2cm, --amplitude 5%, --lid-mass 0.2kg, --period 0.1s"),
            std::string::npos)
      << own.err;
  EXPECT_NE(own.err.find("mu_s 0.05,0.13,0.35,0.6, 2 packing(s) from seed 1, then 4 more"),
            std::string::npos)
      << own.err;
  EXPECT_NE(own.out.find("the design's fit: mu_s = "), std::string::npos) << own.out;
  EXPECT_NE(own.out.find(", 8 runs; "), std::string::npos) << own.out;
  // Either way the design is placed and its count said (a 60-grain twin fits well inside).
  const bool refined = own.out.find("4 packing(s) more at mu_s ") != std::string::npos;
  EXPECT_TRUE(refined || own.out.find("not refined") != std::string::npos) << own.out;
  if (refined) {
    EXPECT_NE(own.out.find(", seeds 3-6"), std::string::npos) << own.out;
  }
  const std::string staged_json = read_text(in_work("staged/summary.json"));
  EXPECT_EQ(json_value(staged_json, "n_simulations"), refined ? 12 : 8) << own.out;
  EXPECT_EQ(json_value(staged_json, "refined"), refined ? 4 : 0) << staged_json;
  // Compared with the experiment (no --fit-only): at a refined packing where one lies inside
  // the interval, no simulation more; else at the fit, one more.
  staged.erase(std::find(staged.begin(), staged.end(), "--fit-only"));
  const RunResult compared = granmem_ok(staged);
  const std::string compared_json = read_text(in_work("staged/summary.json"));
  expect_compared_at_a_run_inside(compared_json, compared.out, refined ? 12 : 8);
  std::vector<std::string> poured = design;
  poured.insert(poured.end(), {"--deposit", "each"});
  granmem_ok(calibrate(poured));  // the same folder: poured runs are other runs, not reused
  double off = 0;
  for (const char* seed : {"1", "2"}) {
    const std::string run = in_work(std::string("cal/runs/mu_s_0.2_seed_") + seed + ".h5");
    off = std::max(off, std::abs(height_at(run, 0) - height_at(in_work("exp.h5"), 0)));
  }
  EXPECT_GT(off, 0.05 * d);
  // Scans' centres carry their errors: the default pours, and placing is said to lean.
  Trajectories scans = read_trajectories(in_work("exp.h5"));
  scans.header.has_position_error = true;
  for (Frame& f : scans.frames)
    f.position_error = Eigen::RowVector3d(2e-5, 2e-5, 3e-5).replicate(f.position.rows(), 1);
  write_trajectories(in_work("scans.h5"), scans);
  std::vector<std::string> from_scans = calibrate(design);
  from_scans[2] = "scans.h5";
  EXPECT_NE(granmem_ok(from_scans).err.find("deposited at each friction"), std::string::npos);
  std::vector<std::string> scans_from = from_scans;
  scans_from.insert(scans_from.end(), {"--placed-cycle", "1"});
  expect_clean_failure(scans_from, {"--placed-cycle 1", "this one is poured"});
  from_scans.insert(from_scans.end(), {"--deposit", "experiment"});
  EXPECT_NE(granmem_ok(from_scans).err.find("lean the fit to higher friction"), std::string::npos);
  // A fine scan (standard errors 0.0006 d) that locates every grain is placed by default from
  // its first frame, the preparation (its centres' errors would undo a drive's training);
  // placed before the window as asked, it is the same packing as the simulation's (its runs
  // reused). One that misses 2 of the 60 grains at its preparation is placed before the
  // window; missing them there too, poured.
  for (Frame& f : scans.frames)
    f.position_error.setConstant(0.0006 * d);
  write_trajectories(in_work("fine.h5"), scans);
  std::vector<std::string> fine = calibrate(design);
  fine[2] = "fine.h5";
  fine[4] = "fine";
  const RunResult placed_fine = granmem_ok(fine);
  EXPECT_NE(placed_fine.err.find("placed where the experiment's frame of cycle 0 has its 60"),
            std::string::npos)
      << placed_fine.err;
  std::vector<std::string> fine_before = calibrate(design);
  fine_before[2] = "fine.h5";
  fine_before.insert(fine_before.end(), {"--placed-cycle", "1"});
  EXPECT_NE(granmem_ok(fine_before).err.find("reusing 6 finished runs"), std::string::npos);
  for (Frame& f : scans.frames)
    if (f.step == 0) f.position.topRows(2).setConstant(std::nan(""));
  write_trajectories(in_work("missed.h5"), scans);
  fine[2] = "missed.h5";
  fine[4] = "missed";
  EXPECT_NE(granmem_ok(fine).err.find("placed where the experiment's frame of cycle 1 has its 60"),
            std::string::npos);
  for (Frame& f : scans.frames)
    if (f.step == 1) f.position.topRows(2).setConstant(std::nan(""));
  write_trajectories(in_work("missed.h5"), scans);
  fine[4] = "missed_twice";
  EXPECT_NE(granmem_ok(fine).err.find("deposited at each friction"), std::string::npos);
  // A store whose first frame is after cycle 1, not the packing before the first cycle: the
  // default places it (it precedes the window); placed from cycle 0, refused.
  Trajectories later = read_trajectories(in_work("exp.h5"));
  later.frames.erase(later.frames.begin());
  write_trajectories(in_work("later.h5"), later);
  std::vector<std::string> from_later = calibrate(design);
  from_later[2] = "later.h5";
  EXPECT_NE(granmem_ok(from_later).err.find("placed where the experiment's frame of cycle 1"),
            std::string::npos);
  from_later.insert(from_later.end(), {"--deposit", "experiment", "--placed-cycle", "0"});
  expect_clean_failure(from_later, {"later.h5", "--deposit experiment", "frame of cycle 0",
                                    "(--placed-cycle)", "has none"});
}

// Placed from scans (a fine scan's frame, which carries its locating errors) after the drive
// began, the first refined packing is placed once more from its own frame moved by the scans'
// error: the placement probe, one of the refined simulations. What it does to the window is
// carried as the experiment's systematic error (each observable's at least the probe's), and
// a second call reuses it; a simulation's exact frame needs no probe, nor scans placed from
// their preparation, which the drive has not trained.
// --one-cycle-ahead: after the design's fit, one packing more at four frictions about it,
// placed anew from the experiment's frame before each cycle of the window and driven that
// cycle; the fit is the mean of the cycles' own, and holds the truth.
// One cycle ahead's packing in `runs`: its 4 frictions (seed 3), each run from the
// experiment's frame of cycle `from` to cycle `to`.
void expect_ahead_runs(const std::filesystem::path& runs, std::int64_t from, std::int64_t to) {
  int found = 0;
  for (const auto& e : std::filesystem::directory_iterator(runs)) {
    if (e.path().extension() != ".h5") continue;
    ++found;
    const TrajectoryReader run(e.path().string());
    EXPECT_EQ(run.steps().front(), from) << e.path();
    EXPECT_EQ(run.steps().back(), to) << e.path();
    EXPECT_NE(e.path().filename().string().find("_seed_3.h5"), std::string::npos) << e.path();
  }
  EXPECT_EQ(found, 4) << runs;
}

TEST_F(Calibrate, FitsOneCycleAheadFromEveryCyclesFrame) {
  const std::vector<std::string> design{
      "--window", "1:3", "--mu-s", "0.1,0.2,0.4", "--one-cycle-ahead", "--ahead-burn-in", "0"};
  const RunResult r = granmem_ok(calibrate(design));
  EXPECT_NE(r.out.find("one cycle ahead: a packing more (seed 3) at mu_s "), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("3 cycles' own fits (cycle: mu_s): 1: "), std::string::npos) << r.out;
  const std::string json = read_text(in_work("cal/summary.json"));
  const auto [lo, hi] = expect_fit_in_its_interval(json);
  EXPECT_LE(lo, 0.2) << json;
  EXPECT_GE(hi, 0.2) << json;
  EXPECT_EQ(json_value(json, "n_simulations"), 6 + 4) << json;
  EXPECT_NE(json.find("\"one_cycle_ahead\": true"), std::string::npos) << json;
  EXPECT_NE(json.find("\"cycle_log_mu_s_sigma\""), std::string::npos) << json;
  // The figures: each cycle's fit, and the runs less the experiment's at each cycle's end.
  for (const char* figure : {"one_cycle_ahead_cycles", "one_cycle_ahead_fit"}) {
    for (const char* ext : {".png", ".dat", ".gp"})
      EXPECT_TRUE(std::filesystem::exists(in_work("cal/" + std::string(figure) + ext))) << figure;
  }
  // Each cycle's runs start from the experiment's frame before it, and drive that cycle only.
  for (std::int64_t c = 1; c <= 3; ++c)
    expect_ahead_runs(in_work("cal/ahead/cycle_" + std::to_string(c) + "/runs"), c - 1, c);
  // A second call reuses every run.
  const RunResult again = granmem_ok(calibrate(design));
  EXPECT_EQ(again.err.find(" runs, "), std::string::npos) << again.err;
  EXPECT_EQ(read_text(in_work("cal/summary.json")), json);
  // Refused before any run: too short a window, a refined design, a joint fit, a poured twin.
  std::vector<std::string> bad =
      calibrate({"--window", "2:3", "--mu-s", "0.1,0.2,0.4", "--one-cycle-ahead"});
  expect_clean_failure(bad, {"--one-cycle-ahead", "at least 3 cycles"});
  bad = calibrate(design);
  bad.insert(bad.end(), {"--refine", "2"});
  expect_clean_failure(bad, {"--one-cycle-ahead", "not with --refine"});
  bad = calibrate(design);
  bad.insert(bad.end(), {"--deposit", "each"});
  expect_clean_failure(bad, {"--one-cycle-ahead", "placed from the experiment's packing"});
  // Cycle 1 would need a frame of cycle -1.
  bad = calibrate({"--window", "1:3", "--mu-s", "0.1,0.2,0.4", "--one-cycle-ahead"});
  expect_clean_failure(bad, {"--one-cycle-ahead", "2 of the window's cycles 1-3"});
  bad = calibrate({"--window", "1:3", "--mu-s", "0.1,0.2,0.4", "--ahead-burn-in", "-1"});
  expect_clean_failure(bad, {"--ahead-burn-in", "0 or more"});
}

// Left to it, calibrate fits one cycle ahead where the experiment has every cycle's frame over
// a window of 5 or more: each run placed from the frame two cycles before the one compared
// (its contacts' history loaded again by the first), the window fit where asked.
TEST_F(Calibrate, FitsOneCycleAheadByDefaultAfterABurnInCycle) {
  std::vector<std::string> sim{"simulate", "--cycles", "6",       "--seed",    "8", "--mu-s",
                               "0.2",      "--out",    "exp6.h5", "--threads", "1"};
  sim.insert(sim.end(), kTwin.begin(), kTwin.end());
  granmem_ok(sim);
  std::vector<std::string> args = calibrate({"--mu-s", "0.1,0.2,0.4"});
  args[2] = "exp6.h5";
  const RunResult r = granmem_ok(args);
  // The default window is cycles 1-6; cycle 1 has no frame two cycles before it.
  EXPECT_NE(r.out.find("5 cycles' own fits (cycle: mu_s): 2: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("driven 2 cycles, the last compared"), std::string::npos) << r.out;
  const std::string json = read_text(in_work("cal/summary.json"));
  const auto [lo, hi] = expect_fit_in_its_interval(json);
  EXPECT_LE(lo, 0.2) << json;
  EXPECT_GE(hi, 0.2) << json;
  EXPECT_EQ(json_value(json, "ahead_burn_in"), 1) << json;
  for (std::int64_t c = 2; c <= 6; ++c) {
    expect_ahead_runs(in_work("cal/ahead/cycle_" + std::to_string(c) + "_from_" +
                              std::to_string(c - 2) + "/runs"),
                      c - 2, c);
  }
  // --window-fit: the design's runs reused, the window's means fitted.
  args.push_back("--window-fit");
  const RunResult window = granmem_ok(args);
  EXPECT_EQ(window.out.find("one cycle ahead"), std::string::npos) << window.out;
  EXPECT_EQ(read_text(in_work("cal/summary.json")).find("\"one_cycle_ahead\""), std::string::npos);
}

TEST_F(Calibrate, ProbesWhatPlacingFromScansDoesToTheTwin) {
  Trajectories scans = read_trajectories(in_work("exp.h5"));
  scans.header.has_position_error = true;
  for (Frame& f : scans.frames)
    f.position_error = Eigen::RowVector3d::Constant(0.0006 * 0.005).replicate(f.position.rows(), 1);
  write_trajectories(in_work("fine.h5"), scans);
  std::vector<std::string> probed =
      calibrate({"--window", "2:3", "--mu-s", "0.1,0.2,0.4", "--refine", "2", "--fit-only",
                 "--placed-cycle", "1"});
  probed[2] = "fine.h5";
  const RunResult r = granmem_ok(probed);
  EXPECT_NE(r.out.find("1 packing(s) more at mu_s "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("and the first placed once more from its own frame moved by the scans' "
                       "error (the placement probe)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("seed 3 placed once more from its frame of cycle 1 moved by the scans' "
                       "error"),
            std::string::npos)
      << r.out;
  const std::string json = read_text(in_work("cal/summary.json"));
  EXPECT_EQ(json_value(json, "n_simulations"), 6 + 1 + 1) << json;
  const std::map<std::string, double> probe = json_numbers_under(json, "less_source");
  ASSERT_FALSE(probe.empty()) << json;
  const std::string fitted = json.substr(json.find("\"observables\":"));
  int checked = 0;
  for (const auto& [name, effect] : probe) {
    const auto at = fitted.find("\"" + name + "\":{");
    if (at == std::string::npos) continue;  // measured, not fitted
    const std::string observable = fitted.substr(at, fitted.find('}', at) - at);
    EXPECT_GE(json_value(observable, "experiment_systematic"), std::abs(effect) * (1 - 1e-9))
        << name << "\n"
        << json;
    ++checked;
  }
  EXPECT_GT(checked, 0) << json;
  EXPECT_NE(granmem_ok(probed).err.find("reusing the placement probe"), std::string::npos);
  // From the simulation's exact frame: both refined packings are packings, no probe.
  const RunResult exact = granmem_ok(
      calibrate({"--window", "2:3", "--mu-s", "0.1,0.2,0.4", "--refine", "2", "--fit-only"}));
  EXPECT_EQ(exact.out.find("placement probe"), std::string::npos) << exact.out;
  EXPECT_NE(exact.out.find("2 packing(s) more at mu_s "), std::string::npos) << exact.out;
  // From the scans' preparation (their first frame, the default): no probe either.
  std::vector<std::string> prepared =
      calibrate({"--window", "2:3", "--mu-s", "0.1,0.2,0.4", "--refine", "2", "--fit-only"});
  prepared[2] = "fine.h5";
  prepared[4] = "prepared";
  const RunResult from_preparation = granmem_ok(prepared);
  EXPECT_EQ(from_preparation.out.find("placement probe"), std::string::npos)
      << from_preparation.out;
  EXPECT_NE(from_preparation.out.find("2 packing(s) more at mu_s "), std::string::npos)
      << from_preparation.out;
  EXPECT_EQ(json_value(read_text(in_work("prepared/summary.json")), "placed_cycle"), 0);
}

TEST_F(Calibrate, FitsMuSAndMuRJointly) {
  expect_clean_failure(
      calibrate({"--fit", "mu_s,mu_r", "--mu-s", "0.05,0.2,0.4", "--observables", "displacements"}),
      {"--fit mu_s,mu_r", "steady-state"});
  expect_clean_failure(
      calibrate({"--fit", "mu_s,mu_r", "--mu-s", "0.05,0.2,0.4", "--observables", "steady-state"}),
      {"--mu-r", "at least 3"});
  const RunResult r = granmem_ok(
      calibrate({"--window", "2:3", "--mu-s", "0.05,0.2,0.4", "--mu-r", "0.005,0.01,0.02", "--fit",
                 "mu_s,mu_r", "--observables", "steady-state", "--replicas", "1", "--fit-only"}));
  EXPECT_NE(r.out.find("mu_r = "), std::string::npos) << r.out;
  const std::string json = read_text(in_work("cal/summary.json"));
  for (const char* key :
       {"\"mu_r_ci95\"", "\"correlation\"", "\"region95\"", "\"n_simulations\": 9"}) {
    EXPECT_NE(json.find(key), std::string::npos) << key << " in " << json;
  }
  const double mu_r = json_value(json, "mu_r"), mu_s = json_value(json, "mu_s");
  EXPECT_GE(mu_r, 0.005 - 1e-12);
  EXPECT_LE(mu_r, 0.02 + 1e-12);
  EXPECT_GE(mu_s, 0.05 - 1e-12);
  EXPECT_LE(mu_s, 0.4 + 1e-12);
  EXPECT_LE(std::abs(json_value(json, "correlation")), 1.0);
  EXPECT_DOUBLE_EQ(json_value(json, "mu_r_true"), 0.01);
  EXPECT_TRUE(std::filesystem::exists(in_work("cal/joint_fit.png")));
  EXPECT_TRUE(std::filesystem::exists(in_work("cal/runs/mu_s_0.2_mu_r_0.005_seed_1.h5")));
  // --refine on this design: its mu_r is the lowest simulated, at the range's edge, so no
  // packing is added there; on a wider range of mu_r two are, at the joint fit.
  auto refine_joint = [&](const std::string& mu_r) {
    return granmem_ok(calibrate({"--window", "2:3", "--mu-s", "0.05,0.2,0.4", "--mu-r", mu_r,
                                 "--fit", "mu_s,mu_r", "--observables", "steady-state",
                                 "--replicas", "1", "--fit-only", "--refine", "2"}));
  };
  const RunResult edge = refine_joint("0.005,0.01,0.02");
  EXPECT_NE(edge.out.find("not refined: the fit is at the edge"), std::string::npos) << edge.out;
  EXPECT_NE(edge.out.find("9 simulations"), std::string::npos) << edge.out;
  const RunResult refined = refine_joint("0.002,0.01,0.03");
  EXPECT_NE(refined.out.find("2 packing(s) more at mu_s "), std::string::npos) << refined.out;
  EXPECT_NE(refined.out.find(", seeds 2-3"), std::string::npos) << refined.out;
  EXPECT_NE(refined.out.find("11 simulations"), std::string::npos) << refined.out;
  // Started from the experiment's own packing: every run placed (2 replicas, each its
  // jitter), and the truth, one of the design's points, inside both intervals.
  std::vector<std::string> placed_fit{"calibrate",
                                      "--experiment",
                                      "exp.h5",
                                      "--out",
                                      "placed",
                                      "--window",
                                      "2:3",
                                      "--mu-s",
                                      "0.05,0.2,0.4",
                                      "--mu-r",
                                      "0.005,0.01,0.02",
                                      "--fit",
                                      "mu_s,mu_r",
                                      "--observables",
                                      "steady-state",
                                      "--replicas",
                                      "2",
                                      "--fit-only",
                                      "--deposit",
                                      "experiment"};
  placed_fit.insert(placed_fit.end(), kTwin.begin(), kTwin.end());
  granmem_ok(placed_fit);
  const std::string placed = read_text(in_work("placed/summary.json"));
  EXPECT_NE(placed.find("\"deposit\": \"experiment\""), std::string::npos) << placed;
  EXPECT_EQ(json_value(placed, "n_simulations"), 18) << placed;
  const auto interval_holds = [&](const char* key, double truth) {
    const std::size_t at = placed.find(std::string("\"") + key + "\": [");
    ASSERT_NE(at, std::string::npos) << key;
    double lo = 0, hi = 0;
    std::sscanf(placed.c_str() + at + std::strlen(key) + 5, "%lf, %lf", &lo, &hi);
    EXPECT_LE(lo, truth) << key << " in " << placed;
    EXPECT_GE(hi, truth) << key << " in " << placed;
  };
  interval_holds("mu_s_ci95", 0.2);
  interval_holds("mu_r_ci95", 0.01);
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
