#include <iostream>
#include <set>
#include <sstream>

#include "commands.hpp"
#include "granmem/calibration/calibrate.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"
#include "simulation_settings.hpp"

namespace granmem::app {
namespace {

std::vector<std::string> parse_names(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream in(text);
  for (std::string name; std::getline(in, name, ',');)
    if (!trim(name).empty()) names.emplace_back(trim(name));
  return names;
}

double one_friction(const std::string& text, const std::string& option) {
  const std::vector<double> values = parse_frictions(text, option);
  if (values.size() != 1) throw Error(option + ": one friction, not '" + text + "'");
  return values.front();
}

}  // namespace

void add_calibrate(CLI::App& app, const SimulateSettings& simulate) {
  struct Args {
    std::string experiment, out, mu_s, window, noise = "auto", wall_distance = "0",
                                               preparation = "auto", summaries = "pooled",
                                               observables = "steady-state", only, fit = "mu_s";
    std::map<std::string, std::string> twin;
    bool subtract_drift = true, fit_only = false, one_cycle_ahead = false, window_fit = false;
    int ahead_burn_in = CalibrateOptions{}.ahead_burn_in;
    int threads = 0, degree = 0, replicas = 0, refine = -1;
    std::string axis_noise = "auto", placed_jitter = "auto", placed_cycle = "auto";
    std::string true_mu_s, true_mu_r;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Fit the DEM's sliding friction mu_s (or mu_s and mu_r) so that a simulated twin's "
      "steady state, its rotations and structure, or its end-of-cycle displacements match an "
      "experiment's (Ceres), with a 95% interval");
  cmd->add_option("--experiment", args->experiment, "the experiment's trajectory store (.h5)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out, "output folder")->required();
  CLI::Option* mu_s_option = cmd->add_option(
      "--mu-s", args->mu_s,
      "the frictions simulated, comma list; default steady-state 0.05,0.14,0.4, --refine 3 "
      "(placed: 0.05,0.13,0.35,0.6, --refine 4), the joint fit 0.05,0.12,0.3, "
      "displacements 0.03,0.05,0.08,0.12,0.2,0.3,0.5");
  cmd->add_option("--window", args->window,
                  "FIRST:LAST cycles compared (their window means, or their end-of-cycle "
                  "displacements pooled); default the experiment's last 10; steady-state: "
                  "auto, the longest window ending there over which the twin's runs are steady");
  cmd->add_option("--noise", args->noise,
                  "locating noise added to the simulated positions: none, fit, a value in voxels, "
                  "scans (the RMS of the position standard errors locate carried into the store), "
                  "or auto (scans where the store has them, else fit for scans, none for "
                  "simulations)")
      ->capture_default_str();
  cmd->add_option("--axis-noise", args->axis_noise,
                  "steady-state: the experiment's error in each hole axis, degrees (the "
                  "standard deviation of its tilt in each direction across it), added to the "
                  "twin's exact axes before their rotations are measured; auto: the scans' own "
                  "RMS axis standard error where the store has them (granmem's locate at 12 "
                  "voxels a grain: ~0.4), else none; 0: none")
      ->capture_default_str();
  cmd->add_option("--wall-distance", args->wall_distance,
                  "leave out grains closer than this to a container face (with a unit)")
      ->capture_default_str();
  add_drift_flags(cmd, args->subtract_drift);
  cmd->add_option("--degree", args->degree,
                  "degree of the polynomial in log mu_s through the runs' summaries; 0: 3 "
                  "for mu_s alone on a twin placed from the experiment's packing, else 2")
      ->capture_default_str();
  cmd->add_option("--replicas", args->replicas,
                  "packings per friction (seeds seed, seed+1, ...): their scatter is the "
                  "realization noise the interval includes; default steady-state 3 (placed 2), "
                  "the joint fit and displacements 2")
      ->check(CLI::Range(1, 1000));
  cmd->add_option(
         "--refine", args->refine,
         "steady-state: packings added about the fit of the --mu-s (x --mu-r) x "
         "--replicas design, each its own seed (placed: one at fit / 1.15, one at "
         "fit x 1.15, the rest at it; poured: all at it), and the fit made again on every run "
         "(they measure one packing's scatter where the experiment is; placed from scans "
         "after the drive began, the last is the placement probe: the first placed again "
         "from its own frame moved by the scans' error); default 0, but 3 for a steady-state "
         "fit of mu_s "
         "with --mu-s and --replicas left out (placed 4)")
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--deposit", args->preparation,
                  "each: every run pours its seed's grains and deposits them at its own mu_s "
                  "(as the experiment was prepared); shared: one packing per seed deposited at "
                  "the twin's --mu-s, its friction switched before the drive; experiment: "
                  "every run starts from the experiment's own packing, the grains of its frame "
                  "before the window (--placed-cycle) moved by --placed-jitter and settled at "
                  "the run's mu_s; auto: experiment for a steady-state fit of mu_s on a "
                  "simulation's packing (that frame exact: every grain), else each")
      ->capture_default_str()
      ->check(CLI::IsMember({"each", "shared", "experiment", "auto"}));
  cmd->add_option("--true-mu-s", args->true_mu_s,
                  "the sliding friction a pseudo-experiment was made with, where its store does "
                  "not say it (scans drawn from a simulation): in the report and the figures");
  cmd->add_option("--true-mu-r", args->true_mu_r, "likewise its rolling friction");
  cmd->add_option("--placed-jitter", args->placed_jitter,
                  "--deposit experiment: each replica's grains moved from the experiment's by a "
                  "normal draw of this RMS a coordinate (a length); auto: 1e-4 grain "
                  "diameters")
      ->capture_default_str();
  cmd->add_option(
         "--placed-cycle", args->placed_cycle,
         "--deposit experiment: the experiment's cycle whose frame the twin's packings "
         "are placed from, its runs driven from the next cycle on (0: the packing "
         "before the first cycle); auto: for scans their first frame (the preparation) where "
         "it holds the packing, else the cycle before the window")
      ->capture_default_str();
  cmd->add_option("--summaries", args->summaries,
                  "pooled: the CDF of the window's pooled displacements (the paper's steady "
                  "state); per-cycle: each cycle's CDF (a transient, e.g. the first cycles after "
                  "deposition, where friction shows in how the displacements change)")
      ->capture_default_str()
      ->check(CLI::IsMember({"pooled", "per-cycle"}));
  cmd->add_option("--observables", args->observables,
                  "displacements: the distribution of end-of-cycle displacements (--summaries); "
                  "steady-state: the window means of the end-of-cycle displacement and the "
                  "rotation, the packing fraction from "
                  "the packing's height and in its bulk, the coordination, all from positions, "
                  "and the wall force at full compression and at the cycle's end where the "
                  "experiment has them; for a twin placed before the frame before the window "
                  "(the scans' preparation), the packing's height at that frame too "
                  "(docs/CALIBRATION.md)")
      ->capture_default_str()
      ->check(CLI::IsMember({"displacements", "steady-state"}));
  cmd->add_option("--only", args->only,
                  "steady-state: fit only these observables, comma list (dr, rot_disp, "
                  "bulk_packing_fraction, coordination, height_packing_fraction, "
                  "height_packing_fraction_before_window, packing_fraction, "
                  "wall_force_full_compression, wall_force_unloaded); "
                  "default all the experiment has, the lid's packing_fraction left out where "
                  "the height's is there");
  cmd->add_option("--fit", args->fit,
                  "the frictions fitted: mu_s, or mu_s,mu_r jointly (steady-state observables; "
                  "--mu-r is then the list of rolling frictions simulated, e.g. "
                  "0.003,0.01,0.03, and the twin every --mu-s x --mu-r)")
      ->capture_default_str()
      ->check(CLI::IsMember({"mu_s", "mu_s,mu_r"}));
  cmd->add_flag("--fit-only", args->fit_only,
                "steady-state: fit and stop; no run at the fitted friction, so no distances "
                "or comparison figures (one simulation fewer)");
  cmd->add_flag("--one-cycle-ahead", args->one_cycle_ahead,
                "steady-state, placed twin, mu_s: after the design's fit, one packing more at "
                "fit/1.2, fit/1.07, fit x 1.07 and fit x 1.2, placed anew from the experiment's "
                "frame --ahead-burn-in + 1 cycles before each of the window's cycles and driven "
                "to it; the fit the mean of the cycles' own, its error their scatter (no refined "
                "packings, no comparison run; docs/CALIBRATION.md, \"One cycle ahead\"); the "
                "default where 5 or more of the window's cycles have those frames, and --refine, "
                "--placed-cycle and --window auto are not given");
  cmd->add_flag("--window-fit", args->window_fit,
                "steady-state: fit the window's means (the design, its refined packings), not "
                "one cycle ahead, where that would be the default")
      ->excludes("--one-cycle-ahead");
  cmd->add_option("--ahead-burn-in", args->ahead_burn_in,
                  "one cycle ahead: cycles each run drives before the one compared, placed "
                  "from the experiment's frame that many cycles earlier (its contacts' "
                  "tangential history loaded again)")
      ->capture_default_str();
  cmd->add_option("--threads", args->threads,
                  "runs at once, and the cores they use (default: one per core; the last run also "
                  "takes the cores the others leave)");
  // The twin's settings: as `simulate` takes them, here or in the config's [simulate].
  std::map<std::string, CLI::Option*> given;
  const RunSettings defaults = default_simulate_settings();
  for (std::size_t k = 0; k < kSimulateOptionCount; ++k) {
    const OptionSpec& o = kSimulateOptions[k];
    if (!is_twin_setting(o.name)) continue;
    args->twin[o.name] = defaults.at(o.name);
    given[o.name] = cmd->add_option(std::string("--") + o.name, args->twin[o.name],
                                    std::string("twin: ") + o.help)
                        ->capture_default_str()
                        ->group("Simulated twin (or the config's [simulate])");
  }

  cmd->callback([args, given, simulate, mu_s_option] {
    CalibrateOptions o;
    // The twin: simulate's defaults, then the config's [simulate], then calibrate's own;
    // the protocol's settings none of them sets are the experiment's (resolved_options()).
    o.twin = simulate.args->value;
    for (const auto& [name, option] : simulate.given) {
      if (option->count() > 0) o.twin_given.insert(name);
    }
    for (const auto& [name, option] : given) {
      if (option->count() == 0) continue;
      o.twin[name] = args->twin.at(name);
      o.twin_given.insert(name);
    }
    o.experiment = args->experiment;
    o.out = args->out;
    if (mu_s_option->count() > 0) o.mu_s = parse_frictions(args->mu_s, "--mu-s");
    if (args->fit == "mu_s,mu_r") o.mu_r = parse_frictions(o.twin.at("mu-r"), "--mu-r");
    o.observables = args->observables == "steady-state" ? CalibrationObservables::steady_state
                                                        : CalibrationObservables::displacements;
    o.only = parse_names(args->only);
    if (!args->window.empty()) o.set_window(args->window, "--window");
    o.noise = args->noise;
    o.per_cycle = args->summaries == "per-cycle";
    o.wall_distance = parse_si(args->wall_distance, Dimension::length, "m", "--wall-distance");
    o.axis_noise = parse_axis_noise(args->axis_noise, "--axis-noise");
    o.subtract_drift = args->subtract_drift;
    o.degree = args->degree;
    o.replicas = args->replicas;
    if (args->refine >= 0) o.refine = args->refine;
    o.preparation = preparation_named(args->preparation);
    o.placed_jitter = parse_placed_jitter(args->placed_jitter, "--placed-jitter");
    o.placed_cycle = parse_placed_cycle(args->placed_cycle, "--placed-cycle");
    o.fit_only = args->fit_only;
    if (args->one_cycle_ahead) o.one_cycle_ahead = true;
    if (args->window_fit) o.one_cycle_ahead = false;
    o.ahead_burn_in = args->ahead_burn_in;
    if (!args->true_mu_s.empty()) o.true_mu_s = one_friction(args->true_mu_s, "--true-mu-s");
    if (!args->true_mu_r.empty()) o.true_mu_r = one_friction(args->true_mu_r, "--true-mu-r");
    o.parallel = args->threads;
    o.log = [](const std::string& line) { std::cerr << line << "\n"; };
    o.deposit_progress = print_deposit_progress(std::cerr);
    o.progress = [](const FrictionRunSpec& run, const CyclicProgress& p) {
      std::cerr << friction_run_progress(run, p) << "\n";
    };
    const CalibrateSummary s = calibrate(o);
    for (const std::string& note : s.notes)
      std::cerr << "granmem: note: " << note << "\n";
    std::cout << s.Report();
  });
}

}  // namespace granmem::app
