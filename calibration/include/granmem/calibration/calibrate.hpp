#pragma once

#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "granmem/calibration/friction_series.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/run_settings.hpp"
#include "granmem/sim/simulate_settings.hpp"

// `granmem calibrate` as a library call: the DEM's friction fitted so that a simulated twin
// of an experiment matches what was measured (docs/CALIBRATION.md).
namespace granmem {

// What the fit compares: the end-of-cycle displacement distributions (one friction), or
// the steady state's window means (rotation, structure, loads; one friction or two).
enum class CalibrationObservables { displacements, steady_state };

// How the twin's packings are made: each run deposits its own grains at its friction (as
// the experiment was prepared), or one packing per seed is deposited once (kept in the
// output folder) and its friction switched before the drive, or each run starts from the
// experiment's own packing, the grains of its frame before the window (placed_packing.hpp;
// CalibrateOptions::placed_cycle) jittered by the run's seed and settled at the run's
// friction. Automatic: the experiment's own packing where that frame holds it exactly or
// within a fine scan's errors (placeable_packing_at()) and the fit is mu_s's on the steady
// state, where it was measured (docs/CALIBRATION.md); else each its own.
enum class TwinPreparation { each, shared, experiment, automatic };
// The settings that make the protocol: a pseudo-experiment simulated by granmem says what
// it used, the twin takes them where its caller did not set them, and they must agree.
inline constexpr const char* kProtocolSettings[] = {
    "grains",   "box",          "diameter", "amplitude",       "drive",         "wall-motion",
    "lid-mass", "lid-pressure", "period",   "inertial-number", "polydispersity"};
// The jitter of a replica of the experiment's packing (m per coordinate, in grain
// diameters): what stands for the microstate a frame does not hold (contact forces,
// velocities), small enough not to move the placed packing (its springs' overlaps under the
// lid are ~1e-3 d; moved by 1e-2 d, a 2,500-grain packing settled 1 % denser, by 1e-4 d as
// it was), and the runs' chaos grows it to a replica's scatter within cycles.
inline constexpr double kPlacedJitterDiameters = 1e-4;
// CalibrateOptions::one_cycle_ahead: the frictions of its packing, times the design's fit:
// on both sides, within where the one-cycle observables' trend is a quadratic in ln mu_s
// (the end-of-cycle displacement bends most, and a line through +-15 % read it 7 % high at
// 0.46), and wide enough to hold the truth where the design's fit is off by 10 %.
inline constexpr double kOneCycleAheadSpan[] = {1 / 1.2, 1 / 1.07, 1.07, 1.2};
// CalibrateOptions::one_cycle_ahead left to calibrate: on where this many of the window's
// cycles or more are comparable (fewer cycles' scatter is a poor error: Student's t for 3 dof
// is 3.2; the main job's 3-cycle window keeps the window fit, measured within a factor 1.075).
inline constexpr std::int64_t kOneCycleAheadByDefault = 5;
// The preparation's name in options, the summary and the runs' parameters.
const char* preparation_name(TwinPreparation preparation);
// Its name read back (each, shared, experiment, auto); Error naming `option` otherwise.
TwinPreparation preparation_named(const std::string& name, const std::string& option = "--deposit");
// Whether the run has a frame of `cycle` that holds its packing exactly: a simulation's
// (orientations, no positions' standard errors) with every grain. A scan's carries its
// locating errors, and a packing placed from it settles denser (a 2,500-grain packing
// placed with 20 um errors, 0.0016 in packing fraction).
bool exact_packing_at(const TrajectoryReader& run, std::int64_t cycle);
// Whether a twin placed from the run's frame of `cycle` starts where the packing was: the
// frame holds it exactly, or it is a scan whose centres' standard errors (RMS along each
// axis) are within kPlaceableScanError grain diameters and which locates at least
// kPlaceableScanFound of the run's grains (the rest are taken from later frames). Measured
// (docs/CALIBRATION.md, "The wall's force read beside the scans"): scans of the default
// render, standard errors 0.0009-0.0011 d and actual errors 7 and 15 um on 5 mm grains,
// placed a twin whose fits held as the DEM's own positions did; coarse scans' standard
// errors are 0.005 d, their actual errors 130-190 um, and 20 um already settles denser.
// Standard errors understate a scan's actual error (1.6-2.8x on the default render), so
// the contacts' reading checks it after the runs (kPlaceableContactError).
inline constexpr double kPlaceableScanError = 0.0012;
inline constexpr double kPlaceableScanFound = 0.99;
// A placed twin's scans whose contacts read a larger error (RMS a coordinate, in grain
// diameters) than this are said to lean the fit (the default render's read 0.0021 d).
inline constexpr double kPlaceableContactError = 0.003;
bool placeable_packing_at(const TrajectoryReader& run, std::int64_t cycle);

struct CalibrateOptions {
  std::filesystem::path experiment;  // the experiment's trajectory store
  std::filesystem::path out;         // summary, tables, figures; the twin's runs in out/runs
  RunSettings twin = default_simulate_settings();  // the twin's `simulate` settings
  // The twin's settings the caller set (a config, the command line, Python's keywords). The
  // protocol's others (kProtocolSettings) are a pseudo-experiment's own where its store says
  // them: the twin is given the experiment's protocol unless told otherwise.
  std::set<std::string> twin_given;
  // The frictions simulated; empty: the observables' own design (with_default_design()).
  std::vector<double> mu_s;
  // The rolling frictions simulated in a joint fit of mu_s and mu_r (every mu_s x mu_r);
  // empty: mu_s alone, at the twin's own mu_r.
  std::vector<double> mu_r;
  // The steady state by default: its rotation and structure pin mu_s, the end-of-cycle
  // displacements hardly (docs/CALIBRATION.md, "Which observables identify friction").
  CalibrationObservables observables = CalibrationObservables::steady_state;
  std::vector<std::string> only;  // steady state: these observables only (default all)
  // Cycles whose observables are compared; default the experiment's last 10.
  std::optional<std::pair<std::int64_t, std::int64_t>> window;
  // Steady state: the window chosen from the twin's runs instead (steady_window.hpp): the
  // longest ending at the experiment's last cycle over which every observable fitted has
  // stopped changing within one packing's scatter.
  bool auto_window = false;
  // Displacements: none, fit, scans (the RMS of the position standard errors locate
  // carried into the experiment's store), auto (scans where the store has them, else fit
  // for scans, none for simulations), or a value in voxels.
  std::string noise = "auto";
  bool per_cycle = false;    // displacements: each cycle's CDF instead of the window's
  double wall_distance = 0;  // m: grains closer to a container face are left out
  // rad: steady state: the experiment's error in each hole axis (a scan's), added to the
  // twin's exact axes before their rotations are measured (cycle_observables.hpp); 0: none.
  // Unset (auto): the experiment's own, its scans' RMS axis standard error where its store
  // has them (scan_errors.hpp), else none.
  std::optional<double> axis_noise;
  bool subtract_drift = true;  // the packing's mean displacement, on both sides
  // Of the polynomial in ln mu_s through the runs; 0: 3 where mu_s alone is fitted on a twin
  // placed from the experiment's packing (a simulation's or scans') over at least four
  // frictions (over 0.05-0.6 the observables bend between 0.13 and 0.35, and a quadratic
  // leaves 4-7x the packings' scatter; docs/CALIBRATION.md, "The placed packing tapped by its
  // own settle" and "The scans' floor at their bottom layer"), else 2.
  int degree = 0;
  // Packings per friction (seeds seed, seed + 1, ...); 0: the observables' own design (so a
  // caller's 0 is not refused, it is the default).
  int replicas = 0;
  TwinPreparation preparation = TwinPreparation::automatic;
  // m: TwinPreparation::experiment: each replica's grains moved from the experiment's by a
  // normal draw of this RMS per coordinate; NaN: kPlacedJitterDiameters grain diameters.
  double placed_jitter = std::nan("");
  // TwinPreparation::experiment: the experiment's cycle whose frame the twin's packings are
  // placed from, its runs driven from the next cycle to the window's last and numbered as
  // the experiment's. Unset (auto): placed_cycle_for().
  std::optional<std::int64_t> placed_cycle;
  bool fit_only = false;  // steady state: no run at the fitted friction, so no comparison
  // Steady state, a placed twin, mu_s alone: after the design's fit, one packing more at
  // kOneCycleAheadSpan x that fit, placed anew from the experiment's frame before each of
  // the window's cycles (ahead_burn_in earlier) and driven to it (each cycle a segment, its
  // runs in out/ahead/cycle_<c>[_from_<c - 1 - burn-in>]/runs), instead of the refined packings;
  // the fit is the mean of the segments' own (fit_friction_by_segments(), docs/CALIBRATION.md, "One
  // cycle ahead"): the twin starts each cycle where the experiment did, so the experiment's chaos
  // over the window is not compared, only what one cycle does from where it was. Compares the
  // window's cycles that comparable_ahead_cycles() finds (each run placed ahead_burn_in + 1
  // cycles before its cycle), 3 or more; implies fit_only (no comparison run). Unset
  // (auto): on for a placed twin fitting mu_s whose refinement, placed cycle and window
  // are left to it (or the window given) where kOneCycleAheadByDefault or more of the
  // window's cycles are comparable; else the window fit (resolved_options()).
  std::optional<bool> one_cycle_ahead;
  bool ahead() const { return one_cycle_ahead.value_or(false); }
  // One cycle ahead: the cycles each of its runs drives before the one compared, placed from
  // the experiment's frame that many cycles earlier. The placed packing's contacts start
  // with no tangential history, and one cycle loads them again (docs/CALIBRATION.md,
  // "One cycle ahead").
  int ahead_burn_in = 1;
  // Steady state: packings added about the design's fit (mu_s, or mu_s and mu_r jointly; at
  // refined_mu_s()), each its own seed (seed + replicas, ...), then the fit made again on every
  // run. They measure one packing's scatter where the experiment is, as realizations
  // independent of the design's, and hold the trend there.
  // A twin placed from scans (not a simulation's exact frame) after the drive began makes the
  // last of them its placement probe instead: the first placed once more from its own frame moved
  // by the scans' locating error, whose window less that run's is carried as the experiment's
  // systematic error (what placing from such a frame does, which 0.5 um replicas do not see).
  // Unset: the design's own (with_default_design()), 0 unless the design is left to it.
  std::optional<int> refine;
  int refined_packings() const { return refine.value_or(0); }
  // The mu_s of `packings` refined packings about the design's fit `fit`. A twin placed from
  // the experiment's packing puts one at fit / 1.15, one at fit x 1.15 (each at most halfway,
  // in ln mu_s, to the design's end beyond it) and the rest at the fit: its cubic bends across
  // the design's 0.13-0.35, where the fit wants the trend held on both sides of it, and near
  // 0.5 it wants the packings' scatter at it (docs/CALIBRATION.md, "The refined packings on
  // both sides of the fit"). A poured twin's all stay at the fit.
  std::vector<double> refined_mu_s(double fit, int packings) const;
  // The frictions a trend of `degree` needs: its degree + 1, and one more to measure the
  // runs' scatter where a friction has one packing (a joint twin's spare runs are its grid's).
  std::size_t frictions_for_degree(int degree) const {
    return std::size_t(degree) + (joint() || replicas > 1 ? 1 : 2);
  }
  // The frictions a pseudo-experiment was made with, for the report and the figures, where
  // its store does not say them (scans drawn from a simulation); a simulation's own are
  // read from its store (given as well, they must agree).
  std::optional<double> true_mu_s, true_mu_r;
  int parallel = 0;  // runs at once; 0: one per core (a run alone takes every core)
  // Lines saying what the calibration does (the twin, reused runs and packings), the
  // deposition's progress, and each run's progress.
  std::function<void(const std::string&)> log;
  DepositProgress deposit_progress;
  std::function<void(const FrictionRunSpec&, const CyclicProgress&)> progress;
  // Set (Python's KeyboardInterrupt): no further run starts; finished runs are reused by
  // the next call.
  const std::atomic<bool>* stop = nullptr;

