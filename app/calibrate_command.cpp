#include <omp.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>
#include <thread>

#include "commands.hpp"
#include "granmem/calibration/comparison.hpp"
#include "granmem/calibration/figures.hpp"
#include "granmem/calibration/friction_fit.hpp"
#include "granmem/calibration/friction_series.hpp"
#include "granmem/calibration/observable_fit.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/ranks.hpp"
#include "simulation_settings.hpp"

namespace granmem::app {
namespace {

namespace fs = std::filesystem;

// Options of `simulate` that calibrate sets itself, or that make no sense for a twin.
const std::set<std::string> kNotTwin{"out",  "checkpoint", "checkpoint-every",  "cycles",
                                     "mu-s", "track",      "samples-per-cycle", "full-compression"};

std::vector<double> parse_frictions(const std::string& text, const std::string& option) {
  if (trim(text).empty()) throw Error(option + ": the range of frictions is empty");
  std::vector<double> mu;
  for (const Quantity& q : parse_quantity_list(text, option)) {
    if (!q.unit.empty() || !(q.value > 0) || !std::isfinite(q.value)) {
      throw Error(option + " '" + text + "': expected positive frictions, e.g. 0.05,0.1,0.2,0.4");
    }
    mu.push_back(q.value);
  }
  std::sort(mu.begin(), mu.end());
  if (mu.empty()) throw Error(option + ": the range of frictions is empty");
  if (std::adjacent_find(mu.begin(), mu.end()) != mu.end()) {
    throw Error(option + " '" + text + "': a friction is listed twice");
  }
  return mu;
}

// Settings that make the protocol: a pseudo-experiment simulated by granmem says what it
// used, and they must agree with the twin's.
void check_against_experiment(const RunHeader& experiment, const std::string& file,
                              const std::map<std::string, std::string>& twin, double box) {
  for (const char* key :
       {"grains", "box", "diameter", "amplitude", "drive", "wall-motion", "lid-mass",
        "lid-pressure", "period", "inertial-number", "polydispersity"}) {
    const auto it = experiment.parameters.find(std::string("simulate/") + key);
    if (it != experiment.parameters.end() && it->second != twin.at(key)) {
      throw Error(file + ": the experiment was simulated with --" + key + " " + it->second +
                  ", the twin has " + twin.at(key) + " (set it in the config's [simulate])");
    }
  }
  if (experiment.box && is_physical_length_unit(experiment.length_unit)) {
    const double m = metres_per(experiment.length_unit);
    for (int a = 0; a < 2; ++a) {
      const double edge = experiment.box->edges(a) * m;
      if (std::abs(edge - box) > 0.05 * box) {
        throw Error(file + ": the experiment's box is " + std::to_string(edge * 100) +
                    " cm wide, the twin's " + std::to_string(box * 100) + " cm (--box)");
      }
    }
  }
}

// The comparison's lines printed, its notes on stderr.
Comparison reported(Comparison c) {
  for (const std::string& note : c.notes)
    std::cerr << "granmem: note: " << note << "\n";
  std::cout << c.Report();
  return c;
}

std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}
std::string json_text(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

std::string settings_json(const std::map<std::string, std::string>& settings) {
  std::string j = "{";
  for (const auto& [key, value] : settings)
    j += (j.size() > 1 ? ", " : "") + json_text(key) + ": " + json_text(value);
  return j + "}";
}

// Three digits: the best run's file name, and a second call finds it.
double three_digits(double x) {
  char rounded[32];
  std::snprintf(rounded, sizeof rounded, "%.3g", x);
  return std::stod(rounded);
}

// The steady-state fit's outputs: the runs' window means (steady_state_runs.csv), the
// figure, and the summary's per-observable part.
struct SteadyStateOutputs {
  std::vector<std::filesystem::path> written;
  std::vector<std::string> notes;  // observables that still drift across the window
  std::string json;                // the "observables" member of summary.json
};

SteadyStateOutputs write_steady_state_fit(const fs::path& out, const ObservableFit& fit,
                                          const SteadyState& experiment,
                                          const std::vector<SteadyStateRun>& runs,
                                          double true_mu_s) {
  SteadyStateOutputs o;
  Table t;
  Column& mu = t.add("mu_s");
  Column& seed = t.add("seed", "", true);
  std::vector<Column*> value;
  for (const std::string& name : fit.names)
    value.push_back(&t.add(name));
  for (const SteadyStateRun& r : runs) {
    mu.values.push_back(r.mu_s);
    seed.values.push_back(double(r.seed));
    for (std::size_t k = 0; k < fit.names.size(); ++k)
      value[k]->values.push_back(r.state[fit.names[k]]);
  }
  write_csv(t, out / "steady_state_runs.csv",
            {"the twin's steady state: window means per run (rot_disp in grain diameters, "
             "wall force in N)"});
  o.written.push_back(out / "steady_state_runs.csv");

  std::map<std::uint64_t, int> packing;
  for (const SteadyStateRun& r : runs)
    packing.emplace(r.seed, int(packing.size()));
  std::vector<ObservablePanel> panels;
  std::ostringstream j;
  j << "{";
  for (std::size_t k = 0; k < fit.names.size(); ++k) {
    ObservablePanel p;
    p.label = steady_state_label(fit.names[k]);
    for (const SteadyStateRun& r : runs) {
      p.run_mu_s.push_back(r.mu_s);
      p.run_value.push_back(r.state[fit.names[k]]);
      p.run_packing.push_back(packing.at(r.seed));
    }
    p.curve_mu_s = fit.curve_mu_s;
    p.curve = fit.curve[k];
    p.experiment = experiment[fit.names[k]];
    p.experiment_error = fit.scatter[k];
    panels.push_back(std::move(p));
    double twin_drift = 0;
    for (const SteadyStateRun& r : runs)
      twin_drift += r.state.drift_of(fit.names[k]) / double(runs.size());
    const double drift = experiment.drift_of(fit.names[k]);
    // The twin's mean over its runs says it for the protocol; one run's drift is noisy.
    if (std::abs(twin_drift) > fit.scatter[k]) {
      o.notes.push_back(fit.names[k] + " still changes by " + json_number(twin_drift) +
                        " across the window (the twin's runs' mean; one packing's scatter " +
                        json_number(fit.scatter[k]) + "): not yet a steady state");
    }
    j << (k ? ", " : "") << json_text(fit.names[k])
      << ": {\"experiment\": " << json_number(experiment[fit.names[k]])
      << ", \"drift_over_window\": " << json_number(drift)
      << ", \"twin_drift_over_window\": " << json_number(twin_drift)
      << ", \"model_at_fit\": " << json_number(fit.model[k])
      << ", \"packing_scatter\": " << json_number(fit.scatter[k])
      << ", \"log_mu_s_resolution\": " << json_number(fit.resolution[k]) << "}";
  }
  j << "}";
  o.json = j.str();
  char title[160];
  std::snprintf(title, sizeof title, "steady-state fit: mu_s = %.3g (95%% %.3g-%.3g)%s", fit.mu_s,
                fit.mu_s_ci95[0], fit.mu_s_ci95[1],
                std::isfinite(true_mu_s) ? (", true " + json_number(true_mu_s)).c_str() : "");
  const auto figure =
      plot_observable_fit(out, "observable_fit", panels, fit.mu_s, fit.mu_s_ci95, true_mu_s, title);
  o.written.insert(o.written.end(), figure.begin(), figure.end());
  return o;
}

// The experiment's friction (mu-s, mu-r) where granmem simulated it (a pseudo-experiment),
// else NaN.
double true_friction(const RunHeader& experiment, const std::string& key) {
  const auto it = experiment.parameters.find("simulate/" + key);
  if (it == experiment.parameters.end()) return std::nan("");
  try {
    return std::stod(it->second);
  } catch (const std::exception&) {
    return std::nan("");
  }
}

std::vector<std::string> parse_names(const std::string& text) {
  std::vector<std::string> names;
  std::stringstream in(text);
  for (std::string name; std::getline(in, name, ',');)
    if (!trim(name).empty()) names.emplace_back(trim(name));
  return names;
}

// What a steady-state fit needs of the calibration: the experiment, the twin's runs (and
// how to simulate one more), and where to write.
struct SteadyStateJob {
  const TrajectoryReader& experiment;
  const std::string& experiment_path;
  const CycleObservables& measured;
  const ObservableOptions& observe;
  const std::vector<FrictionRunSpec>& specs;
  const fs::path& runs_dir;
  const fs::path& out;
  const std::map<std::string, std::string>& settings;
  std::uint64_t seed;
  int replicas, degree;
  std::vector<std::string> only;
  bool fit_only;
  std::function<void(const std::vector<FrictionRunSpec>&)> run_all;
};

std::vector<SteadyStateRun> twin_steady_states(const SteadyStateJob& job) {
  std::vector<SteadyStateRun> twin;
  for (const FrictionRunSpec& run : job.specs) {
    const TrajectoryReader r(friction_run_path(job.runs_dir, run));
    twin.push_back(
        {run.mu_s, run.seed, steady_state(r, cycle_observables(r, job.observe)), run.mu_r});
  }
  return twin;
}

// The twin at the fit (unless --fit-only): the distances and comparison figures.
Comparison compare_at_fit(const SteadyStateJob& job, const FrictionRunSpec& best) {
  if (job.fit_only) return {};
  job.run_all({best});
  if (!mpi_ranks().root()) return {};
  std::string label = "DEM mu_s = " + json_number(best.mu_s);
  if (best.mu_r >= 0) label += ", mu_r = " + json_number(best.mu_r);
  return reported(
      compare_runs(job.experiment, TrajectoryReader(friction_run_path(job.runs_dir, best)),
                   "experiment", label, job.observe, Eigen::Vector3d::Zero(), 0, job.out));
}

// summary.json of a steady-state fit: `fitted` holds the fit's own members.
void write_steady_state_summary(const SteadyStateJob& job, const std::string& fitted,
                                const std::string& observables, std::size_t simulations) {
  AtomicFile f(job.out / "summary.json");
  std::ofstream j(f.temp_path());
  j << "{\n"
    << fitted << ",\n  \"n_simulations\": " << simulations << ",\n  \"replicas\": " << job.replicas
    << ",\n  \"observables\": " << observables << ",\n  \"window\": [" << job.observe.window.first
    << ", " << job.observe.window.second
    << "],\n  \"experiment\": " << json_text(job.experiment_path)
    << ",\n  \"settings\": " << settings_json(job.settings) << "\n}\n";
  j.close();
  f.commit();
}

std::size_t simulations_with(const SteadyStateJob& job, const FrictionRunSpec& best) {
  const bool simulated = std::any_of(job.specs.begin(), job.specs.end(), [&](const auto& r) {
    return r.mu_s == best.mu_s && r.seed == best.seed && r.mu_r == best.mu_r;
  });
  return job.specs.size() + (job.fit_only || simulated ? 0 : 1);
}

void print_observables(const std::vector<std::string>& names, const std::vector<double>* resolution,
                       const SteadyStateJob& job) {
  std::cout << "  steady state over cycles " << job.observe.window.first << "-"
            << job.observe.window.second << ":";
  for (std::size_t k = 0; k < names.size(); ++k) {
    std::cout << (k ? ", " : " ") << names[k];
    if (resolution) std::cout << " (+-" << (*resolution)[k] << " in ln mu_s)";
  }
  std::cout << "\n";
}

void fit_steady_state(const SteadyStateJob& job) {
  const std::vector<SteadyStateRun> twin = twin_steady_states(job);
  ObservableFitOptions fo;
  fo.degree = job.degree;
  const SteadyState exp_state = steady_state(job.experiment, job.measured);
  const ObservableFit fit = fit_friction_to_steady_state(exp_state, twin, fo, job.only);
  const FrictionRunSpec best{three_digits(fit.mu_s), job.seed};
  const Comparison compared = compare_at_fit(job, best);
  if (!mpi_ranks().root()) return;
  const double truth = true_friction(job.experiment.header(), "mu-s");
  const SteadyStateOutputs written = write_steady_state_fit(job.out, fit, exp_state, twin, truth);
  const std::size_t simulations = simulations_with(job, best);
  std::ostringstream fitted;
  fitted << "  \"mu_s\": " << json_number(fit.mu_s) << ",\n  \"mu_s_ci95\": ["
         << json_number(fit.mu_s_ci95[0]) << ", " << json_number(fit.mu_s_ci95[1])
         << "],\n  \"mu_s_true\": " << json_number(truth)
         << ",\n  \"mu_s_interval_method\": " << json_text(fit.method)
         << ",\n  \"log_mu_s_sigma\": " << json_number(fit.log_mu_s_sigma)
         << ",\n  \"gls_sigma\": " << json_number(fit.gls_sigma)
         << ",\n  \"cross_validated_sigma\": " << json_number(fit.cross_validated_sigma)
         << ",\n  \"chi2\": " << json_number(fit.chi2) << ",\n  \"dof\": " << json_number(fit.dof);
  write_steady_state_summary(job, fitted.str(), written.json, simulations);
  std::cout << std::setprecision(3) << "mu_s = " << fit.mu_s << "  (95% interval "
            << fit.mu_s_ci95[0] << " - " << fit.mu_s_ci95[1] << ", " << simulations
            << " simulations)";
  if (std::isfinite(truth)) std::cout << "  true " << truth;
  std::cout << "\n";
  print_observables(fit.names, &fit.resolution, job);
  std::cout << "  chi2 " << fit.chi2 << " for " << fit.dof << " dof; +-" << fit.gls_sigma
            << " in ln mu_s from the fit, cross-validated " << fit.cross_validated_sigma
            << " in ln mu_s on " << fit.cross_validations << " runs\n";
  for (const std::string& note : written.notes)
    std::cout << "  note: " << note << "\n";
  std::cout << "wrote " << (job.out / "summary.json").string() << ", steady_state_runs.csv, "
            << written.written.size() + compared.written.size() << " figure files\n";
}

void fit_joint(const SteadyStateJob& job) {
  const std::vector<SteadyStateRun> twin = twin_steady_states(job);
  ObservableFitOptions fo;
  fo.degree = job.degree;
  const SteadyState exp_state = steady_state(job.experiment, job.measured);
  const JointObservableFit fit = fit_frictions_to_steady_state(exp_state, twin, fo, job.only);
  const FrictionRunSpec best{three_digits(fit.mu_s), job.seed, three_digits(fit.mu_r)};
  const Comparison compared = compare_at_fit(job, best);
  if (!mpi_ranks().root()) return;
  const double true_s = true_friction(job.experiment.header(), "mu-s");
  const double true_r = true_friction(job.experiment.header(), "mu-r");
  std::vector<double> run_s, run_r;
  for (const FrictionRunSpec& r : job.specs) {
    run_s.push_back(r.mu_s);
    run_r.push_back(r.mu_r);
  }
  char title[200];
  std::snprintf(title, sizeof title,
                "joint fit: mu_s = %.3g (%.3g-%.3g), mu_r = %.3g (%.3g-%.3g), correlation %.2f",
                fit.mu_s, fit.mu_s_ci95[0], fit.mu_s_ci95[1], fit.mu_r, fit.mu_r_ci95[0],
                fit.mu_r_ci95[1], fit.correlation);
  const auto figure = plot_joint_region(job.out, "joint_fit", run_s, run_r, fit.region95,
                                        {fit.mu_s, fit.mu_r}, {true_s, true_r}, title);
  const std::size_t simulations = simulations_with(job, best);
  std::ostringstream fitted, observables;
  fitted << "  \"mu_s\": " << json_number(fit.mu_s) << ",\n  \"mu_s_ci95\": ["
         << json_number(fit.mu_s_ci95[0]) << ", " << json_number(fit.mu_s_ci95[1])
         << "],\n  \"mu_r\": " << json_number(fit.mu_r) << ",\n  \"mu_r_ci95\": ["
         << json_number(fit.mu_r_ci95[0]) << ", " << json_number(fit.mu_r_ci95[1])
         << "],\n  \"correlation\": " << json_number(fit.correlation)
         << ",\n  \"log_covariance\": [" << json_number(fit.log_covariance[0]) << ", "
         << json_number(fit.log_covariance[1]) << ", " << json_number(fit.log_covariance[2]) << ", "
         << json_number(fit.log_covariance[3]) << "],\n  \"mu_s_true\": " << json_number(true_s)
         << ",\n  \"mu_r_true\": " << json_number(true_r)
         << ",\n  \"interval_method\": " << json_text(fit.method)
         << ",\n  \"chi2\": " << json_number(fit.chi2) << ",\n  \"dof\": " << json_number(fit.dof)
         << ",\n  \"region95\": [";
  for (std::size_t k = 0; k < fit.region95.size(); ++k)
    fitted << (k ? ", " : "") << "[" << json_number(fit.region95[k][0]) << ", "
           << json_number(fit.region95[k][1]) << "]";
  fitted << "]";
  observables << "[";
  for (std::size_t k = 0; k < fit.names.size(); ++k)
    observables << (k ? ", " : "") << json_text(fit.names[k]);
  observables << "]";
  write_steady_state_summary(job, fitted.str(), observables.str(), simulations);
  std::cout << std::setprecision(3) << "mu_s = " << fit.mu_s << "  (95% interval "
            << fit.mu_s_ci95[0] << " - " << fit.mu_s_ci95[1] << ")";
  if (std::isfinite(true_s)) std::cout << "  true " << true_s;
  std::cout << "\nmu_r = " << fit.mu_r << "  (95% interval " << fit.mu_r_ci95[0] << " - "
            << fit.mu_r_ci95[1] << ")";
  if (std::isfinite(true_r)) std::cout << "  true " << true_r;
  std::cout << "\n  correlation of ln mu_s and ln mu_r " << fit.correlation << ", " << simulations
            << " simulations\n";
  print_observables(fit.names, nullptr, job);
  std::cout << "  chi2 " << fit.chi2 << " for " << fit.dof << " dof; cross-validated "
            << fit.cross_validated_sigma[0] << " (mu_s), " << fit.cross_validated_sigma[1]
            << " (mu_r) in ln on " << fit.cross_validations << " runs\n"
            << "wrote " << (job.out / "summary.json").string() << ", "
            << figure.size() + compared.written.size() << " figure files\n";
}

}  // namespace

void add_calibrate(CLI::App& app, const SimulateSettings& simulate) {
  struct Args {
    std::string experiment, out, mu_s = "0.03,0.05,0.08,0.12,0.2,0.3,0.5", window, noise = "auto",
                                 wall_distance = "0", preparation = "each", summaries = "pooled",
                                 observables = "displacements", only, fit = "mu_s";
    std::map<std::string, std::string> twin;
    bool keep_drift = false, fit_only = false;
    int threads = 0, degree = 2, replicas = 2;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate",
      "Fit the DEM's sliding friction mu_s so that its end-of-cycle displacements match an "
      "experiment's (Ceres), with a 95% interval");
  cmd->add_option("--experiment", args->experiment, "the experiment's trajectory store (.h5)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out, "output folder")->required();
  cmd->add_option("--mu-s", args->mu_s, "the frictions simulated, comma list")
      ->capture_default_str();
  cmd->add_option("--window", args->window,
                  "FIRST:LAST cycles whose end-of-cycle displacements are pooled; default the "
                  "experiment's last 10");
  cmd->add_option("--noise", args->noise,
                  "locating noise added to the simulated positions: none, fit, a value in voxels, "
                  "or auto (fit for scans, none for simulations)")
      ->capture_default_str();
  cmd->add_option("--wall-distance", args->wall_distance,
                  "leave out grains closer than this to a container face (with a unit)")
      ->capture_default_str();
  cmd->add_flag("--keep-drift", args->keep_drift,
                "keep the packing's mean displacement (default: subtracted, both sides)");
  cmd->add_option("--degree", args->degree,
                  "degree of the polynomial in log mu_s through the runs' summaries")
      ->capture_default_str();
  cmd->add_option("--replicas", args->replicas,
                  "packings per friction (seeds seed, seed+1, ...): their scatter is the "
                  "realization noise the interval includes")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--deposit", args->preparation,
                  "each: every run pours its seed's grains and deposits them at its own mu_s "
                  "(as the experiment was prepared); shared: one packing per seed deposited at "
                  "the twin's --mu-s, its friction switched before the drive")
      ->capture_default_str()
      ->check(CLI::IsMember({"each", "shared"}));
  cmd->add_option("--summaries", args->summaries,
                  "pooled: the CDF of the window's pooled displacements (the paper's steady "
                  "state); per-cycle: each cycle's CDF (a transient, e.g. the first cycles after "
                  "deposition, where friction shows in how the displacements change)")
      ->capture_default_str()
      ->check(CLI::IsMember({"pooled", "per-cycle"}));
  cmd->add_option("--observables", args->observables,
                  "displacements: the distribution of end-of-cycle displacements (--summaries); "
                  "steady-state: the window means of the rotation, the packing fraction from "
                  "the packing's height and in its bulk, the coordination, all from positions, "
                  "and the wall force where the experiment has it (docs/CALIBRATION.md)")
      ->capture_default_str()
      ->check(CLI::IsMember({"displacements", "steady-state"}));
  cmd->add_option("--only", args->only,
                  "steady-state: fit only these observables, comma list (rot_disp, "
                  "bulk_packing_fraction, coordination, height_packing_fraction, "
                  "packing_fraction, wall_force_full_compression); default all the experiment "
                  "has, the lid's packing_fraction left out where the height's is there");
  cmd->add_option("--fit", args->fit,
                  "the frictions fitted: mu_s, or mu_s,mu_r jointly (steady-state observables; "
                  "--mu-r is then the list of rolling frictions simulated, e.g. "
                  "0.003,0.01,0.03, and the twin every --mu-s x --mu-r)")
      ->capture_default_str()
      ->check(CLI::IsMember({"mu_s", "mu_s,mu_r"}));
  cmd->add_flag("--fit-only", args->fit_only,
                "steady-state: fit and stop; no run at the fitted friction, so no distances "
                "or comparison figures (one simulation fewer)");
  cmd->add_option("--threads", args->threads, "runs at once (default: all cores)");
  // The twin's settings: as `simulate` takes them, here or in the config's [simulate].
  std::map<std::string, CLI::Option*> given;
  for (std::size_t k = 0; k < kSimulateOptionCount; ++k) {
    const OptionSpec& o = kSimulateOptions[k];
    if (kNotTwin.count(o.name)) continue;
    args->twin[o.name] = o.default_value;
    given[o.name] = cmd->add_option(std::string("--") + o.name, args->twin[o.name],
                                    std::string("twin: ") + o.help)
                        ->capture_default_str()
                        ->group("Simulated twin (or the config's [simulate])");
  }

  cmd->callback([args, given, simulate, cmd] {
    // The twin: simulate's defaults, then the config's [simulate], then calibrate's own.
    std::map<std::string, std::string> v = simulate.args->value;
    for (const auto& [name, option] : simulate.given) {
      if (option->count() == 0) v[name] = simulate.args->value.at(name);
    }
    for (const auto& [name, option] : given) {
      if (option->count() > 0) v[name] = args->twin.at(name);
    }
    const std::vector<double> mu = parse_frictions(args->mu_s, "--mu-s");
    const bool joint = args->fit == "mu_s,mu_r";
    std::vector<double> mu_r;
    if (joint) {
      mu_r = parse_frictions(v.at("mu-r"), "--mu-r");
      v["mu-r"] = json_number(mu_r.front());  // each run sets its own
    }
    if (args->fit_only && args->observables != "steady-state") {
      throw Error(
          "--fit-only: only with --observables steady-state (the displacement fit "
          "compares its distributions at the fit)");
    }
    if (joint && args->observables != "steady-state") {
      throw Error("--fit mu_s,mu_r: the joint fit is on --observables steady-state");
    }
    if (joint && mu_r.size() < 3) throw Error("--mu-r: the joint fit needs at least 3 values");
    // A joint twin's spare runs come from its grid; one friction's from replicas or one more.
    const std::size_t needed = std::size_t(args->degree) + (joint || args->replicas > 1 ? 1 : 2);
    if (mu.size() < needed) {
      throw Error("--mu-s: " + std::to_string(mu.size()) + " frictions; the fit needs at least " +
                  std::to_string(needed) + " (degree " + std::to_string(args->degree) + " + 1" +
                  (args->replicas > 1 ? "" : ", and one more to measure the runs' scatter") + ")");
    }
    const TrajectoryReader experiment(args->experiment);
    const RunHeader& h = experiment.header();
    const PhysicsOptions physics = physics_from(v);
    const DepositOptions d = deposit_from(v);
    d.validate();  // before any work or output
    physics.validate("calibrate", d.radius * (1 - d.polydispersity));
    check_against_experiment(h, args->experiment, v, d.box_side);

    // Observables: the same options on both sides, lengths in the twin's grain diameter.
    ObservableOptions observe;
    observe.diameter = 2 * d.radius;
    observe.motion.subtract_drift = !args->keep_drift;
    observe.motion.wall_distance =
        parse_si(args->wall_distance, Dimension::length, "m", "--wall-distance");
    observe.rotations = h.has_axis || h.has_orientation;
    const auto& steps = experiment.steps();
    if (args->window.empty()) {
      observe.window = {std::max(steps.front() + 1, steps.back() - 9), steps.back()};
    } else {
      observe.window = parse_int_range(args->window, "--window");
    }
    if (observe.window.first < 1) throw Error("--window: cycles start at 1");
    if (observe.motion.wall_distance > 0) {
      observe.motion.box =
          Box{Eigen::Vector3d::Zero(), Eigen::Vector3d(d.box_side, d.box_side, 1e9)};
    }
    const CycleObservables measured = [&] {
      ObservableOptions o = observe;
      o.motion.box.reset();  // the experiment's own container, if any
      if (o.motion.wall_distance > 0 && !h.box) {
        throw Error(args->experiment + ": --wall-distance needs the experiment's box");
      }
      return cycle_observables(experiment, o);
    }();

    if (args->observables == "steady-state") {  // before the twin runs: names the fit can use
      const SteadyState e = steady_state(experiment, measured);
      for (const std::string& name : parse_names(args->only)) {
        if (std::isfinite(e[name])) continue;
        std::string has;
        for (std::size_t k = 0; k < e.names.size(); ++k)
          if (std::isfinite(e.values[k])) has += (has.empty() ? "" : ", ") + e.names[k];
        throw Error("--only: '" + name + "' is not measured in " + args->experiment + " (it has " +
                    has + ")");
      }
    }
    FrictionFitOptions fit_options;
    fit_options.degree = args->degree;
    fit_options.per_cycle = args->summaries == "per-cycle";
    const std::string noise = args->noise == "auto" ? (h.voxel_size ? "fit" : "none") : args->noise;
    if (noise == "fit" || (noise != "none" && !noise.empty())) {
      if (!h.voxel_size) {
        throw Error("--noise " + noise + ": the experiment has no voxel size (not from scans)");
      }
      fit_options.noise_shape = *h.voxel_size * metres_per(h.length_unit) / observe.diameter;
      fit_options.noise = noise == "fit" ? NoiseModel::fitted : NoiseModel::fixed;
      if (noise != "fit") {
        const Quantity q = parse_quantity(noise, "--noise");
        if (!q.unit.empty() || !(q.value >= 0)) {
          throw Error("--noise '" + noise + "': expected none, fit, auto or voxels (0.05)");
        }
        fit_options.noise_sigma = q.value;
      }
    } else if (noise != "none") {
      throw Error("--noise '" + noise + "': expected none, fit, auto or voxels");
    }

    const fs::path out(args->out);
    fs::create_directories(out / "runs");
    FrictionSeriesOptions series;
    series.dir = out / "runs";
    series.walls_follow = wall_friction_follows(v);
    if (joint && series.walls_follow != (v.at("wall-mu-r") == "same")) {
      throw Error(
          "--fit mu_s,mu_r: give the walls' sliding and rolling frictions alike (both "
          "'same', following the grains', or both fixed)");
    }
    series.parallel = args->threads;
    series.protocol.cycles = observe.window.second;
    series.protocol.drive = drive_from(v, physics, d.box_side, d.box_side, d.lid_mass, d.radius);
    for (const auto& [key, value] : v)
      series.protocol.parameters["simulate/" + key] = value;
    series.protocol.parameters["calibrate/deposit"] = args->preparation;
    series.protocol.validate(d.box_side, physics.dt);
    std::vector<std::uint64_t> seeds;
    for (int r = 0; r < args->replicas; ++r)
      seeds.push_back(d.seed + std::uint64_t(r));
    const auto experiment_seed = h.parameters.find("simulate/seed");
    if (experiment_seed != h.parameters.end() &&
        std::count(seeds.begin(), seeds.end(), std::stoull(experiment_seed->second))) {
      std::cerr << "note: the twin's seeds include the experiment's (" << experiment_seed->second
                << "): one twin run pours the experiment's own grains\n";
    }

    std::cerr << "calibrate: twin of " << args->experiment << ": " << d.grains << " grains, box "
              << d.box_side * 100 << " cm, A = " << series.protocol.drive.amplitude * 100
              << " cm, cycles 1-" << series.protocol.cycles << " (window " << observe.window.first
              << ":" << observe.window.second << "), mu_s " << args->mu_s << ", " << args->replicas
              << " packing(s) from seed " << d.seed << ", deposited "
              << (args->preparation == "each" ? "at each friction" : "once per seed") << "\n";
    // Shared packings: one per seed, kept in DIR so that a second call reuses them.
    std::map<std::uint64_t, Simulation> shared;
    if (args->preparation == "shared") {
      for (std::uint64_t seed : seeds) {
        DepositOptions pour = d;
        pour.seed = seed;
        const fs::path path = out / ("packing_seed_" + std::to_string(seed) + ".checkpoint.h5");
        std::map<std::string, std::string> settings = v;
        settings["seed"] = std::to_string(seed);
        if (fs::exists(path)) {
          ProtocolState state;
          shared.emplace(seed, read_checkpoint(path, &state));
          if (state.settings != settings) {
            throw Error(path.string() + ": deposited with other settings; remove it or " +
                        "choose another --out");
          }
          std::cerr << "reusing the packing of " << path.string() << "\n";
          continue;
        }
        std::cerr << "depositing " << d.grains << " grains (seed " << seed << ")\n";
        shared.emplace(seed, deposit(pour, physics, nullptr, print_deposit_progress(std::cerr)));
        ProtocolState state;
        state.settings = settings;
        write_checkpoint(path, shared.at(seed), state);
      }
    }
    auto start = [&](const FrictionRunSpec& run) {
      if (args->preparation == "shared") {
        return with_frictions(shared.at(run.seed), run, series.walls_follow);
      }
      return deposit_at_friction(d, physics, run, series.walls_follow);
    };

    // Runs already in DIR with the same settings are reused: a stopped calibration goes on.
    auto finished = [&](const FrictionRunSpec& run) {
      return finished_run(friction_run_path(series.dir, run), series.protocol.parameters,
                          series.protocol.cycles);
    };
    auto run_all = [&](const std::vector<FrictionRunSpec>& specs) {
      std::vector<FrictionRunSpec> todo;
      for (const FrictionRunSpec& run : specs)
        if (!finished(run)) todo.push_back(run);
      if (todo.size() < specs.size()) {
        std::cerr << "reusing " << specs.size() - todo.size() << " finished runs in "
                  << series.dir.string() << "\n";
      }
      if (todo.empty()) return;
      std::cerr << todo.size() << " runs, "
                << (series.parallel > 0 ? series.parallel
                                        : int(std::thread::hardware_concurrency()))
                << " at once\n";
      run_friction_series(todo, series, start, [&](std::size_t k, const CyclicProgress& p) {
        std::cerr << "mu_s " << todo[k].mu_s
                  << (todo[k].mu_r >= 0 ? " mu_r " + json_number(todo[k].mu_r) : std::string())
                  << " seed " << todo[k].seed << ": cycle " << p.cycle << "/" << p.cycles << "  "
                  << std::scientific << std::setprecision(2) << p.particle_steps_per_second
                  << std::defaultfloat << std::setprecision(6) << " particle-steps/s  "
                  << std::llround(p.seconds_left) << " s left\n";
      });
    };
    std::vector<FrictionRunSpec> specs;
    for (std::uint64_t seed : seeds)
      for (double m : mu)
        for (double r : joint ? mu_r : std::vector<double>{-1})
          specs.push_back({m, seed, r});
    run_all(specs);
    if (args->observables == "steady-state") {
      SteadyStateJob job{experiment,     args->experiment, measured,     observe,
                         specs,          series.dir,       out,          v,
                         d.seed,         args->replicas,   args->degree, parse_names(args->only),
                         args->fit_only, run_all};
      if (joint) {
        fit_joint(job);
      } else {
        fit_steady_state(job);
      }
      return;
    }
    std::vector<FrictionRun> runs;
    for (const FrictionRunSpec& run : specs)
      runs.push_back(
          {run.mu_s,
           cycle_observables(TrajectoryReader(friction_run_path(series.dir, run)), observe),
           run.seed});
    const FrictionFit fit = fit_friction(measured, runs, fit_options);

    // The twin at the fitted friction: what the distances and the figures compare.
    const double best = three_digits(fit.mu_s);
    const FrictionRunSpec best_spec{best, d.seed};
    run_all({best_spec});
    if (!mpi_ranks().root()) return;  // in an MPI job, rank 0 writes the results
    const fs::path best_path = friction_run_path(series.dir, best_spec);
    const TrajectoryReader best_run(best_path);
    const CycleObservables at_fit = cycle_observables(best_run, observe);
    const std::size_t simulations = specs.size() + (std::count(mu.begin(), mu.end(), best) ? 0 : 1);

    // Tables: the summaries per run, and the figures.
    {
      Table t;
      Column& cycle = t.add("cycle", "", true);
      Column& level = t.add("threshold_dr", "d");
      Column& exp_cdf = t.add("experiment_cdf");
      Column& exp_err = t.add("experiment_error");
      Column& model = t.add("fit_cdf");
      std::vector<Column*> per_run;
      for (const FrictionRunSpec& run : specs)
        per_run.push_back(
            &t.add("cdf_mu_s_" + json_number(run.mu_s) + "_seed_" + std::to_string(run.seed)));
      for (std::size_t j = 0; j < fit.thresholds.size(); ++j) {
        cycle.values.push_back(double(fit.threshold_cycle[j]));
        level.values.push_back(fit.thresholds[j]);
        exp_cdf.values.push_back(fit.experiment_cdf[j]);
        exp_err.values.push_back(fit.experiment_error[j]);
        model.values.push_back(fit.model_cdf[j]);
        for (std::size_t k = 0; k < specs.size(); ++k)
          per_run[k]->values.push_back(fit.run_cdf[k][j]);
      }
      write_csv(t, out / "cdf_summaries.csv",
                {"smoothed CDF of the end-of-cycle displacement dr (grain diameters) at the "
                 "experiment's deciles (of the window, cycle 0, or of each cycle), per simulated "
                 "mu_s (with the fitted locating noise)"});
      Table r;
      Column& m = r.add("mu_s");
      Column& seed = r.add("seed", "", true);
      Column& n = r.add("n", "", true);
      Column& mean = r.add("mean_dr", "d");
      Column& median = r.add("median_dr", "d");
      Column& mean_rot = r.add("mean_rot_disp", "d");
      for (std::size_t k = 0; k <= runs.size(); ++k) {
        const CycleObservables& o = k < runs.size() ? runs[k].observables : at_fit;
        const Summary s = summarize(o.dr);
        m.values.push_back(k < runs.size() ? runs[k].mu_s : best);
        seed.values.push_back(double(k < runs.size() ? specs[k].seed : best_spec.seed));
        n.values.push_back(double(s.count));
        mean.values.push_back(s.mean);
        median.values.push_back(s.median);
        mean_rot.values.push_back(summarize(o.rot_disp).mean);
      }
      write_csv(r, out / "runs.csv",
                {"per simulated mu_s (the last row: at the fit): end-of-cycle displacements "
                 "over the window, grain diameters"});
    }
    std::vector<double> run_mu;
    for (const FrictionRunSpec& run : specs)
      run_mu.push_back(run.mu_s);
    std::vector<fs::path> figures = calibration_figures(out, fit, run_mu);
    // The distances at the fit: the run at the fitted mu_s with the fitted locating noise.
    const Comparison compared =
        reported(compare_runs(experiment, best_run, "experiment", "DEM mu_s = " + json_number(best),
                              observe, fit_options.noise_shape, fit.noise_sigma, out));
    figures.insert(figures.end(), compared.written.begin(), compared.written.end());
    auto distance = [&](const std::string& q, bool wasserstein) {
      const auto it = compared.distances.find(q);
      if (it == compared.distances.end()) return std::nan("");
      return wasserstein ? it->second.second : it->second.first;
    };
    const double ks = distance("dr", false), w1 = distance("dr", true);
    const double ks_rot = distance("rot_disp", false), w1_rot = distance("rot_disp", true);

    {
      AtomicFile f(out / "summary.json");
      std::ofstream j(f.temp_path());
      j << "{\n  \"mu_s\": " << json_number(fit.mu_s) << ",\n  \"mu_s_ci95\": ["
        << json_number(fit.mu_s_ci95[0]) << ", " << json_number(fit.mu_s_ci95[1])
        << "],\n  \"mu_s_interval_method\": " << json_text(fit.method)
        << ",\n  \"n_simulations\": " << simulations << ",\n  \"replicas\": " << args->replicas
        << ",\n  \"deposit\": " << json_text(args->preparation)
        << ",\n  \"summaries\": " << json_text(args->summaries) << ",\n  \"mu_s_simulated\": [";
      for (std::size_t k = 0; k < mu.size(); ++k)
        j << (k ? ", " : "") << json_number(mu[k]);
      j << "],\n  \"converged\": " << (fit.converged ? "true" : "false")
        << ",\n  \"chi2\": " << json_number(fit.chi2) << ",\n  \"dof\": " << json_number(fit.dof)
        << ",\n  \"overdispersion\": " << json_number(fit.overdispersion)
        << ",\n  \"noise_model\": " << json_text(noise)
        << ",\n  \"noise_sigma_voxel\": " << json_number(fit.noise_sigma)
        << ",\n  \"noise_sigma_error\": " << json_number(fit.noise_sigma_error)
        << ",\n  \"distances_at_fit\": {\"ks_dr\": " << json_number(ks)
        << ", \"wasserstein1_dr\": " << json_number(w1)
        << ", \"ks_rot_disp\": " << json_number(ks_rot)
        << ", \"wasserstein1_rot_disp\": " << json_number(w1_rot)
        << ", \"length_unit\": \"grain diameter\"},\n  \"window\": [" << observe.window.first
        << ", " << observe.window.second << "],\n  \"experiment\": " << json_text(args->experiment)
        << ",\n  \"settings\": " << settings_json(v) << "\n}\n";
      j.close();
      f.commit();
    }
    std::cout << std::setprecision(3) << "mu_s = " << fit.mu_s << "  (95% interval "
              << fit.mu_s_ci95[0] << " - " << fit.mu_s_ci95[1] << ", " << simulations
              << " simulations" << (fit.converged ? "" : ", fit NOT converged") << ")\n"
              << "  at the fit: KS " << ks << ", Wasserstein-1 " << w1
              << " d (end-of-cycle dr); chi2 " << fit.chi2 << " for " << fit.dof
              << " dof; realization scatter x" << fit.overdispersion << "\n";
    if (fit.mu_s_ci95[0] < mu.front() || fit.mu_s_ci95[1] > mu.back()) {
      std::cout << "  the interval reaches beyond the simulated frictions (" << mu.front() << "-"
                << mu.back() << "): these displacements pin mu_s down only loosely (a larger "
                << "packing or a longer window would)\n";
    }
    if (fit.noise_sigma > 0) {
      std::cout << "  locating noise " << fit.noise_sigma << " +- " << fit.noise_sigma_error
                << " voxel\n";
    }
    std::cout << "wrote " << (out / "summary.json").string() << ", runs.csv, cdf_summaries.csv, "
              << figures.size() << " figure files\n";
  });
}

}  // namespace granmem::app