  bool joint() const { return !mu_r.empty(); }
  // These options with the twin's design where they leave it, the one docs/CALIBRATION.md
  // measures for each fit: for the steady state 3 packings x mu_s 0.05, 0.14, 0.4 and 3
  // packings more at that fit (refine, 12 runs), placed (TwinPreparation::experiment, as
  // resolved_preparation() gives it) 2 x 0.05, 0.13, 0.35, 0.6 and 4 packings more at that fit
  // (refine, 12 runs reaching past 0.4), for the joint fit 2 x mu_s 0.05, 0.12, 0.3 (x each mu_r),
  // for the displacements 2 x 0.03, 0.05, 0.08, 0.12, 0.2, 0.3, 0.5.
  CalibrateOptions with_default_design() const;
  // --window's text: FIRST:LAST, or auto (`option` names it in an error).
  void set_window(const std::string& text, const std::string& option);
  // Checks the options against each other (Error naming the command line's option);
  // calibrate() also checks them against the experiment before any run.
  void validate() const;
};

// The cycles compared: the window given, else the experiment's last 10 (a --window auto
// starts there too, before the twin's runs move it).
std::pair<std::int64_t, std::int64_t> compared_window(const CalibrateOptions& options,
                                                      const TrajectoryReader& experiment);
// The experiment's cycle a placed twin starts from: placed_cycle where given, else the one
// before the window; for scans their first frame (the preparation) where it holds the
// packing (placeable_packing_at()), and with --window auto, chosen from the runs, the
// experiment's first.
std::int64_t placed_cycle_for(const CalibrateOptions& options, const TrajectoryReader& experiment);
// The preparation `options` ask for, automatic resolved for `experiment`.
TwinPreparation resolved_preparation(const CalibrateOptions& options,
                                     const TrajectoryReader& experiment);
// The window's cycles one cycle ahead can compare: those the experiment has a placeable
// frame of `burn_in` + 1 cycles before, and the frame of every cycle from there to it.
std::vector<std::int64_t> comparable_ahead_cycles(const TrajectoryReader& experiment,
                                                  std::pair<std::int64_t, std::int64_t> window,
                                                  int burn_in);
// The options calibrate() runs: the twin's protocol settings not in twin_given taken from a
// pseudo-experiment's store, the preparation resolved for `experiment`, then the design
// where `given` leaves it (with_default_design(): a placed twin's own).
CalibrateOptions resolved_options(const CalibrateOptions& given,
                                  const TrajectoryReader& experiment);

struct CalibrateSummary {
  double mu_s = 0;
  std::array<double, 2> mu_s_ci95{0, 0};
  double mu_r = -1;  // the joint fit's; < 0 otherwise
  std::array<double, 2> mu_r_ci95{0, 0};
  double correlation = 0;  // of ln mu_s and ln mu_r in the joint fit
  // The experiment's frictions where granmem simulated it (a pseudo-experiment), else NaN.
  double true_mu_s = 0, true_mu_r = 0;
  std::size_t simulations = 0;         // the twin's runs, the one at the fit included
  std::size_t simulations_fitted = 0;  // the runs the fit is made from
  std::vector<std::string> notes;      // the comparison's remarks at the fit
  std::vector<std::filesystem::path> written;
  // What the command line prints: the comparison at the fit, the fit and its interval.
  std::string Report() const { return report_; }

 private:
  std::string report_;
  friend CalibrateSummary calibrate(const CalibrateOptions& options);
};

// Simulates the twin's runs not already finished in out/runs (same settings), fits the
// friction(s) with Ceres, runs the twin at the fit (unless fit_only) and compares it with
// the experiment; writes summary.json, tables and figures. In an MPI job the runs are
// shared by the ranks and rank 0 writes and reports.
CalibrateSummary calibrate(const CalibrateOptions& options);

// A list of frictions as the command line gives it ("0.05,0.1,0.2"), sorted; an Error
// naming `option` if one is not a positive number or is listed twice.
std::vector<double> parse_frictions(const std::string& text, const std::string& option);

// --axis-noise's text: auto (unset: the experiment's own), or an angle in degrees (a bare
// number or "deg"), returned in radians; an Error naming `option` otherwise.
std::optional<double> parse_axis_noise(const std::string& text, const std::string& option);
// --placed-jitter's text: auto (NaN, CalibrateOptions::placed_jitter's default) or a length
// in m; Error naming `option` otherwise.
double parse_placed_jitter(const std::string& text, const std::string& option);
// --placed-cycle's text: auto (unset: placed_cycle_for()) or a cycle >= 0; Error
// naming `option` otherwise.
std::optional<std::int64_t> parse_placed_cycle(const std::string& text, const std::string& option);

// Whether a `simulate` setting may be given to the twin: calibrate sets the runs' output,
// cycles and mu_s itself, and the twin keeps no checkpoints, tracks or samples.
bool is_twin_setting(const std::string& name);

// A run's progress as the command line prints it.
std::string friction_run_progress(const FrictionRunSpec& run, const CyclicProgress& p);

}  // namespace granmem
