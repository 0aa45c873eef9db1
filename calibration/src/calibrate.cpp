#include "granmem/calibration/calibrate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <thread>

#include "granmem/calibration/comparison.hpp"
#include "granmem/calibration/contact_locating_error.hpp"
#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/calibration/figures.hpp"
#include "granmem/calibration/friction_fit.hpp"
#include "granmem/calibration/observable_fit.hpp"
#include "granmem/calibration/scan_errors.hpp"
#include "granmem/calibration/steady_window.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/json_file.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/units.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/placed_packing.hpp"
#include "granmem/sim/ranks.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;

// The placement probe's draws of the scans' error: seeds apart from the replicas' jitters.
constexpr std::uint64_t kProbeSeed = 20261128;

// Six digits, as labels and messages show a friction.
std::string number_text(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

// Three digits: the run at the fit gets a file name that a second call finds again.
double three_digits(double x) {
  char rounded[32];
  std::snprintf(rounded, sizeof rounded, "%.3g", x);
  return std::stod(rounded);
}

void check_frictions(const std::vector<double>& mu, const std::string& option) {
  if (mu.empty()) throw Error(option + ": the range of frictions is empty");
  for (double m : mu)
    if (!(m > 0) || !std::isfinite(m)) {
      throw Error(option + ": expected positive frictions, e.g. 0.05,0.1,0.2,0.4");
    }
  std::vector<double> sorted = mu;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
    throw Error(option + ": a friction is listed twice");
  }
}

std::vector<double> sorted(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v;
}

// Whether a shared packing was poured with these settings: the twin's own and the friction
// it was poured at, not what calibrate sets per run (cycles, output).
bool same_packing_settings(const RunSettings& a, const RunSettings& b) {
  for (const auto& [key, value] : b) {
    if (!is_twin_setting(key) && key != "mu-s") continue;
    const auto it = a.find(key);
    if (it == a.end() || it->second != value) return false;
  }
  return true;
}

// A `simulate` setting a pseudo-experiment's store says it was made with; null where none.
const std::string* stored_setting(const RunHeader& experiment, const std::string& key) {
  const auto it = experiment.parameters.find("simulate/" + key);
  return it == experiment.parameters.end() ? nullptr : &it->second;
}

// The protocol settings the twin takes from a pseudo-experiment's store: those the caller
// left (not in twin_given, and at simulate's default for a library caller), as the store
// says them.
RunSettings protocol_left_to_experiment(const CalibrateOptions& given,
                                        const RunHeader& experiment) {
  const RunSettings defaults = default_simulate_settings();
  RunSettings taken;
  for (const char* key : kProtocolSettings) {
    const std::string* stored = stored_setting(experiment, key);
    const bool set = given.twin_given.count(key) || given.twin.at(key) != defaults.at(key);
    if (stored && !set) taken[key] = *stored;
  }
  return taken;
}

// The protocol a pseudo-experiment's store says must agree with the twin's.
void check_against_experiment(const RunHeader& experiment, const std::string& file,
                              const RunSettings& twin, double box) {
  for (const char* key : kProtocolSettings) {
    const std::string* stored = stored_setting(experiment, key);
    if (stored && *stored != twin.at(key)) {
      throw Error(file + ": the experiment was simulated with --" + key + " " + *stored +
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

}  // namespace

const char* preparation_name(TwinPreparation preparation) {
  switch (preparation) {
    case TwinPreparation::shared:
      return "shared";
    case TwinPreparation::experiment:
      return "experiment";
    case TwinPreparation::automatic:
      return "auto";
    default:
      return "each";
  }
}

TwinPreparation preparation_named(const std::string& name, const std::string& option) {
  for (TwinPreparation p : {TwinPreparation::each, TwinPreparation::shared,
                            TwinPreparation::experiment, TwinPreparation::automatic})
    if (name == preparation_name(p)) return p;
  throw Error(option + " '" + name + "': expected each, shared, experiment or auto");
}

bool exact_packing_at(const TrajectoryReader& run, std::int64_t cycle) {
  const RunHeader& h = run.header();
  if (!h.has_orientation || h.has_position_error) return false;
  const std::optional<std::size_t> frame = frame_of_cycle(run, cycle);
  return frame && run.read_frame(*frame).position.allFinite();
}

bool placeable_packing_at(const TrajectoryReader& run, std::int64_t cycle) {
  if (exact_packing_at(run, cycle)) return true;
  const RunHeader& h = run.header();
  const std::optional<std::size_t> frame = frame_of_cycle(run, cycle);
  if (!h.has_position_error || !frame) return false;
  const Frame f = run.read_frame(*frame);
  std::size_t found = 0;
  Eigen::Array3d squared = Eigen::Array3d::Zero();
  for (Eigen::Index i = 0; i < f.position.rows(); ++i) {
    if (!f.position.row(i).allFinite() || !f.position_error.row(i).allFinite()) continue;
    ++found;
    squared += f.position_error.row(i).transpose().array().square();
  }
  std::vector<double> radius;
  for (double r : h.radius)
    if (std::isfinite(r)) radius.push_back(r);
  if (found == 0 || radius.empty()) return false;
  const double diameter = 2 * median(radius);
  const double rms = (squared / double(found)).sqrt().maxCoeff();
  return double(found) >= kPlaceableScanFound * double(h.grain_count()) &&
         rms <= kPlaceableScanError * diameter;
}

std::pair<std::int64_t, std::int64_t> compared_window(const CalibrateOptions& options,
                                                      const TrajectoryReader& experiment) {
  if (options.window) return *options.window;
  const auto& steps = experiment.steps();
  if (steps.empty()) throw Error(options.experiment.string() + ": no frames");
  return {std::max(steps.front() + 1, steps.back() - 9), steps.back()};
}

std::int64_t placed_cycle_for(const CalibrateOptions& options, const TrajectoryReader& experiment) {
  if (options.placed_cycle) return *options.placed_cycle;
  const auto& steps = experiment.steps();
  if (options.auto_window || steps.empty()) return steps.empty() ? 0 : steps.front();
  const std::int64_t before_window = compared_window(options, experiment).first - 1;
  // Scans from their first frame, the preparation: centres off by more than a contact's
  // overlap, settled into a packing the drive has trained, undo its training and the twin
  // compacts faster through the window; a prepared packing has no training to undo.
  const bool scans = experiment.header().has_position_error;
  if (scans && steps.front() < before_window && placeable_packing_at(experiment, steps.front()))
    return steps.front();
  return before_window;
}

TwinPreparation resolved_preparation(const CalibrateOptions& options,
                                     const TrajectoryReader& experiment) {
  if (options.preparation != TwinPreparation::automatic) return options.preparation;
  const bool measured =
      options.observables == CalibrationObservables::steady_state && !options.joint();
  return measured && placeable_packing_at(experiment, placed_cycle_for(options, experiment))
             ? TwinPreparation::experiment
             : TwinPreparation::each;
}

std::vector<std::int64_t> comparable_ahead_cycles(const TrajectoryReader& experiment,
                                                  std::pair<std::int64_t, std::int64_t> window,
                                                  int burn_in) {
  std::vector<std::int64_t> cycles;
  for (std::int64_t c = window.first; c <= window.second; ++c) {
    const std::int64_t placed = c - 1 - burn_in;
    bool framed = placed >= 0 && placeable_packing_at(experiment, placed);
    for (std::int64_t f = placed + 1; framed && f <= c; ++f)
      framed = frame_of_cycle(experiment, f).has_value();
    if (framed) cycles.push_back(c);
  }
  return cycles;
}

namespace {

// CalibrateOptions::one_cycle_ahead resolved: as given, else where every condition of the
// default holds (the options' comment).
bool resolved_one_cycle_ahead(const CalibrateOptions& given, const CalibrateOptions& o,
                              const TrajectoryReader& experiment) {
  if (given.one_cycle_ahead) return *given.one_cycle_ahead;
  const bool steady = o.observables == CalibrationObservables::steady_state;
  if (!steady || o.joint() || o.preparation != TwinPreparation::experiment || given.refine ||
      given.auto_window || given.placed_cycle) {
    return false;
  }
  return std::int64_t(
             comparable_ahead_cycles(experiment, compared_window(o, experiment), o.ahead_burn_in)
                 .size()) >= kOneCycleAheadByDefault;
}

}  // namespace

CalibrateOptions resolved_options(const CalibrateOptions& given,
                                  const TrajectoryReader& experiment) {
  CalibrateOptions options = given;
  for (const auto& [key, value] : protocol_left_to_experiment(given, experiment.header()))
    options.twin[key] = value;
  options.preparation = resolved_preparation(given, experiment);
  options.one_cycle_ahead = resolved_one_cycle_ahead(given, options, experiment);
  if (options.placed_cycle && options.preparation != TwinPreparation::experiment) {
    const bool asked = given.preparation != TwinPreparation::automatic;
    throw Error("--placed-cycle " + std::to_string(*options.placed_cycle) +
                ": only for a twin placed from the experiment; this one is " +
                (asked ? std::string("--deposit ") + preparation_name(given.preparation)
                       : "poured (" + given.experiment.string() + " has no frame of cycle " +
                             std::to_string(*options.placed_cycle) +
                             " holding its packing exactly, or the fit is not mu_s's on the "
                             "steady state); --deposit experiment places it"));
  }
  return options.with_default_design();
}

namespace {

// The experiment's friction (mu-s, mu-r) where granmem simulated it (a pseudo-experiment),
// else NaN.
double true_friction(const RunHeader& experiment, const std::string& key) {
  const std::string* stored = stored_setting(experiment, key);
  if (!stored) return std::nan("");
  try {
    return std::stod(*stored);
  } catch (const std::exception&) {
    return std::nan("");
  }
}

// The friction a pseudo-experiment was made with: the one given (scans drawn from a
// simulation do not carry it), which must agree with what the store says where it says one.
double true_friction(const RunHeader& experiment, const std::string& key,
                     std::optional<double> given) {
  const double stored = true_friction(experiment, key);
  if (!given) return stored;
  if (std::isfinite(stored) && std::abs(*given - stored) > 1e-9 * stored) {
    throw Error("--true-" + key + " " + number_text(*given) + ": the experiment's store says " +
                number_text(stored));
  }
  return *given;
}

// The hole-axis error the twin's axes are given: the one asked for, else (auto) the
// experiment's own, its scans' RMS axis standard error where its store has them (none for
// a simulated experiment, whose axes are exact).
double twin_axis_noise(const CalibrateOptions& o, const ScanErrors& experiment) {
  if (o.axis_noise) return *o.axis_noise;
  const bool steady = o.observables == CalibrationObservables::steady_state;
  return steady && std::isfinite(experiment.axis) ? experiment.axis : 0.0;
}

// The observables' options, the same on both sides, lengths in the twin's grain diameter.
ObservableOptions observable_options(const CalibrateOptions& o, const TrajectoryReader& experiment,
                                     const DepositOptions& d, const ScanErrors& errors) {
  const RunHeader& h = experiment.header();
  ObservableOptions observe;
  observe.diameter = 2 * d.radius;
  observe.motion.subtract_drift = o.subtract_drift;
  observe.motion.wall_distance = o.wall_distance;
  observe.rotations = h.has_axis || h.has_orientation;
  observe.axis_noise = twin_axis_noise(o, errors);
  observe.window = compared_window(o, experiment);
  if (observe.window.first < 1) throw Error("--window: cycles start at 1");
  if (observe.motion.wall_distance > 0) {
    observe.motion.box = Box{Eigen::Vector3d::Zero(), Eigen::Vector3d(d.box_side, d.box_side, 1e9)};
    if (!h.box) {
      throw Error(o.experiment.string() + ": --wall-distance needs the experiment's box");
    }
  }
  return observe;
}

// The experiment's observables, measured in its own container, open at the top as the
// twin's: the lid moves, so grains are left out near the floor and the side walls only.
// `extra_axis_noise`: rad, the experiment's axes tilted once more (its axes carry their own);
// `extra_position_noise`: m, its positions moved once more.
CycleObservables measured_observables(
    const TrajectoryReader& experiment, ObservableOptions o, double extra_axis_noise = 0,
    const Eigen::Vector3d& extra_position_noise = Eigen::Vector3d::Zero()) {
  o.motion.box.reset();
  o.axis_noise = extra_axis_noise;
  o.position_noise = extra_position_noise;
  if (const auto& box = experiment.header().box; box && o.motion.wall_distance > 0) {
    o.motion.box = Box{box->lower, Eigen::Vector3d(box->edges(0), box->edges(1), 1e9)};
  }
  return cycle_observables(experiment, o);
}

// A steady-state fit asked by name for what the experiment does not measure: refused
// before the twin runs.
void check_only(const CalibrateOptions& o, const SteadyState& measured) {
  for (const std::string& name : o.only) {
    if (std::isfinite(measured[name])) continue;
    std::string has;
    for (std::size_t k = 0; k < measured.names.size(); ++k)
      if (std::isfinite(measured.values[k])) has += (has.empty() ? "" : ", ") + measured.names[k];
    throw Error("--only: '" + name + "' is not measured in " + o.experiment.string() + " (it has " +
                has + ")");
  }
}

// The displacement fit's options; the locating noise from --noise and the experiment's
// voxel. scans (and auto where the store has them): the scans' own standard errors as the
// noise, not fitted (a fitted noise is nearly degenerate with friction). A scan's position
// error is 2-3x its standard error, but mostly shared by consecutive scans, so a
// displacement's is 0.55-1.3x what the standard errors predict (docs/CALIBRATION.md).
FrictionFitOptions displacement_fit_options(const CalibrateOptions& o, const RunHeader& h,
                                            const ScanErrors& errors, double diameter,
                                            std::string* noise_model) {
  FrictionFitOptions fit;
  fit.degree = o.degree > 0 ? o.degree : 2;
  fit.per_cycle = o.per_cycle;
  const bool stored = errors.position.allFinite();
  if (o.noise == "scans" || (o.noise == "auto" && stored && h.voxel_size)) {
    *noise_model = "scans";
    if (!stored) {
      throw Error(
          "--noise scans: the experiment's store has no position standard errors "
          "(tracked by granmem track from scans carries them)");
    }
    if (!h.voxel_size) {
      throw Error("--noise scans: the experiment has no voxel size (the noise is in voxels)");
    }
    // sigma in voxels (the RMS over the axes), each axis' share in diameters.
    fit.noise_sigma = std::sqrt(errors.position.cwiseQuotient(*h.voxel_size).squaredNorm() / 3);
    if (!(fit.noise_sigma > 0)) return fit;  // exact positions: no noise
    fit.noise = NoiseModel::fixed;
    fit.noise_shape = errors.position * metres_per(h.length_unit) / diameter / fit.noise_sigma;
    return fit;
  }
  const std::string noise = o.noise == "auto" ? (h.voxel_size ? "fit" : "none") : o.noise;
  *noise_model = noise;
  if (noise == "none") return fit;
  if (!h.voxel_size) {
    throw Error("--noise " + noise + ": the experiment has no voxel size (not from scans)");
  }
  fit.noise_shape = *h.voxel_size * metres_per(h.length_unit) / diameter;
  fit.noise = noise == "fit" ? NoiseModel::fitted : NoiseModel::fixed;
  if (noise != "fit") fit.noise_sigma = parse_quantity(noise, "--noise").value;
  return fit;
}

// The placed packing's grain count and a digest of its grains' positions.
std::string placed_identity(const Grains& grains) {
  std::uint64_t digest = kFnv1aBasis;
  for (const Eigen::Vector3d& x : grains.x)
    digest = fnv1a(x.data(), sizeof(double) * 3, digest);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(digest));
  return std::to_string(grains.size()) + " grains, positions digest " + hex;
}

// The placement probe's run and the twin's run it was placed from (Twin::run_placement_probe).
struct PlacementProbe {
  FrictionRunSpec source;
  fs::path path;
  Eigen::Vector3d error;  // m, the scans' locating error it was moved by
};

// Everything the calibration's stages share: the experiment, the twin's physics and
// protocol, and how to run the twin (reusing what a stopped call finished).
class Twin {
 public:
  Twin(const CalibrateOptions& options, const TrajectoryReader& experiment)
      : o_(options), experiment_(experiment), settings_(options.twin) {
    if (o_.joint()) settings_["mu-r"] = number_text(sorted(o_.mu_r).front());  // each run its own
    physics_ = physics_from(settings_);
    deposit_ = deposit_from(settings_);
    deposit_.validate();  // before any work or output
    physics_.validate("calibrate", deposit_.radius * (1 - deposit_.polydispersity));
    check_against_experiment(experiment.header(), o_.experiment.string(), settings_,
                             deposit_.box_side);
    errors = scan_errors(experiment);
    count_located_grains();
    observe = observable_options(o_, experiment, deposit_, errors);
    measured = measured_observables(experiment, observe);
    if (o_.preparation == TwinPreparation::experiment) place_experiments_grains();
    series_ = series_options();
    for (int r = 0; r < o_.replicas; ++r)
      seeds_.push_back(deposit_.seed + std::uint64_t(r));
  }

  ScanErrors errors;  // the experiment's own, from its scans
  ObservableOptions observe;
  CycleObservables measured;

  // --window auto: the window moved to where the twin's runs are steady (they hold every
  // cycle up to the experiment's last, the window's end). Returns the line that says where.
  std::string choose_window(const std::vector<FrictionRunSpec>& specs) {
    std::vector<ObservableSeries> runs;
    std::vector<std::size_t> cell;  // one per friction (pair)
    std::map<std::pair<double, double>, std::size_t> cells;
    for (const FrictionRunSpec& spec : specs) {
      const TrajectoryReader r(path(spec));
      runs.push_back(observable_series(r, cycle_observables(r, observe)));
      cell.push_back(cells.emplace(std::pair{spec.mu_s, spec.mu_r}, cells.size()).first->second);
    }
    std::vector<std::string> names;
    for (const std::string& name : measured_steady_state().names)
      if (o_.only.empty() || std::count(o_.only.begin(), o_.only.end(), name))
        names.push_back(name);
    SteadyWindowOptions options;
    options.last = observe.window.second;
    // The experiment's first scan ends cycle steps.front(): its first whole cycle is the next.
    options.earliest = std::max<std::int64_t>(1, experiment_.steps().front() + 1);
    const SteadyWindow w = choose_steady_window(runs, cell, names, options);
    observe.window = w.window;
    measured = measured_observables(experiment_, observe);
    std::ostringstream line;
    line << "window from the twin's runs: cycles " << w.window.first << "-" << w.window.second;
    if (w.steady) {
      line << " (every observable's change across it within one packing's scatter)";
    } else {
      line << ": not steady by cycle " << w.window.second << " (" << w.unsteady
           << " still changes by " << w.change << " across its last " << options.min_cycles
           << " cycles, one packing's scatter " << w.scatter << "); the last "
           << w.window.second - w.window.first + 1 << " cycles";
    }
    say(line.str());
    return line.str();
  }

  // The experiment's steady state, measured with what the twin knows of its grains. Grains
  // known to be alike (the twin's are, without polydispersity) at the twin's radius: a
  // scan's located radii carry what is left of its blur's bias (a few % on coarse scans; 6 %
  // before locate corrected it), which would read as a packing three times that looser and
  // with fewer contacts. The packing's height with the twin's
  // grain count, the experiment's own: grains a scan misses would read as a looser packing.
  SteadyState measured_steady_state() const {
    SteadyState s = steady_state(experiment_, measured, {}, known_grains());
    if (const auto cycle = cycle_before_window())
      add_height_before_window(s, experiment_, *cycle, known_grains());
    return s;
  }
  // The frame before the window where the twin was placed from an earlier one (the scans'
  // preparation) and the experiment has it: the packing's height there is compared too.
  std::optional<std::int64_t> cycle_before_window() const {
    const std::int64_t before = observe.window.first - 1;
    if (!placed_ || placed_cycle_ >= before || !frame_of_cycle(experiment_, before))
      return std::nullopt;
    return before;
  }
  KnownGrains known_grains() const {
    KnownGrains known;
    if (deposit_.polydispersity == 0) known.radius = deposit_.radius;
    if (!twin_count_differs()) known.count = std::size_t(deposit_.grains);
    return known;
  }

  const CalibrateOptions& options() const { return o_; }
  // The cycle the twin's runs start after (a placed twin's; 0 for a prepared packing).
  std::int64_t first_cycle() const { return placed_cycle_; }
  bool placed() const { return placed_.has_value(); }
  // The trend's degree (CalibrateOptions::degree; 0: by the twin).
  int trend_degree() const {
    if (o_.degree > 0) return o_.degree;
    return placed_ && !o_.joint() && o_.mu_s.size() >= o_.frictions_for_degree(3) ? 3 : 2;
  }
  const TrajectoryReader& experiment() const { return experiment_; }
  // The seeds after the design's: packings none of its runs pour.
  std::uint64_t next_seed(int k) const { return seeds_.back() + 1 + std::uint64_t(k); }
  const RunSettings& settings() const { return settings_; }
  std::uint64_t seed() const { return deposit_.seed; }

  // Every friction (pair) at every seed.
  std::vector<FrictionRunSpec> design() const {
    std::vector<FrictionRunSpec> specs;
    for (std::uint64_t seed : seeds_)
      for (double m : sorted(o_.mu_s))
        for (double r : o_.joint() ? sorted(o_.mu_r) : std::vector<double>{-1})
          specs.push_back({m, seed, r});
    return specs;
  }

  // The protocol settings taken from a pseudo-experiment's store (resolved_options()), where
  // they are not simulate's defaults: what the twin was not told and did not guess.
  void note_protocol_taken(const RunSettings& taken) const {
    const RunSettings defaults = default_simulate_settings();
    std::string line;
    for (const char* key : kProtocolSettings) {  // in the protocol's order
      const auto it = taken.find(key);
      if (it != taken.end() && it->second != defaults.at(key))
        line += (line.empty() ? "--" : ", --") + it->first + " " + it->second;
    }
    if (!line.empty()) say("the twin's protocol from the experiment's store: " + line);
  }

  // `taken`: the protocol settings read from the experiment's store, said where not defaults.
  void announce(const RunSettings& taken) const {
    note_experiment_seed();
    note_protocol_taken(taken);
    note_located_grains();
    std::ostringstream line;
    std::string mu;
    for (double m : sorted(o_.mu_s))
      mu += (mu.empty() ? "" : ",") + number_text(m);
    line << "calibrate: twin of " << o_.experiment.string() << ": " << deposit_.grains
         << " grains, box " << deposit_.box_side * 100
         << " cm, A = " << series_.protocol.drive.amplitude * 100 << " cm, cycles "
         << series_.protocol.first_cycle + 1 << "-" << series_.protocol.cycles << " (window "
         << observe.window.first << ":" << observe.window.second << "), mu_s " << mu << ", "
         << o_.replicas << " packing(s) from seed " << deposit_.seed;
    if (o_.refined_packings() > 0)
      line << ", then " << o_.refined_packings() << " more " << (placed() ? "about" : "at")
           << " their fit";
    line << ", " << preparation_text();
    if (observe.axis_noise > 0) {
      line << "; the twin's hole axes tilted by " << std::setprecision(3)
           << observe.axis_noise * 180 / M_PI << " deg ("
           << (o_.axis_noise ? "--axis-noise" : "the experiment's RMS axis standard error") << ")";
    }
    say(line.str());
    if (o_.preparation == TwinPreparation::experiment &&
        !exact_packing_at(experiment_, placed_cycle_)) {
      say("note: the experiment's frame of cycle " + std::to_string(placed_cycle_) +
          " does not hold its packing exactly (a scan's centres carry their locating errors, "
          "and grains it missed are taken from later frames): the twin's packings settle from "
          "them; " +
          (placed_in_a_trained_packing()
               ? std::string("settled into a packing the drive has trained, centres off by "
                             "more than a contact's overlap undo its training: the twin "
                             "compacts faster, and they lean the fit to higher friction (the "
                             "placement probe measures it; the scans' first frame, the "
                             "preparation, has no training to undo)")
               : std::string("placed from the preparation, before the drive, they leave no "
                             "training undone, but centres off by 20 um settle denser and "
                             "lean the fit to higher friction")));
    }
    // Axes from scans without their errors (another program's tracks): the twin's stay
    // exact, and its rotations read small against the scans'; said, not guessed.
    const RunHeader& h = experiment_.header();
    if (observe.rotations && !o_.axis_noise && h.has_axis && !h.has_orientation &&
        !h.has_axis_error && o_.observables == CalibrationObservables::steady_state) {
      say("note: the experiment's hole axes carry no standard errors, so the twin's stay exact; "
          "if they come from scans, give their error with --axis-noise DEG");
    }
  }

  std::string preparation_text() const {
    switch (o_.preparation) {
      case TwinPreparation::shared:
        return "deposited once per seed";
      case TwinPreparation::experiment:
        return "placed where the experiment's frame of cycle " + std::to_string(placed_cycle_) +
               " has its " + std::to_string(placed_->size()) + " grains, moved by " +
               number_text(placed_jitter_ * 1e3) +
               " mm RMS a coordinate, settled at each friction under a drag of " +
               number_text(deposit_.placed_settling_damping) + "/s";
      default:
        return "deposited at each friction";
    }
  }

  // The fewest and most grains located in a frame of the experiment.
  void count_located_grains() {
    located_ = {std::numeric_limits<std::size_t>::max(), 0};
    for (std::size_t t = 0; t < experiment_.frame_count(); ++t) {
      const Vectors3 x = experiment_.read_frame(t).position;
      std::size_t located = 0;
      for (Eigen::Index i = 0; i < x.rows(); ++i)
        located += x.row(i).allFinite();
      located_ = {std::min(located_.first, located), std::max(located_.second, located)};
    }
  }
  // More than 5 % apart: the twin is not the experiment's packing, and its count is not
  // the experiment's (its height is then measured with the grains located).
  bool twin_count_differs() const {
    const auto n = std::size_t(deposit_.grains);
    const auto [fewest, most] = located_;
    return std::max(n - std::min(n, fewest), most - std::min(most, n)) > n / 20;
  }
  // The experiment's frames locate fewer (or more) grains than the twin pours: a few
  // missed by the scans are counted in its height; many mean the twin is not its packing.
  void note_located_grains() const {
    const auto n = std::size_t(deposit_.grains);
    const auto [fewest, most] = located_;
    if (fewest == n && most == n) return;
    std::ostringstream line;
    line << "note: the experiment's frames locate " << fewest;
    if (most != fewest) line << "-" << most;
    line << " grains, the twin pours " << n;
    if (twin_count_differs()) {
      line << ": more than 5 % apart, so the twin is not the experiment's packing; give it "
              "the experiment's grain count ([simulate] grains)";
    } else {
      line << ": its packing's height is taken with " << n << " grains ("
           << (fewest < n ? "the scans missed some" : "the scans split some") << ")";
    }
    say(line.str());
  }

  // --deposit experiment: the experiment's frame of the placed cycle (by default the one
  // before the window) is where every run's grains start (each replica jittered by its
  // seed); the runs drive the cycles after it, numbered as the experiment's.
  void place_experiments_grains() {
    placed_cycle_ = placed_cycle_for(o_, experiment_);
    const std::optional<std::size_t> frame = frame_of_cycle(experiment_, placed_cycle_);
    if (!frame) {
      throw Error(o_.experiment.string() + ": --deposit experiment starts the twin from the " +
                  "experiment's frame of cycle " + std::to_string(placed_cycle_) +
                  (o_.placed_cycle ? " (--placed-cycle)" : " (the one before the window)") +
                  ", and it has none");
    }
    if (placed_cycle_ >= observe.window.first) {
      throw Error("--placed-cycle " + std::to_string(placed_cycle_) +
                  ": the twin must start before the window's first cycle (" +
                  std::to_string(observe.window.first) + ")");
    }
    placed_ = grains_of_frame(experiment_, *frame, deposit_, physics_);
    placed_jitter_ = std::isfinite(o_.placed_jitter) ? o_.placed_jitter
                                                     : kPlacedJitterDiameters * 2 * deposit_.radius;
  }

  // A placed twin's placed from scans (their frame carries locating errors), not from a
  // simulation's exact frame.
  bool placed_from_scans() const {
    return placed_ && !exact_packing_at(experiment_, placed_cycle_);
  }
  // Placed after the drive began (not from the preparation): a frame the drive has trained,
  // whose training centres off by a scan's error undo as they settle.
  bool placed_in_a_trained_packing() const { return placed_cycle_ > 0; }

  // The placement probe: the run `source` placed once more, from its own frame of the placed
  // cycle moved by a draw of the scans' locating error `error` (m, along x, y, z), at its
  // friction and seed, in its own folder (probe/). Its window less its source's is what
  // placing from such a frame does to the twin, which the source's replicas (jittered by
  // 0.5 um) do not see (docs/CALIBRATION.md, "The placement probe").
  void run_placement_probe(const FrictionRunSpec& source, const Eigen::Vector3d& error) {
    const TrajectoryReader from(path(source));
    const std::optional<std::size_t> frame = frame_of_cycle(from, placed_cycle_);
    if (!frame) {
      throw Error(path(source).string() + ": no frame of cycle " + std::to_string(placed_cycle_) +
                  " to place the placement probe from");
    }
    const Grains moved = jittered(grains_of_frame(from, *frame, deposit_, physics_), error,
                                  kProbeSeed + source.seed, deposit_);
    FrictionSeriesOptions series = series_;
    series.dir = o_.out / "probe";
    series.protocol.parameters["calibrate/placed_from"] = placed_identity(moved);
    std::ostringstream of;
    of << path(source).filename().string() << " moved by " << error.x() << ", " << error.y() << ", "
       << error.z() << " m";
    series.protocol.parameters["calibrate/probe_of"] = of.str();
    probe_ = PlacementProbe{source, friction_run_path(series.dir, source), error};
    if (finished_run(probe_->path, series.protocol.parameters, series.protocol.cycles)) {
      say("reusing the placement probe " + probe_->path.string());
      return;
    }
    say("the placement probe: " + of.str() + ", 1 run");
    fs::create_directories(series.dir);
    run_friction_series(
        {source}, series,
        [&](const FrictionRunSpec& spec, int cores) { return placed_start(moved, spec, cores); },
        [&](std::size_t, const CyclicProgress& p) {
          if (o_.progress) o_.progress(source, p);
        });
  }
  const std::optional<PlacementProbe>& placement_probe() const { return probe_; }

  // Shared packings: one per seed (the design's, or `more`), kept in the output folder so
  // that a second call reuses them.
  void prepare_shared_packings(const std::vector<std::uint64_t>& more = {}) {
    if (o_.preparation != TwinPreparation::shared) return;
    for (std::uint64_t seed : more.empty() ? seeds_ : more) {
      if (shared_.count(seed)) continue;
      const fs::path path = o_.out / ("packing_seed_" + std::to_string(seed) + ".checkpoint.h5");
      RunSettings settings = settings_;
      settings["seed"] = std::to_string(seed);
      if (fs::exists(path)) {
        ProtocolState state;
        shared_.emplace(seed, read_checkpoint(path, &state));
        if (!same_packing_settings(state.settings, settings)) {
          throw Error(path.string() + ": deposited with other settings; remove it or " +
                      "choose another --out");
        }
        say("reusing the packing of " + path.string());
        continue;
      }
      say("depositing " + std::to_string(deposit_.grains) + " grains (seed " +
          std::to_string(seed) + ")");
      DepositOptions pour = deposit_;
      pour.seed = seed;
      shared_.emplace(seed, deposit(pour, physics_, nullptr, o_.deposit_progress));
      ProtocolState state;
      state.settings = settings;
      write_checkpoint(path, shared_.at(seed), state);
    }
  }

  // Runs those of `specs` not already finished in the runs folder with the same settings.
  void run(const std::vector<FrictionRunSpec>& specs) const {
    std::vector<FrictionRunSpec> todo;
    for (const FrictionRunSpec& spec : specs)
      if (!finished_run(path(spec), series_.protocol.parameters, series_.protocol.cycles)) {
        todo.push_back(spec);
      }
    if (todo.size() < specs.size()) {
      say("reusing " + std::to_string(specs.size() - todo.size()) + " finished runs in " +
          series_.dir.string());
    }
    if (todo.empty()) return;
    const int at_once =
        series_.parallel > 0 ? series_.parallel : int(std::thread::hardware_concurrency());
    say(std::to_string(todo.size()) + " runs, " + std::to_string(at_once) + " at once");
    auto start = [&](const FrictionRunSpec& spec, int cores) {
      if (o_.preparation == TwinPreparation::shared) {
        return with_frictions(shared_.at(spec.seed), spec, series_.walls_follow);
      }
      if (o_.preparation == TwinPreparation::experiment) return placed_start(*placed_, spec, cores);
      return deposit_at_friction(deposit_, physics_, spec, series_.walls_follow, cores);
    };
    run_friction_series(todo, series_, start, [&](std::size_t k, const CyclicProgress& p) {
      if (o_.progress) o_.progress(todo[k], p);
    });
  }

  fs::path path(const FrictionRunSpec& spec) const { return friction_run_path(series_.dir, spec); }

  void say(const std::string& line) const {
    if (o_.log) o_.log(line);
  }

 private:
  // A run's packing placed at `grains` (its seed's jitter added) and settled at its friction.
  Simulation placed_start(const Grains& grains, const FrictionRunSpec& spec, int cores) const {
    DepositOptions settling = deposit_;
    settling.threads = Simulation::threads_on_own_cores(grains.size(), cores);
    return settled_packing(jittered(grains, placed_jitter_, spec.seed, deposit_), settling,
                           with_frictions(physics_, spec, series_.walls_follow),
                           GrainPlacement::at_rest);
  }

  FrictionSeriesOptions series_options() const {
    FrictionSeriesOptions series;
    series.dir = o_.out / "runs";
    series.walls_follow = wall_friction_follows(settings_);
    if (o_.joint() && series.walls_follow != (settings_.at("wall-mu-r") == "same")) {
      throw Error(
          "--fit mu_s,mu_r: give the walls' sliding and rolling frictions alike (both "
          "'same', following the grains', or both fixed)");
    }
    series.parallel = o_.parallel;
    series.stop = o_.stop;
    series.protocol.cycles = observe.window.second;
    series.protocol.first_cycle = placed_cycle_;
    series.protocol.drive = drive_from(settings_, physics_, deposit_.box_side, deposit_.box_side,
                                       deposit_.lid_mass, deposit_.radius);
    // The twin's own settings only: what calibrate sets per run (cycles, mu_s) is written
    // as such, not as a config's leftover that would keep a finished run from being reused.
    for (const auto& [key, value] : settings_)
      if (is_twin_setting(key)) series.protocol.parameters["simulate/" + key] = value;
    if (o_.preparation == TwinPreparation::shared)  // its packings poured at this friction
      series.protocol.parameters["simulate/mu-s"] = settings_.at("mu-s");
    series.protocol.parameters["calibrate/deposit"] = preparation_name(o_.preparation);
    if (placed_) {  // runs placed from another experiment's packing are other runs
      series.protocol.parameters["calibrate/placed_from"] = placed_identity(*placed_);
      series.protocol.parameters["calibrate/placed_jitter"] = number_text(placed_jitter_) + " m";
      series.protocol.parameters["calibrate/placed_settling_damping"] =
          number_text(deposit_.placed_settling_damping) + " 1/s";
      series.protocol.parameters["calibrate/placed_cycle"] = std::to_string(placed_cycle_);
    }
    series.protocol.validate(deposit_.box_side, physics_.dt);
    return series;
  }

 public:
  // Whether the twin's packings of this seed pour the experiment's own grains (a
  // pseudo-experiment poured with it). A placed twin's seeds draw jitters, not pours.
  bool pours_experiments_grains(std::uint64_t seed) const {
    const std::string* stored = stored_setting(experiment_.header(), "seed");
    if (!stored || o_.preparation == TwinPreparation::experiment) return false;
    try {
      return std::stoull(*stored) == seed;
    } catch (const std::exception&) {
      return false;
    }
  }

 private:
  void note_experiment_seed() const {
    for (std::uint64_t s : seeds_) {
      if (pours_experiments_grains(s)) {
        say("note: the twin's seeds include the experiment's (" + std::to_string(s) +
            "): one twin run pours the experiment's own grains");
      }
    }
  }

  const CalibrateOptions& o_;
  const TrajectoryReader& experiment_;
  std::pair<std::size_t, std::size_t> located_{0, 0};  // count_located_grains()
  RunSettings settings_;
  PhysicsOptions physics_;
  DepositOptions deposit_;
  FrictionSeriesOptions series_;
  std::vector<std::uint64_t> seeds_;
  std::map<std::uint64_t, Simulation> shared_;
  std::optional<Grains> placed_;  // --deposit experiment: its frame's grains
  std::optional<PlacementProbe> probe_;
  double placed_jitter_ = 0;       // m
  std::int64_t placed_cycle_ = 0;  // the experiment's cycle they were placed from
};

// The simulations the fit stands on: the twin's runs and its placement probe.
std::size_t simulations_fitted(const Twin& twin, const std::vector<FrictionRunSpec>& specs) {
  return specs.size() + (twin.placement_probe() ? 1 : 0);
}

std::size_t simulations_with(const Twin& twin, const std::vector<FrictionRunSpec>& specs,
                             const FrictionRunSpec& best) {
  const bool simulated = std::any_of(specs.begin(), specs.end(), [&](const auto& r) {
    return r.mu_s == best.mu_s && r.seed == best.seed && r.mu_r == best.mu_r;
  });
  return simulations_fitted(twin, specs) + (twin.options().fit_only || simulated ? 0 : 1);
}

// The run the experiment is compared with: the twin's run nearest the fit (in ln mu_s, and
// ln mu_r jointly) where one is `compatible` with it (inside its 95 % interval or region),
// as the data cannot tell it from the fit and it costs no simulation more (a staged
// design's refined packings usually are); else `at_fit`, run for the comparison. Never a
// run that pours the experiment's own grains: it would compare the experiment with itself.
FrictionRunSpec compared_run(const Twin& twin, const std::vector<FrictionRunSpec>& specs,
                             const FrictionRunSpec& at_fit,
                             const std::function<bool(const FrictionRunSpec&)>& compatible) {
  const auto distance = [&](const FrictionRunSpec& r) {
    const double ds = std::log(r.mu_s / at_fit.mu_s);
    const double dr = at_fit.mu_r > 0 ? std::log(r.mu_r / at_fit.mu_r) : 0.0;
    return ds * ds + dr * dr;
  };
  const FrictionRunSpec* nearest = nullptr;
  for (const FrictionRunSpec& r : specs) {
    if (!compatible(r) || twin.pours_experiments_grains(r.seed)) continue;
    if (!nearest || distance(r) < distance(*nearest)) nearest = &r;
  }
  return nearest ? *nearest : at_fit;
}

// The line that says which run the comparison is at, where it is not a run at the fit.
std::string compared_run_line(const FrictionRunSpec& compared, const FrictionRunSpec& at_fit) {
  if (compared.mu_s == at_fit.mu_s && compared.mu_r == at_fit.mu_r && compared.seed == at_fit.seed)
    return {};
  std::string line =
      "compared at the twin's run nearest the fit, mu_s " + number_text(compared.mu_s);
  if (compared.mu_r >= 0) line += ", mu_r " + number_text(compared.mu_r);
  return line + " (seed " + std::to_string(compared.seed) + "), inside the 95% " +
         (compared.mu_r >= 0 ? "region" : "interval") + ": no simulation more\n";
}

// "12 simulations", and where the comparison took one more at the fit, says so: the fit's
// own runs are the design's.
std::string simulations_text(const CalibrateSummary& s) {
  std::string text = std::to_string(s.simulations_fitted) + " simulations";
  if (s.simulations > s.simulations_fitted) text += ", 1 more at the fit for the comparison";
  return text;
}

// The twin at the fit (unless fit_only) compared with the experiment: the distances, the
// comparison's figures and lines.
Comparison compare_at_fit(const Twin& twin, const FrictionRunSpec& best,
                          Eigen::Vector3d noise_shape, double noise_sigma) {
  if (twin.options().fit_only) return {};
  twin.run({best});
  if (!mpi_ranks().root()) return {};
  std::string label = "DEM mu_s = " + number_text(best.mu_s);
  if (best.mu_r >= 0) label += ", mu_r = " + number_text(best.mu_r);
  return compare_runs(twin.experiment(), TrajectoryReader(twin.path(best)), "experiment", label,
                      twin.observe, noise_shape, noise_sigma, twin.options().out, {},
                      twin.first_cycle());
}

// The members every summary.json ends with.
void add_protocol(JsonObject& j, const Twin& twin) {
  j["window"] = {twin.observe.window.first, twin.observe.window.second};
  if (twin.options().preparation == TwinPreparation::experiment)
    j["placed_cycle"] = twin.first_cycle();
  j["experiment"] = twin.options().experiment.string();
  j["settings"] = twin.settings();
}

// The scans' locating error (m, along x, y and z) given to a run's positions, in the run's
// unit, each run its own draws; none where it is zero.
PositionNoise run_position_noise(const FrictionRunSpec& spec, const Eigen::Vector3d& error,
                                 const TrajectoryReader& r) {
  PositionNoise noise;
  if (error.isZero()) return noise;
  noise.sigma = error / metres_per_length(r);
  noise.seed = fnv1a(&spec.mu_s, sizeof spec.mu_s,
                     fnv1a(&spec.mu_r, sizeof spec.mu_r, fnv1a(&spec.seed, sizeof spec.seed)));
  return noise;
}

// The steady state of the twin's run `spec` stored at `path` (its own, or its placement
// probe's), its positions and displacements given the scans' errors (twin_steady_states).
SteadyState twin_run_steady_state(const Twin& twin, const fs::path& path,
                                  const FrictionRunSpec& spec,
                                  const Eigen::Vector3d& position_noise,
                                  const Eigen::Vector3d& displacement_noise) {
  ObservableOptions observe = twin.observe;
  observe.position_noise = displacement_noise;
  const TrajectoryReader r(path);
  PositionNoise noise = run_position_noise(spec, position_noise, r);
  SteadyState s = steady_state(r, cycle_observables(r, observe), {}, {}, noise);
  if (const auto cycle = twin.cycle_before_window()) {
    noise.seed = fnv1a(&*cycle, sizeof *cycle, noise.seed);  // that frame's own draws
    add_height_before_window(s, r, *cycle, {}, noise);
  }
  return s;
}

// The twin's runs' steady states. `position_noise` (m, along x, y and z): the scans'
// locating error, given to every run's positions before their structure is measured, each
// run its own draws; `displacement_noise` (m): the per-frame error that moves the scans'
// displacements, given to the positions their displacements are measured from.
std::vector<SteadyStateRun> twin_steady_states(
    const Twin& twin, const std::vector<FrictionRunSpec>& specs,
    const Eigen::Vector3d& position_noise = Eigen::Vector3d::Zero(),
    const Eigen::Vector3d& displacement_noise = Eigen::Vector3d::Zero()) {
  std::vector<SteadyStateRun> runs;
  for (const FrictionRunSpec& spec : specs) {
    const SteadyState state =
        twin_run_steady_state(twin, twin.path(spec), spec, position_noise, displacement_noise);
    runs.push_back({spec.mu_s, spec.seed, state, spec.mu_r});
  }
  return runs;
}

// The placement probe's window less its source run's, both measured as the twin's runs are
// (twin_steady_states, the same draws of the scans' error); empty without a probe.
SteadyState placement_probe_effect(const Twin& twin, const Eigen::Vector3d& position_noise,
                                   const Eigen::Vector3d& displacement_noise) {
  const std::optional<PlacementProbe>& probe = twin.placement_probe();
  if (!probe) return {};
  const auto measured = [&](const fs::path& path) {
    return twin_run_steady_state(twin, path, probe->source, position_noise, displacement_noise);
  };
  const SteadyState source = measured(twin.path(probe->source));
  SteadyState effect = measured(probe->path);
  for (std::size_t k = 0; k < effect.names.size(); ++k)
    effect.values[k] -= source[effect.names[k]];
  effect.drift.clear();
  return effect;
}

// The steady-state fit's outputs: the runs' window means (steady_state_runs.csv), the
// figure, and the summary's per-observable part.
struct SteadyStateOutputs {
  std::vector<fs::path> written;
  std::vector<std::string> notes;  // observables that still drift across the window
  JsonObject observables;          // the "observables" member of summary.json
};

void write_steady_state_runs(const fs::path& out, const ObservableFit& fit,
                             const std::vector<SteadyStateRun>& runs) {
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
            {"the twin's steady state: window means per run (dr and rot_disp in grain diameters, "
             "wall force in N)"});
}

// A fit at the lowest or highest friction the twin simulated is held there by the fit's
// bounds: the experiment's may lie beyond, and the design must reach past it.
std::string design_edge_note(double mu_s, const std::vector<SteadyStateRun>& runs) {
  const auto [lo, hi] = std::minmax_element(
      runs.begin(), runs.end(),
      [](const SteadyStateRun& a, const SteadyStateRun& b) { return a.mu_s < b.mu_s; });
  const bool low = mu_s<lo->mu_s * 1.01, high = mu_s> hi->mu_s / 1.01;
  if (!low && !high) return {};
  const double edge = low ? lo->mu_s : hi->mu_s;
  return "the fit is at the twin's " + std::string(low ? "lowest" : "highest") + " mu_s, " +
         number_text(edge) +
         ": the experiment's may lie beyond it; simulate past it (--mu-s with " +
         number_text(low ? edge / 2 : edge * 2) + ")";
}

SteadyStateOutputs write_steady_state_fit(const fs::path& out, const ObservableFit& fit,
                                          const SteadyState& experiment,
                                          const std::vector<SteadyStateRun>& runs, double true_mu_s,
                                          CycleRange window) {
  SteadyStateOutputs o;
  write_steady_state_runs(out, fit, runs);
  o.written.push_back(out / "steady_state_runs.csv");
  std::map<std::uint64_t, int> packing;
  for (const SteadyStateRun& r : runs)
    packing.emplace(r.seed, int(packing.size()));
  std::vector<ObservablePanel> panels;
  for (std::size_t k = 0; k < fit.names.size(); ++k) {
    const std::string& name = fit.names[k];
    ObservablePanel p;
    p.label = steady_state_label(name);
    for (const SteadyStateRun& r : runs) {
      p.run_mu_s.push_back(r.mu_s);
      p.run_value.push_back(r.state[name]);
      p.run_packing.push_back(packing.at(r.seed));
    }
    p.curve_mu_s = fit.curve_mu_s;
    p.curve = fit.curve[k];
    p.experiment = experiment[name];
    p.experiment_error = std::hypot(fit.scatter[k], experiment.systematic_of(name));
    panels.push_back(std::move(p));
    double twin_drift = 0;
    for (const SteadyStateRun& r : runs)
      twin_drift += r.state.drift_of(name) / double(runs.size());
    // The twin's mean over its runs says it for the protocol; one run's drift is noisy.
    if (std::abs(twin_drift) > fit.scatter[k]) {
      o.notes.push_back(name + " still changes by " + number_text(twin_drift) +
                        " across the window (the twin's runs' mean; one packing's scatter " +
                        number_text(fit.scatter[k]) + "): not yet a steady state");
    }
    o.observables[name] = {{"experiment", experiment[name]},
                           {"drift_over_window", experiment.drift_of(name)},
                           {"twin_drift_over_window", twin_drift},
                           {"model_at_fit", fit.model[k]},
                           {"packing_scatter", fit.scatter[k]},
                           {"log_mu_s_resolution", fit.resolution[k]},
                           {"experiment_systematic", experiment.systematic_of(name)}};
  }
  if (const std::string edge = design_edge_note(fit.mu_s, runs); !edge.empty())
    o.notes.push_back(edge);
  char title[200];
  std::snprintf(title, sizeof title, "means over cycles %lld-%lld: mu_s = %.3g (95%% %.3g-%.3g)%s",
                static_cast<long long>(window.first), static_cast<long long>(window.second),
                fit.mu_s, fit.mu_s_ci95[0], fit.mu_s_ci95[1],
                std::isfinite(true_mu_s) ? (", true " + number_text(true_mu_s)).c_str() : "");
  const auto figure =
      plot_observable_fit(out, "observable_fit", panels, fit.mu_s, fit.mu_s_ci95, true_mu_s, title);
  o.written.insert(o.written.end(), figure.begin(), figure.end());
  return o;
}

std::string observables_line(const Twin& twin, const std::vector<std::string>& names,
                             const std::vector<double>* resolution) {
  std::ostringstream line;
  line << std::setprecision(3) << "  steady state over cycles " << twin.observe.window.first << "-"
       << twin.observe.window.second << ":";
  for (std::size_t k = 0; k < names.size(); ++k) {
    line << (k ? ", " : " ") << names[k];
    if (resolution) line << " (+-" << (*resolution)[k] << " in ln mu_s)";
  }
  return line.str() + "\n";
}

// The run at the fit's comparison: its lines first in the report, its notes and files kept.
void add_comparison(CalibrateSummary& s, std::ostream& report, const Comparison& c) {
  s.notes.insert(s.notes.end(), c.notes.begin(), c.notes.end());
  s.written.insert(s.written.end(), c.written.begin(), c.written.end());
  report << c.Report();
}

// The twin's runs fitted to the experiment's steady state: mu_s alone, or with mu_r.
ObservableFitOptions observable_fit_options(const Twin& twin) {
  ObservableFitOptions fo;
  fo.degree = twin.trend_degree();
  return fo;
}

// The twin's runs at the friction (pair) nearest (mu_s, mu_r), in ln mu_s (and ln mu_r,
// joint), every packing's, in the runs' order.
std::vector<FrictionRunSpec> runs_nearest(const std::vector<SteadyStateRun>& runs, double mu_s,
                                          double mu_r) {
  const auto distance = [&](const SteadyStateRun& r) {
    return std::abs(std::log(r.mu_s / mu_s)) +
           (std::isfinite(mu_r) && r.mu_r > 0 ? std::abs(std::log(r.mu_r / mu_r)) : 0.0);
  };
  const auto nearest = std::min_element(
      runs.begin(), runs.end(), [&](auto& a, auto& b) { return distance(a) < distance(b); });
  std::vector<FrictionRunSpec> at;
  for (const SteadyStateRun& r : runs)
    if (r.mu_s == nearest->mu_s && r.mu_r == nearest->mu_r) at.push_back({r.mu_s, r.seed, r.mu_r});
  return at;
}

// The scans' errors read from their contacts against the twin's run nearest (mu_s, mu_r).
struct ContactsReading {
  ContactLocatingError positions;
  DisplacementError displacements;
};
// The scans' locating error read from their contacts (contact_locating_error.hpp) against
// the twin's run nearest `mu_s`: for scans of grains known to be alike (a simulated
// experiment's positions are exact), poured or placed (a placed run's distances are the
// DEM's once settled: on 0.31's scans 7.13 and 15.1 um against a placed run, 7.19 and 15.1
// against a poured one); NaN errors elsewhere. In metres.
ContactsReading errors_from_contacts(const Twin& twin, const std::vector<SteadyStateRun>& runs,
                                     double mu_s, double mu_r) {
  const KnownGrains known = twin.known_grains();
  if (!twin.experiment().header().voxel_size || !known.radius || runs.empty()) return {};
  const TrajectoryReader reference(twin.path(runs_nearest(runs, mu_s, mu_r).front()));
  const double diameter = 2 * *known.radius;
  return {locating_error_from_contacts(twin.experiment(), reference, diameter),
          displacement_error_from_contacts(twin.experiment(), reference, diameter,
                                           twin.observe.window)};
}

// An observable the scans' own noise moves by more than a share of one packing's scatter
// pulls the fit by the noise, not by friction (a contact count within a 2 % gap, at a
// locating error of 1 % of a diameter). Measured by moving the experiment's positions by
// their error once more (its axes by tilting them once more). Where the twin gets the same
// noise (its positions the error the scans' contacts read, its axes their axis error) only
// the noise's size's error can bias the fit: ~10 % in the axes' (docs/BENCHMARKS.md), ~20 %
// of the noise's part where that grows as sigma^2 (the contacts' reading is closer, 1 %,
// docs/CALIBRATION.md); so such an observable is left out where kModelledNoise of the move
// could exceed one packing's scatter (the noise then most of what is measured). Where the
// twin's stay exact (no contacts to read the error from, --axis-noise 0) the positions are
// judged by locate's standard errors, which a scan's actual error exceeds 2-3x
// (docs/BENCHMARKS.md), so by a quarter of a scatter (the effects grow as sigma^2: 1-2
// scatters at the actual error). The displacements likewise: where the scans' persistent
// contacts give the per-frame error that moves them (a scan's errors in consecutive frames
// are partly shared: an independent error of the contacts' size moves them ~1.8x as far,
// the persistent contacts' reading 0.95-1.15x, docs/CALIBRATION.md) the twin's get it and
// they are judged as modelled; elsewhere by a quarter of a scatter.
constexpr double kNoiseShare = 0.25;
constexpr double kModelledNoise = 0.2;
struct NoiseLimited {
  std::string name;
  double effect, scatter;
  bool modelled;        // the twin adds the same noise (its axes', positions' or displacements')
  bool dropped = true;  // false: kept, as the fit needs more observables than the rest
};

// A placed twin's packing read back at the experiment's frame it was placed from: the mean
// over the runs nearest the fit of their structure there (their positions given the scans'
// error where their contacts read one) less the experiment's own. What the twin does not
// reproduce of the experiment's structure before any cycle: the settle's (the lost contact
// history) and what the scans' error model misses. The fit carries it as the experiment's
// systematic error: taken as an offset that persists into the window (the experiment's
// values moved by it) it moved the scanned cases' fits further from their truth, and chi2
// up 2-7x (docs/CALIBRATION.md).
struct PlacedReadBack {
  SteadyState less_experiment;
  std::vector<FrictionRunSpec> runs;
};
PlacedReadBack placed_read_back(const Twin& twin, const std::vector<SteadyStateRun>& runs,
                                double mu_s, double mu_r, const Eigen::Vector3d& error) {
  PlacedReadBack p;
  if (!twin.placed() || runs.empty()) return p;
  p.runs = runs_nearest(runs, mu_s, mu_r);
  const std::int64_t cycle = twin.first_cycle();
  const SteadyState own = frame_structure(twin.experiment(), cycle, {}, twin.known_grains());
  p.less_experiment.names = own.names;
  p.less_experiment.values.assign(own.names.size(), 0.0);
  for (const FrictionRunSpec& spec : p.runs) {
    const TrajectoryReader run(twin.path(spec));
    const SteadyState placed =
        frame_structure(run, cycle, {}, {}, run_position_noise(spec, error, run));
    for (std::size_t k = 0; k < own.names.size(); ++k)
      p.less_experiment.values[k] += (placed[own.names[k]] - own.values[k]) / double(p.runs.size());
  }
  return p;
}

// The experiment's steady state with a placed packing's read-back and its placement probe's
// effect (where there is one) as its systematic errors, in quadrature; an observable read at
// the frame before the window carries its structure's read-back, as the window's does.
SteadyState with_systematic(SteadyState experiment, const PlacedReadBack& placed,
                            const SteadyState& probe) {
  experiment.systematic.assign(experiment.names.size(), 0.0);
  for (std::size_t k = 0; k < experiment.names.size(); ++k) {
    double sum = 0;
    const std::string& name = experiment.names[k];
    for (double d : {placed.less_experiment[structure_read_as(name)], probe[name]})
      if (std::isfinite(d)) sum += d * d;
    experiment.systematic[k] = std::sqrt(sum);
  }
  return experiment;
}

// What the scans' noise does to the fit: the observables it leaves out, and the errors
// their contacts read where they were read (then given to the twin's positions and
// displacements).
struct ScanNoise {
  std::vector<NoiseLimited> limited;
  ContactLocatingError contacts;
  DisplacementError displacements;
  PlacedReadBack placed;
  SteadyState probe;       // the placement probe less its source run
  SteadyState experiment;  // as fitted: with the read-back and the probe as its systematic errors
};

template <class E>
bool read_from_contacts(const E& e) {
  return std::isfinite(e.across) && std::isfinite(e.along_z);
}

// An error read from the contacts along x, y and z, m.
template <class E>
Eigen::Vector3d position_noise(const E& e) {
  return Eigen::Vector3d(e.across, e.across, e.along_z);
}

double fitted_mu_r(const ObservableFit&) {
  return std::nan("");
}
double fitted_mu_r(const JointObservableFit& f) {
  return f.mu_r;
}

// The window means of the per-cycle mean displacements (the steady state's "dr" and
// "rot_disp"), without the structure steady_state() measures from every frame.
SteadyState window_mean_motion(const CycleObservables& o) {
  ObservableSeries s;
  s.entries.push_back({"dr", o.cycle, o.mean_dr, false});
  s.entries.push_back({"rot_disp", o.cycle, o.mean_rot_disp, false});
  return window_means(s, o.window);
}

std::vector<NoiseLimited> noise_limited(const Twin& twin, const std::vector<std::string>& names,
                                        const std::vector<double>& scatter,
                                        const ScanNoise& noise) {
  const bool positions_modelled = read_from_contacts(noise.contacts);
  const Eigen::Vector3d e =
      positions_modelled ? position_noise(noise.contacts) / metres_per_length(twin.experiment())
                         : twin.errors.position;
  const bool displacements_modelled = read_from_contacts(noise.displacements);
  const Eigen::Vector3d moved_by = displacements_modelled
                                       ? position_noise(noise.displacements)
                                       : Eigen::Vector3d(e * metres_per_length(twin.experiment()));
  SteadyState effect;
  double displacement = std::nan("");
  if (e.allFinite() && !e.isZero()) {
    effect =
        structure_noise_effect(twin.experiment(), twin.observe.window, e, {}, twin.known_grains());
  }
  if (moved_by.allFinite() && !moved_by.isZero()) {
    const CycleObservables moved =
        measured_observables(twin.experiment(), twin.observe, 0, moved_by);
    displacement = window_mean_motion(moved)["dr"] - twin.measured_steady_state()["dr"];
  }
  double rotation = std::nan("");
  if (twin.errors.axis > 0 && twin.observe.rotations) {
    const CycleObservables tilted =
        measured_observables(twin.experiment(), twin.observe, twin.errors.axis);
    rotation = window_mean_motion(tilted)["rot_disp"] - twin.measured_steady_state()["rot_disp"];
  }
  std::vector<NoiseLimited> limited;
  for (std::size_t k = 0; k < names.size(); ++k) {
    const bool rotation_k = names[k] == "rot_disp", displacement_k = names[k] == "dr";
    const bool modelled = rotation_k       ? twin.observe.axis_noise > 0
                          : displacement_k ? displacements_modelled
                                           : positions_modelled;
    const double d = rotation_k       ? rotation
                     : displacement_k ? displacement
                                      : effect[structure_read_as(names[k])];
    if (std::isfinite(d) &&
        std::abs(d) * (modelled ? kModelledNoise : 1) > (modelled ? 1 : kNoiseShare) * scatter[k])
      limited.push_back({names[k], d, scatter[k], modelled});
  }
  return limited;
}

// The twin's runs fitted to the experiment, as a scan would see them: where the scans'
// contacts give their locating error (read against the run nearest a first fit of the runs'
// exact positions), the runs' positions are given it before their structure is measured,
// and the fit is made again; a placed twin's then again with its packing's read-back as the
// experiment's systematic errors; then without the observables the scans' noise still
// moves, unless they were chosen with --only. `fewest`: the observables the fit needs.
// `runs`: the runs' steady states as fitted.
template <class Fit, class FitTo>
Fit fit_as_scanned(const Twin& twin, const std::vector<FrictionRunSpec>& specs, FitTo fit_to,
                   std::size_t fewest, std::vector<SteadyStateRun>& runs, ScanNoise* noise) {
  const std::vector<std::string>& only = twin.options().only;
  SteadyState experiment = twin.measured_steady_state();
  runs = twin_steady_states(twin, specs);
  Fit fit = fit_to(experiment, runs, only);
  ScanNoise found;
  const ContactsReading read = errors_from_contacts(twin, runs, fit.mu_s, fitted_mu_r(fit));
  found.contacts = read.positions;
  found.displacements = read.displacements;
  const auto given = [](const auto& e) {
    return read_from_contacts(e) ? position_noise(e) : Eigen::Vector3d::Zero().eval();
  };
  if (read_from_contacts(found.contacts) || read_from_contacts(found.displacements)) {
    runs = twin_steady_states(twin, specs, given(found.contacts), given(found.displacements));
    fit = fit_to(experiment, runs, only);
  }
  found.placed = placed_read_back(twin, runs, fit.mu_s, fitted_mu_r(fit), given(found.contacts));
  found.probe = placement_probe_effect(twin, given(found.contacts), given(found.displacements));
  if (!found.placed.runs.empty() || !found.probe.names.empty()) {
    experiment = with_systematic(experiment, found.placed, found.probe);
    fit = fit_to(experiment, runs, only);
  }
  found.experiment = experiment;
  if (only.empty()) found.limited = noise_limited(twin, fit.names, fit.scatter, found);
  std::vector<std::string> kept;
  for (const std::string& name : fit.names) {
    if (std::none_of(found.limited.begin(), found.limited.end(),
                     [&](const NoiseLimited& l) { return l.name == name; }))
      kept.push_back(name);
  }
  const bool refit_without = !found.limited.empty() && kept.size() >= fewest;
  for (NoiseLimited& l : found.limited)
    l.dropped = refit_without;
  if (noise) *noise = found;
  return refit_without ? fit_to(experiment, runs, kept) : fit;
}

ObservableFit steady_state_fit(const Twin& twin, const std::vector<FrictionRunSpec>& specs,
                               std::vector<SteadyStateRun>& runs, ScanNoise* noise = nullptr) {
  auto fit_to = [&](const SteadyState& experiment, const std::vector<SteadyStateRun>& r,
                    const std::vector<std::string>& names) {
    return fit_friction_to_steady_state(experiment, r, observable_fit_options(twin), names);
  };
  return fit_as_scanned<ObservableFit>(twin, specs, fit_to, 1, runs, noise);
}

JointObservableFit joint_steady_state_fit(const Twin& twin,
                                          const std::vector<FrictionRunSpec>& specs,
                                          std::vector<SteadyStateRun>& runs,
                                          ScanNoise* noise = nullptr) {
  auto fit_to = [&](const SteadyState& experiment, const std::vector<SteadyStateRun>& r,
                    const std::vector<std::string>& names) {
    return fit_frictions_to_steady_state(experiment, r, observable_fit_options(twin), names);
  };
  return fit_as_scanned<JointObservableFit>(twin, specs, fit_to, 2, runs, noise);
}

// The report's lines on the observables left out, and why; their names for summary.json.
void report_noise_limited(const ScanNoise& noise, std::ostream& report, JsonObject& j) {
  std::vector<std::string> names;
  for (const NoiseLimited& l : noise.limited) {
    const bool rotation = l.name == "rot_disp", displacement = l.name == "dr";
    const bool contacts =
        displacement ? read_from_contacts(noise.displacements) : read_from_contacts(noise.contacts);
    const std::string what = rotation ? "axes" : displacement ? "displacements" : "positions";
    report << std::setprecision(3) << "  note: " << l.name
           << (l.dropped ? " left out" : " kept, as the fit needs it,") << ": the scans' own "
           << (rotation ? "axis" : "locating") << " noise"
           << (!rotation && contacts ? " (their contacts' error)" : "") << " moves it by "
           << l.effect << " (one packing's scatter " << l.scatter << ")"
           << (l.modelled ? ", more than the twin's " +
                                std::string(rotation ? "tilted " : "moved ") + what + " model"
                          : " and the twin's " + what + " are exact")
           << (l.dropped ? " (--only keeps it)\n" : "\n");
    if (l.dropped) names.push_back(l.name);
  }
  j["left_out_for_scan_noise"] = names;
}

// The per-frame error that moves the scans' displacements, read from their persistent
// contacts.
void report_displacement_error(const DisplacementError& e, std::ostream& report, JsonObject& j) {
  if (!read_from_contacts(e)) return;
  const double um = 1e6;
  report << std::setprecision(3) << "  the scans' displacements err as by " << e.across * um
         << " um across the slices and " << e.along_z * um
         << " um along z in each frame, from the change of their persistent contacts ("
         << e.contacts << "); the twin's displacements were given this error\n";
  JsonObject c;
  c["across_um"] = e.across * um;
  c["along_z_um"] = e.along_z * um;
  c["contacts"] = e.contacts;
  c["given_to_twin"] = true;
  j["displacement_error_from_contacts"] = c;
}

// The scans' locating error read from their contacts, said beside locate's standard errors.
void report_contact_error(const Twin& twin, const ContactLocatingError& e, std::ostream& report,
                          JsonObject& j) {
  if (!read_from_contacts(e)) return;
  const double um = 1e6, stored = metres_per_length(twin.experiment()) * um;
  report << std::setprecision(3) << "  the scans' centres err by " << e.across * um
         << " um across the slices and " << e.along_z * um
         << " um along z, from the spread of their contacts against the twin's (" << e.pairs
         << " distances; a contact reads " << std::abs(e.offset) * um << " um "
         << (e.offset < 0 ? "short" : "long") << " on average)";
  if (twin.errors.position.allFinite()) {
    report << "; locate's standard errors say "
           << twin.errors.position.head<2>().norm() / std::sqrt(2.0) * stored << " and "
           << twin.errors.position.z() * stored << " um";
  }
  report << "; the twin's positions were given this error before their structure was "
            "measured\n";
  const double rms = std::sqrt((2 * e.across * e.across + e.along_z * e.along_z) / 3);
  const double diameter = 2 * twin.known_grains().radius.value_or(std::nan(""));
  if (twin.options().preparation == TwinPreparation::experiment &&
      rms > kPlaceableContactError * diameter) {
    report << std::setprecision(3) << "  note: placed where the scans' centres err by " << rms * um
           << " um RMS a coordinate, more than " << kPlaceableContactError
           << " d: the twin's packings settle denser than the scanned one was, leaning the fit "
              "to higher friction; --deposit each pours them\n";
  }
  JsonObject c;
  c["across_um"] = e.across * um;
  c["along_z_um"] = e.along_z * um;
  c["contact_offset_um"] = e.offset * um;
  c["distances"] = e.pairs;
  c["given_to_twin"] = true;
  j["locating_error_from_contacts"] = c;
}

// A difference of steady states carried as the experiment's systematic errors: each finite
// one on the report's line, ended there, and returned for summary.json.
JsonObject reported_as_systematic(const SteadyState& d, std::ostream& report) {
  JsonObject differences;
  report << std::setprecision(2);
  for (std::size_t k = 0; k < d.names.size(); ++k) {
    if (!std::isfinite(d.values[k])) continue;
    report << " " << d.names[k] << " " << std::showpos << d.values[k] << std::noshowpos;
    differences[d.names[k]] = d.values[k];
  }
  report << "; carried as the experiment's systematic errors\n";
  return differences;
}

// A placed twin's packing read back at the frame it was placed from: the structure of the
// run nearest the fit there (its positions given the scans' error where their contacts read
// one) minus the experiment's own. A settle that taps the placed packing denser than its
// frame leans the fit to higher friction (docs/CALIBRATION.md, "The placed packing tapped by
// its own settle").
// The placed packing's read-back, which the fit carried as the experiment's systematic errors.
void report_placed_frame(const Twin& twin, const PlacedReadBack& placed, std::ostream& report,
                         JsonObject& j) {
  if (placed.runs.empty()) return;
  report << std::setprecision(3) << "  the placed packing read back at its frame of cycle "
         << twin.first_cycle() << " (mu_s " << placed.runs.front().mu_s;
  if (placed.runs.front().mu_r >= 0) report << ", mu_r " << placed.runs.front().mu_r;
  report << ", " << placed.runs.size() << " packing" << (placed.runs.size() > 1 ? "s" : "")
         << "), less the experiment's:";
  j["placed_frame_less_experiment"] = reported_as_systematic(placed.less_experiment, report);
  j["placed_frame_runs"] = placed.runs.size();
}

// The placement probe's window less its source's, which the fit carried as the experiment's
// systematic errors (with the read-back, in quadrature).
void report_placement_probe(const Twin& twin, const SteadyState& probe, std::ostream& report,
                            JsonObject& j) {
  if (probe.names.empty()) return;
  const PlacementProbe& p = *twin.placement_probe();
  constexpr double um = 1e6;
  report << std::setprecision(3) << "  the placement probe (mu_s " << p.source.mu_s << " seed "
         << p.source.seed << " placed once more from its frame of cycle " << twin.first_cycle()
         << " moved by the scans' error, " << p.error.x() * um << ", " << p.error.y() * um
         << " and " << p.error.z() * um << " um along x, y and z), less that run:";
  JsonObject o;
  o["source"] = twin.path(p.source).filename().string();
  o["error_um"] = std::vector<double>{p.error.x() * um, p.error.y() * um, p.error.z() * um};
  o["less_source"] = reported_as_systematic(probe, report);
  j["placement_probe"] = o;
}

// Strictly inside the range of `simulated`.
bool interior(double mu, const std::vector<double>& simulated) {
  const auto [lo, hi] = std::minmax_element(simulated.begin(), simulated.end());
  return mu > *lo && mu < *hi;
}

// The design's fit, as the friction (pair) refined packings are added about, its line, and, for
// a twin placed from scans, their locating error (m along x, y, z; else zero): their
// contacts' reading where they give one, else their standard errors.
struct DesignFit {
  FrictionRunSpec at;
  std::string line;
  Eigen::Vector3d scan_error = Eigen::Vector3d::Zero();
};
DesignFit design_fit(const Twin& twin, const std::vector<FrictionRunSpec>& specs) {
  const CalibrateOptions& o = twin.options();
  std::ostringstream line;
  line << std::setprecision(3) << "the design's fit: ";
  FrictionRunSpec at;
  ScanNoise noise;
  std::vector<SteadyStateRun> runs;
  if (o.joint()) {
    const JointObservableFit f = joint_steady_state_fit(twin, specs, runs, &noise);
    at = {three_digits(f.mu_s), 0, three_digits(f.mu_r)};
    line << "mu_s = " << f.mu_s << " (95% interval " << f.mu_s_ci95[0] << " - " << f.mu_s_ci95[1]
         << "), mu_r = " << f.mu_r << " (" << f.mu_r_ci95[0] << " - " << f.mu_r_ci95[1] << ")";
  } else {
    const ObservableFit f = steady_state_fit(twin, specs, runs, &noise);
    at = {three_digits(f.mu_s), 0};
    line << "mu_s = " << f.mu_s << " (95% interval " << f.mu_s_ci95[0] << " - " << f.mu_s_ci95[1]
         << ")";
  }
  line << ", " << runs.size() << " runs";
  for (const NoiseLimited& l : noise.limited)
    if (l.dropped) line << ", without " << l.name << " (the scans' noise)";
  line << "; ";
  if (!twin.placed_from_scans()) return {at, line.str()};
  if (read_from_contacts(noise.contacts)) return {at, line.str(), position_noise(noise.contacts)};
  const Eigen::Vector3d stored = twin.errors.position * metres_per_length(twin.experiment());
  return {at, line.str(), stored.allFinite() ? stored : Eigen::Vector3d::Zero()};
}

// The refined packings' frictions as the report says them: "0.243 x2, 0.322".
std::string refined_frictions_text(const std::vector<FrictionRunSpec>& more) {
  std::string text;
  for (std::size_t k = 0; k < more.size();) {
    std::size_t same = k;
    while (same < more.size() && more[same].mu_s == more[k].mu_s)
      ++same;
    text += (k ? ", " : "") + number_text(more[k].mu_s) +
            (same - k > 1 ? " x" + std::to_string(same - k) : "");
    k = same;
  }
  return text;
}

// --refine: the design fitted, then packings more about its fit (CalibrateOptions::
// refined_mu_s), each a new seed. Within the design's range only: a fit at its edge says the
// range is wrong, not where to look.
std::vector<FrictionRunSpec> refined_design(Twin& twin, std::vector<FrictionRunSpec> specs,
                                            std::ostream& report) {
  const CalibrateOptions& o = twin.options();
  auto [at, line, scan_error] = design_fit(twin, specs);
  // Placed from scans (their error read) after the drive has begun, one of the packings is the
  // placement probe; placed from the preparation there is no training for the error to undo.
  const bool probe = !o.joint() && o.refined_packings() >= 2 &&
                     twin.placed_in_a_trained_packing() && (scan_error.array() > 0).any();
  const int packings = o.refined_packings() - (probe ? 1 : 0);
  if (!interior(at.mu_s, o.mu_s) || (o.joint() && !interior(at.mu_r, o.mu_r))) {
    line += "not refined: the fit is at the edge of the frictions simulated (widen the range)";
    twin.say(line);
    report << line << "\n";
    return specs;
  }
  std::vector<std::uint64_t> seeds;
  std::vector<FrictionRunSpec> more;
  for (double mu : o.refined_mu_s(at.mu_s, packings)) {
    seeds.push_back(twin.next_seed(int(more.size())));
    more.push_back({three_digits(mu), seeds.back(), at.mu_r});
  }
  line += std::to_string(packings) + " packing(s) more at mu_s " + refined_frictions_text(more) +
          (o.joint() ? ", mu_r " + number_text(at.mu_r) : "") +
          (packings > 1
               ? ", seeds " + std::to_string(seeds.front()) + "-" + std::to_string(seeds.back())
               : ", seed " + std::to_string(seeds.front())) +
          (probe ? ", and the first placed once more from its own frame moved by the scans' "
                   "error (the placement probe)"
                 : "");
  twin.say(line);
  twin.prepare_shared_packings(seeds);
  twin.run(more);
  if (probe) twin.run_placement_probe(more.front(), scan_error);
  specs.insert(specs.end(), more.begin(), more.end());
  report << line << "\n";
  return specs;
}

// summary.json's head for a fit of mu_s: the fit, its interval (s.mu_s_ci95), the truth,
// how the interval was made and the standard error of ln mu_s behind it.
JsonObject fitted_mu_s_json(double mu_s, const std::string& method, double log_mu_s_sigma,
                            const CalibrateSummary& s) {
  JsonObject j;
  j["mu_s"] = mu_s;
  j["mu_s_ci95"] = s.mu_s_ci95;
  j["mu_s_true"] = s.true_mu_s;
  j["mu_s_interval_method"] = method;
  j["log_mu_s_sigma"] = log_mu_s_sigma;
  return j;
}

void fit_steady_state(const Twin& twin, const std::vector<FrictionRunSpec>& specs,
                      CalibrateSummary& s, std::ostream& report) {
  const CalibrateOptions& o = twin.options();
  ScanNoise noise;
  std::vector<SteadyStateRun> runs;
  const ObservableFit fit = steady_state_fit(twin, specs, runs, &noise);
  const SteadyState& measured = noise.experiment;
  const FrictionRunSpec at_fit{three_digits(fit.mu_s), twin.seed()};
  const FrictionRunSpec best = compared_run(twin, specs, at_fit, [&](const FrictionRunSpec& r) {
    return r.mu_s >= fit.mu_s_ci95[0] && r.mu_s <= fit.mu_s_ci95[1];
  });
  const Comparison compared = compare_at_fit(twin, best, Eigen::Vector3d::Zero(), 0);
  if (!mpi_ranks().root()) return;
  if (!o.fit_only) report << compared_run_line(best, at_fit);
  add_comparison(s, report, compared);
  s.mu_s = fit.mu_s;
  s.mu_s_ci95 = {fit.mu_s_ci95[0], fit.mu_s_ci95[1]};
  s.simulations = simulations_with(twin, specs, best);
  s.simulations_fitted = simulations_fitted(twin, specs);
  const SteadyStateOutputs written =
      write_steady_state_fit(o.out, fit, measured, runs, s.true_mu_s, twin.observe.window);
  s.written.insert(s.written.end(), written.written.begin(), written.written.end());
  JsonObject j = fitted_mu_s_json(fit.mu_s, fit.method, fit.log_mu_s_sigma, s);
  j["gls_sigma"] = fit.gls_sigma;
  j["systematic_sigma"] = fit.systematic_sigma;
  j["cross_validated_sigma"] = fit.cross_validated_sigma;
  j["chi2"] = fit.chi2;
  j["dof"] = fit.dof;
  j["n_simulations"] = s.simulations;
  j["n_simulations_fitted"] = s.simulations_fitted;
  j["replicas"] = o.replicas;
  j["deposit"] = preparation_name(o.preparation);
  j["axis_noise_deg"] = twin.observe.axis_noise * 180 / M_PI;
  j["axis_noise_from"] = o.axis_noise                  ? "given"
                         : twin.observe.axis_noise > 0 ? "experiment"
                                                       : "none";
  std::vector<double> simulated;
  for (const FrictionRunSpec& spec : specs)
    simulated.push_back(spec.mu_s);
  std::sort(simulated.begin(), simulated.end());
  simulated.erase(std::unique(simulated.begin(), simulated.end()), simulated.end());
  j["mu_s_simulated"] = simulated;
  j["refine"] = o.refined_packings();
  j["refined"] = specs.size() - o.mu_s.size() * std::size_t(o.replicas);  // 0 at the edge
  j["observables"] = written.observables;
  std::ostringstream left_out;
  report_noise_limited(noise, left_out, j);
  report_contact_error(twin, noise.contacts, left_out, j);
  report_displacement_error(noise.displacements, left_out, j);
  report_placed_frame(twin, noise.placed, left_out, j);
  report_placement_probe(twin, noise.probe, left_out, j);
  add_protocol(j, twin);
  write_json(o.out / "summary.json", j);
  report << std::setprecision(3) << "mu_s = " << fit.mu_s << "  (95% interval " << fit.mu_s_ci95[0]
         << " - " << fit.mu_s_ci95[1] << ", " << simulations_text(s) << ")";
  if (std::isfinite(s.true_mu_s)) report << "  true " << s.true_mu_s;
  report << "\n" << observables_line(twin, fit.names, &fit.resolution);
  report << "  chi2 " << fit.chi2 << " for " << fit.dof << " dof; +-" << fit.gls_sigma
         << " in ln mu_s from the fit";
  if (fit.systematic_sigma > 0)
    report << " (" << fit.systematic_sigma << " of it the experiment's systematic errors)";
  report << ", cross-validated " << fit.cross_validated_sigma << " in ln mu_s at the fit from "
         << fit.cross_validations << " runs\n";
  report << left_out.str();
  for (const std::string& note : written.notes)
    report << "  note: " << note << "\n";
  report << "wrote " << (o.out / "summary.json").string() << ", steady_state_runs.csv, "
         << written.written.size() - 1 + compared.written.size() << " figure files\n";
}

// One cycle ahead (CalibrateOptions::one_cycle_ahead): the experiment's cycles each a
// segment, its frame before it the twin's start, its own frame the compared.
std::vector<std::int64_t> ahead_cycles(const Twin& twin) {
  const CalibrateOptions& o = twin.options();
  const auto [first, last] = twin.observe.window;
  if (last - first + 1 < 3) {
    throw Error(
        "--one-cycle-ahead: a window of at least 3 cycles (their scatter is the fit's "
        "error); this one has " +
        std::to_string(last - first + 1));
  }
  const std::vector<std::int64_t> cycles =
      comparable_ahead_cycles(twin.experiment(), twin.observe.window, o.ahead_burn_in);
  if (cycles.size() < 3) {
    throw Error("--one-cycle-ahead: " + o.experiment.string() + " has what " +
                std::to_string(cycles.size()) + " of the window's cycles " + std::to_string(first) +
                "-" + std::to_string(last) + " need (each its frame and a placeable one " +
                std::to_string(o.ahead_burn_in + 1) +
                " before it, and any between); at least 3 (their scatter is the fit's error)");
  }
  return cycles;
}

// A segment's trend in ln mu_s across the ahead packing's four frictions (kOneCycleAheadSpan).
constexpr int kOneCycleAheadDegree = 2;

// A segment's options: the ahead packing (`mu`, its own seed) placed from cycle - 1 (less
// the burn-in) and compared over that cycle alone, in its own folder.
CalibrateOptions segment_options(const CalibrateOptions& o, std::int64_t cycle,
                                 const std::vector<double>& mu, std::uint64_t seed) {
  CalibrateOptions s = o;
  s.one_cycle_ahead = false;
  s.ahead_burn_in = 0;
  s.placed_cycle = cycle - 1 - o.ahead_burn_in;
  s.window = std::pair{cycle, cycle};
  s.out = o.out / "ahead" /
          ("cycle_" + std::to_string(cycle) +
           (o.ahead_burn_in ? "_from_" + std::to_string(*s.placed_cycle) : std::string()));
  s.mu_s = mu;
  s.replicas = 1;
  s.refine = 0;
  s.degree = kOneCycleAheadDegree;
  s.fit_only = true;
  s.twin["seed"] = std::to_string(seed);
  return s;
}

// One segment's experiment and runs as the scans see them (fit_as_scanned: the runs given
// the scans' error, the placed read-back as the experiment's systematic errors) and the
// observables its fit keeps.
SteadyStateSegment ahead_segment(const CalibrateOptions& so, const Twin& twin,
                                 std::vector<std::string>& kept) {
  fs::create_directories(so.out / "runs");
  Twin segment(so, twin.experiment());
  const std::vector<FrictionRunSpec> specs = segment.design();
  segment.run(specs);
  ScanNoise noise;
  SteadyStateSegment seg;
  const ObservableFit own = steady_state_fit(segment, specs, seg.runs, &noise);
  seg.experiment = noise.experiment;
  kept = own.names;
  return seg;
}

std::vector<std::string> in_both(const std::vector<std::string>& a,
                                 const std::vector<std::string>& b) {
  std::vector<std::string> both;
  for (const std::string& n : a)
    if (std::find(b.begin(), b.end(), n) != b.end()) both.push_back(n);
  return both;
}

// `edge`: design_edge_note() of the packing ahead (empty where the fit is inside its range).
void report_one_cycle_ahead(const Twin& twin, const SegmentedFit& fit,
                            const std::vector<std::int64_t>& cycles, const CalibrateSummary& s,
                            const std::string& edge, std::ostream& report) {
  report << std::setprecision(3) << "mu_s = " << fit.mu_s << "  (95% interval " << fit.mu_s_ci95[0]
         << " - " << fit.mu_s_ci95[1] << ", " << s.simulations << " simulations, one cycle ahead)";
  if (std::isfinite(s.true_mu_s)) report << "  true " << s.true_mu_s;
  report << "\n  " << cycles.size() << " cycles' own fits (cycle: mu_s):";
  for (std::size_t k = 0; k < cycles.size(); ++k)
    report << " " << cycles[k] << ": " << fit.segment_mu_s[k];
  report << "\n  on";
  for (const std::string& n : fit.names)
    report << " " << n;
  report << "; +-" << fit.scatter_sigma << " in ln mu_s from the cycles' scatter, "
         << fit.systematic_sigma << " from the experiment's systematic errors\n";
  if (!edge.empty()) report << "  note: " << edge << "\n";
  report << "wrote " << (twin.options().out / "summary.json").string() << " and "
         << s.written.size() - 1 << " figure files\n";
}

void write_one_cycle_ahead_summary(const Twin& twin, const SegmentedFit& fit,
                                   const std::vector<std::int64_t>& cycles,
                                   const std::vector<double>& mu, const std::string& design_line,
                                   const CalibrateSummary& s) {
  JsonObject j = fitted_mu_s_json(fit.mu_s, fit.method, fit.log_mu_s_sigma, s);
  j["scatter_sigma"] = fit.scatter_sigma;
  j["systematic_sigma"] = fit.systematic_sigma;
  j["one_cycle_ahead"] = true;
  j["cycles"] = cycles;
  j["cycle_mu_s"] = fit.segment_mu_s;
  j["cycle_log_mu_s_sigma"] = fit.segment_log_sigma;
  j["ahead_mu_s"] = mu;
  j["ahead_burn_in"] = twin.options().ahead_burn_in;
  j["observables"] = fit.names;
  j["design_fit"] = design_line;
  j["n_simulations"] = s.simulations;
  j["deposit"] = preparation_name(twin.options().preparation);
  add_protocol(j, twin);
  write_json(twin.options().out / "summary.json", j);
}

// The one-cycle fit's figures: each cycle's own fit against the cycle (with the mean, its
// interval and a pseudo-experiment's truth), and each observable's runs less the
// experiment's of their cycle against mu_s, with the cycles' mean trend through them.
std::vector<fs::path> one_cycle_ahead_figures(const fs::path& out, const SegmentedFit& fit,
                                              const std::vector<std::int64_t>& cycles, int burn_in,
                                              double true_mu_s) {
  std::vector<double> x, error;
  for (std::size_t k = 0; k < cycles.size(); ++k) {
    x.push_back(double(cycles[k]));
    error.push_back(fit.segment_mu_s[k] * fit.segment_log_sigma[k]);
  }
  std::vector<fs::path> written = plot_fits_apart(
      out, "one_cycle_ahead_cycles", x, fit.segment_mu_s, error, fit.mu_s, fit.mu_s_ci95, true_mu_s,
      burn_in ? "cycle (the twin placed from the experiment's frame " +
                    std::to_string(burn_in + 1) + " cycles before it)"
              : std::string("cycle (the twin placed from the experiment's frame before it)"),
      "one cycle ahead: each cycle's own fit (its GLS error)");
  std::vector<ObservablePanel> panels;
  for (std::size_t o = 0; o < fit.names.size(); ++o) {
    ObservablePanel p;
    p.label = steady_state_label(fit.names[o]);
    p.run_mu_s = fit.run_mu_s;
    p.run_value = fit.offset[o];
    p.run_packing.assign(fit.run_mu_s.size(), 0);
    p.curve_mu_s = fit.curve_mu_s;
    p.curve = fit.curve_offset[o];
    p.experiment_error = fit.offset_error[o];
    panels.push_back(std::move(p));
  }
  char title[200];
  std::snprintf(title, sizeof title,
                "one cycle ahead, each run less the experiment at its cycle's end, cycles "
                "%lld-%lld: mu_s = %.3g (95%% %.3g-%.3g)%s",
                static_cast<long long>(cycles.front()), static_cast<long long>(cycles.back()),
                fit.mu_s, fit.mu_s_ci95[0], fit.mu_s_ci95[1],
                std::isfinite(true_mu_s) ? (", true " + number_text(true_mu_s)).c_str() : "");
  const auto observables = plot_observable_fit(
      out, "one_cycle_ahead_fit", panels, fit.mu_s, fit.mu_s_ci95, true_mu_s, title,
      {"twin runs, every cycle", "experiment (0) +- the cycles' mean's error"});
  written.insert(written.end(), observables.begin(), observables.end());
  return written;
}

// The design's fit, then its packing one cycle ahead over every cycle of the window, and
// the fit of the segments.
// `cycles`: ahead_cycles(), checked before the design ran.
void fit_one_cycle_ahead(const Twin& twin, const std::vector<FrictionRunSpec>& design,
                         const std::vector<std::int64_t>& cycles, CalibrateSummary& s,
                         std::ostream& report) {
  const CalibrateOptions& o = twin.options();
  DesignFit first = design_fit(twin, design);
  const std::uint64_t seed = twin.next_seed(0);
  std::vector<double> mu;
  std::vector<FrictionRunSpec> ahead;
  for (double f : kOneCycleAheadSpan) {
    mu.push_back(three_digits(first.at.mu_s * f));
    ahead.push_back({mu.back(), seed});
  }
  first.line +=
      "one cycle ahead: a packing more (seed " + std::to_string(seed) + ") at mu_s " +
      refined_frictions_text(ahead) +
      ", placed anew from the experiment's frame of each of cycles " +
      std::to_string(cycles.front() - 1 - o.ahead_burn_in) + "-" +
      std::to_string(cycles.back() - 1 - o.ahead_burn_in) + " and driven " +
      (o.ahead_burn_in ? std::to_string(o.ahead_burn_in + 1) + " cycles, the last compared"
                       : std::string("the next"));
  twin.say(first.line);
  report << first.line << "\n";
  std::vector<SteadyStateSegment> segments;
  std::vector<std::string> names;  // those every cycle's own fit keeps (within --only)
  for (std::int64_t c : cycles) {
    twin.say("cycle " + std::to_string(c) + ": placed from the experiment's frame of cycle " +
             std::to_string(c - 1 - o.ahead_burn_in));
    const CalibrateOptions so = segment_options(o, c, mu, seed);
    std::vector<std::string> kept;
    segments.push_back(ahead_segment(so, twin, kept));
    names = c == cycles.front() ? kept : in_both(names, kept);
  }
  // Empty would read as "every observable" to the fit: the ones the scans' noise left out too.
  if (names.empty()) throw Error("--one-cycle-ahead: no observable kept in every cycle's fit");
  ObservableFitOptions by_cycle = observable_fit_options(twin);
  by_cycle.degree = kOneCycleAheadDegree;
  const SegmentedFit fit = fit_friction_by_segments(segments, by_cycle, names);
  if (!mpi_ranks().root()) return;
  s.mu_s = fit.mu_s;
  s.mu_s_ci95 = {fit.mu_s_ci95[0], fit.mu_s_ci95[1]};
  s.simulations = s.simulations_fitted = design.size() + mu.size();
  write_one_cycle_ahead_summary(twin, fit, cycles, mu, first.line, s);
  s.written.push_back(o.out / "summary.json");
  const std::vector<fs::path> figures =
      one_cycle_ahead_figures(o.out, fit, cycles, o.ahead_burn_in, s.true_mu_s);
  s.written.insert(s.written.end(), figures.begin(), figures.end());
  report_one_cycle_ahead(twin, fit, cycles, s, design_edge_note(fit.mu_s, segments.front().runs),
                         report);
}

void fit_joint(const Twin& twin, const std::vector<FrictionRunSpec>& specs, CalibrateSummary& s,
               std::ostream& report) {
  const CalibrateOptions& o = twin.options();
  ScanNoise noise;
  std::vector<SteadyStateRun> runs;
  const JointObservableFit fit = joint_steady_state_fit(twin, specs, runs, &noise);
  const FrictionRunSpec at_fit{three_digits(fit.mu_s), twin.seed(), three_digits(fit.mu_r)};
  // Inside the joint 95 % region: (ln mu_s, ln mu_r) within chi2(2 dof) = 5.99 of the fit.
  const Eigen::Matrix2d covariance = Eigen::Map<const Eigen::Matrix2d>(fit.log_covariance.data());
  const Eigen::Matrix2d precision = covariance.inverse();
  const FrictionRunSpec best = compared_run(twin, specs, at_fit, [&](const FrictionRunSpec& r) {
    const Eigen::Vector2d d(std::log(r.mu_s / fit.mu_s), std::log(r.mu_r / fit.mu_r));
    return d.dot(precision * d) <= 5.991;
  });
  const Comparison compared = compare_at_fit(twin, best, Eigen::Vector3d::Zero(), 0);
  if (!mpi_ranks().root()) return;
  if (!o.fit_only) report << compared_run_line(best, at_fit);
  add_comparison(s, report, compared);
  s.mu_s = fit.mu_s;
  s.mu_s_ci95 = {fit.mu_s_ci95[0], fit.mu_s_ci95[1]};
  s.mu_r = fit.mu_r;
  s.mu_r_ci95 = {fit.mu_r_ci95[0], fit.mu_r_ci95[1]};
  s.correlation = fit.correlation;
  s.simulations = simulations_with(twin, specs, best);
  s.simulations_fitted = simulations_fitted(twin, specs);
  std::vector<double> run_s, run_r;
  for (const FrictionRunSpec& r : specs) {
    run_s.push_back(r.mu_s);
    run_r.push_back(r.mu_r);
  }
  char title[200];
  std::snprintf(title, sizeof title,
                "joint fit: mu_s = %.3g (%.3g-%.3g), mu_r = %.3g (%.3g-%.3g), correlation %.2f",
                fit.mu_s, fit.mu_s_ci95[0], fit.mu_s_ci95[1], fit.mu_r, fit.mu_r_ci95[0],
                fit.mu_r_ci95[1], fit.correlation);
  const auto figure = plot_joint_region(o.out, "joint_fit", run_s, run_r, fit.region95,
                                        {fit.mu_s, fit.mu_r}, {s.true_mu_s, s.true_mu_r}, title);
  s.written.insert(s.written.end(), figure.begin(), figure.end());
  JsonObject j;
  j["mu_s"] = fit.mu_s;
  j["mu_s_ci95"] = s.mu_s_ci95;
  j["mu_r"] = fit.mu_r;
  j["mu_r_ci95"] = s.mu_r_ci95;
  j["correlation"] = fit.correlation;
  j["log_covariance"] = fit.log_covariance;
  j["mu_s_true"] = s.true_mu_s;
  j["mu_r_true"] = s.true_mu_r;
  j["interval_method"] = fit.method;
  j["chi2"] = fit.chi2;
  j["dof"] = fit.dof;
  j["region95"] = fit.region95;
  j["n_simulations"] = s.simulations;
  j["n_simulations_fitted"] = s.simulations_fitted;
  j["replicas"] = o.replicas;
  j["deposit"] = preparation_name(o.preparation);
  j["observables"] = fit.names;
  std::ostringstream left_out;
  report_noise_limited(noise, left_out, j);
  report_contact_error(twin, noise.contacts, left_out, j);
  report_displacement_error(noise.displacements, left_out, j);
  report_placed_frame(twin, noise.placed, left_out, j);
  report_placement_probe(twin, noise.probe, left_out, j);
  j["systematic_sigma"] = fit.systematic_sigma;
  add_protocol(j, twin);
  write_json(o.out / "summary.json", j);
  report << std::setprecision(3) << "mu_s = " << fit.mu_s << "  (95% interval " << fit.mu_s_ci95[0]
         << " - " << fit.mu_s_ci95[1] << ")";
  if (std::isfinite(s.true_mu_s)) report << "  true " << s.true_mu_s;
  report << "\nmu_r = " << fit.mu_r << "  (95% interval " << fit.mu_r_ci95[0] << " - "
         << fit.mu_r_ci95[1] << ")";
  if (std::isfinite(s.true_mu_r)) report << "  true " << s.true_mu_r;
  report << "\n  correlation of ln mu_s and ln mu_r " << fit.correlation << ", "
         << simulations_text(s) << "\n"
         << observables_line(twin, fit.names, nullptr) << "  chi2 " << fit.chi2 << " for "
         << fit.dof << " dof; cross-validated " << fit.cross_validated_sigma[0] << " (mu_s), "
         << fit.cross_validated_sigma[1] << " (mu_r) in ln at the fit from "
         << fit.cross_validations << " runs\n"
         << left_out.str() << "wrote " << (o.out / "summary.json").string() << ", "
         << figure.size() + compared.written.size() << " figure files\n";
}

// The displacement fit's tables: each run's smoothed CDF at the experiment's deciles, and
// each run's displacement summary (the last row: the run at the fit).
void write_displacement_tables(const fs::path& out, const FrictionFit& fit,
                               const std::vector<FrictionRunSpec>& specs,
                               const std::vector<FrictionRun>& runs, const FrictionRunSpec& best,
                               const CycleObservables& at_fit) {
  Table t;
  Column& cycle = t.add("cycle", "", true);
  Column& level = t.add("threshold_dr", "d");
  Column& exp_cdf = t.add("experiment_cdf");
  Column& exp_err = t.add("experiment_error");
  Column& model = t.add("fit_cdf");
  std::vector<Column*> per_run;
  for (const FrictionRunSpec& run : specs)
    per_run.push_back(
        &t.add("cdf_mu_s_" + number_text(run.mu_s) + "_seed_" + std::to_string(run.seed)));
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
    m.values.push_back(k < runs.size() ? runs[k].mu_s : best.mu_s);
    seed.values.push_back(double(k < runs.size() ? specs[k].seed : best.seed));
    n.values.push_back(double(s.count));
    mean.values.push_back(s.mean);
    median.values.push_back(s.median);
    mean_rot.values.push_back(summarize(o.rot_disp).mean);
  }
  write_csv(r, out / "runs.csv",
            {"per simulated mu_s (the last row: at the fit): end-of-cycle displacements "
             "over the window, grain diameters"});
}

void fit_displacements(const Twin& twin, const std::vector<FrictionRunSpec>& specs,
                       const FrictionFitOptions& fit_options, const std::string& noise_model,
                       CalibrateSummary& s, std::ostream& report) {
  const CalibrateOptions& o = twin.options();
  std::vector<FrictionRun> runs;
  for (const FrictionRunSpec& spec : specs)
    runs.push_back(
        {spec.mu_s, cycle_observables(TrajectoryReader(twin.path(spec)), twin.observe), spec.seed});
  const FrictionFit fit = fit_friction(twin.measured, runs, fit_options);

  // The twin at the fitted friction: what the distances and the figures compare, with the
  // fitted locating noise.
  const FrictionRunSpec best{three_digits(fit.mu_s), twin.seed()};
  twin.run({best});
  if (!mpi_ranks().root()) return;  // in an MPI job, rank 0 writes the results
  const TrajectoryReader best_run(twin.path(best));
  const CycleObservables at_fit = cycle_observables(best_run, twin.observe);
  s.mu_s = fit.mu_s;
  s.mu_s_ci95 = {fit.mu_s_ci95[0], fit.mu_s_ci95[1]};
  s.simulations = simulations_with(twin, specs, best);
  s.simulations_fitted = simulations_fitted(twin, specs);
  write_displacement_tables(o.out, fit, specs, runs, best, at_fit);
  s.written.push_back(o.out / "cdf_summaries.csv");
  s.written.push_back(o.out / "runs.csv");
  std::vector<double> run_mu;
  for (const FrictionRunSpec& spec : specs)
    run_mu.push_back(spec.mu_s);
  const std::vector<fs::path> figures = calibration_figures(o.out, fit, run_mu);
  s.written.insert(s.written.end(), figures.begin(), figures.end());
  const Comparison compared = compare_runs(
      twin.experiment(), best_run, "experiment", "DEM mu_s = " + number_text(best.mu_s),
      twin.observe, fit_options.noise_shape, fit.noise_sigma, o.out, {}, twin.first_cycle());
  add_comparison(s, report, compared);
  auto distance = [&](const std::string& q, bool wasserstein) {
    const auto it = compared.distances.find(q);
    if (it == compared.distances.end()) return std::nan("");
    return wasserstein ? it->second.second : it->second.first;
  };
  const double ks = distance("dr", false), w1 = distance("dr", true);

  JsonObject j;
  j["mu_s"] = fit.mu_s;
  j["mu_s_ci95"] = s.mu_s_ci95;
  j["mu_s_interval_method"] = fit.method;
  j["n_simulations"] = s.simulations;
  j["n_simulations_fitted"] = s.simulations_fitted;
  j["replicas"] = o.replicas;
  j["deposit"] = preparation_name(o.preparation);
  j["summaries"] = o.per_cycle ? "per-cycle" : "pooled";
  j["mu_s_simulated"] = sorted(o.mu_s);
  j["converged"] = fit.converged;
  j["chi2"] = fit.chi2;
  j["dof"] = fit.dof;
  j["overdispersion"] = fit.overdispersion;
  j["noise_model"] = noise_model;
  j["noise_sigma_voxel"] = fit.noise_sigma;
  j["noise_sigma_error"] = fit.noise_sigma_error;
  j["distances_at_fit"] = {{"ks_dr", ks},
                           {"wasserstein1_dr", w1},
                           {"ks_rot_disp", distance("rot_disp", false)},
                           {"wasserstein1_rot_disp", distance("rot_disp", true)},
                           {"length_unit", "grain diameter"}};
  add_protocol(j, twin);
  write_json(o.out / "summary.json", j);

  const std::vector<double> mu = sorted(o.mu_s);
  report << std::setprecision(3) << "mu_s = " << fit.mu_s << "  (95% interval " << fit.mu_s_ci95[0]
         << " - " << fit.mu_s_ci95[1] << ", " << simulations_text(s)
         << (fit.converged ? "" : ", fit NOT converged") << ")\n"
         << "  at the fit: KS " << ks << ", Wasserstein-1 " << w1 << " d (end-of-cycle dr); chi2 "
         << fit.chi2 << " for " << fit.dof << " dof; realization scatter x" << fit.overdispersion
         << "\n";
  if (fit.mu_s_ci95[0] < mu.front() || fit.mu_s_ci95[1] > mu.back()) {
    report << "  the interval reaches beyond the simulated frictions (" << mu.front() << "-"
           << mu.back() << "): these displacements pin mu_s down only loosely (a larger "
           << "packing or a longer window would)\n";
  }
  if (fit.noise_sigma > 0) {
    report << "  locating noise " << fit.noise_sigma << " +- " << fit.noise_sigma_error
           << " voxel\n";
  }
  report << "wrote " << (o.out / "summary.json").string() << ", runs.csv, cdf_summaries.csv, "
         << figures.size() + compared.written.size() << " figure files\n";
}

}  // namespace

std::vector<double> CalibrateOptions::refined_mu_s(double fit, int packings) const {
  std::vector<double> mu(std::size_t(std::max(packings, 0)), fit);
  if (preparation != TwinPreparation::experiment || packings < 2) return mu;
  constexpr double kSide = 1.15;
  const auto [first, last] = std::minmax_element(mu_s.begin(), mu_s.end());
  mu.front() = std::max(fit / kSide, std::sqrt(fit * *first));
  mu.back() = std::min(fit * kSide, std::sqrt(fit * *last));
  return mu;
}

CalibrateOptions CalibrateOptions::with_default_design() const {
  struct Design {
    std::vector<double> mu_s;
    int replicas;
    int refine = 0;
  };
  const bool steady = observables == CalibrationObservables::steady_state;
  // A placed twin's replicas differ by their jitter alone and scatter little, so two per
  // friction measure it; its range reaches past 0.4, and its last four packings go on both
  // sides of where the first eight fit. A poured twin's packings scatter more: three per friction,
  // and three more at their fit.
  const Design design = joint() ? Design{{0.05, 0.12, 0.3}, 2}
                        : steady && preparation == TwinPreparation::experiment
                            ? Design{{0.05, 0.13, 0.35, 0.6}, 2, 4}
                        : steady ? Design{{0.05, 0.14, 0.4}, 3, 3}
                                 : Design{{0.03, 0.05, 0.08, 0.12, 0.2, 0.3, 0.5}, 2};
  CalibrateOptions o = *this;
  // A design given is run as given: refined only where asked (one cycle ahead: never).
  if (!o.refine) o.refine = o.mu_s.empty() && o.replicas == 0 && !ahead() ? design.refine : 0;
  if (o.mu_s.empty()) o.mu_s = design.mu_s;
  if (o.replicas == 0) o.replicas = design.replicas;
  return o;
}

void CalibrateOptions::validate() const {
  check_frictions(mu_s, "--mu-s");
  if (joint()) check_frictions(mu_r, "--mu-r");
  const bool steady = observables == CalibrationObservables::steady_state;
  for (const auto& [truth, option] :
       {std::pair{true_mu_s, "--true-mu-s"}, {true_mu_r, "--true-mu-r"}}) {
    if (truth && !(*truth > 0 && std::isfinite(*truth)))
      throw Error(std::string(option) + ": a friction above 0");
  }
  if (true_mu_s && !steady)
    throw Error("--true-mu-s: only with --observables steady-state (its report and figures)");
  if (true_mu_r && !joint()) throw Error("--true-mu-r: only with --fit mu_s,mu_r");
  if (fit_only && !steady) {
    throw Error(
        "--fit-only: only with --observables steady-state (the displacement fit "
        "compares its distributions at the fit)");
  }
  if (joint() && !steady) {
    throw Error("--fit mu_s,mu_r: the joint fit is on --observables steady-state");
  }
  // What only the displacements' fit reads, refused rather than ignored under the default.
  if (steady && per_cycle) {
    throw Error("--summaries per-cycle: only with --observables displacements");
  }
  if (steady && noise != "auto") {
    throw Error("--noise " + noise +
                ": only with --observables displacements (the steady state takes a scan's "
                "errors from its store and its contacts)");
  }
  if (joint() && mu_r.size() < 3) throw Error("--mu-r: the joint fit needs at least 3 values");
  if (replicas < 1) throw Error("--replicas: at least one packing");
  // Replicas of a placed packing differ by their jitter alone: none, and they are one run.
  if (!std::isnan(placed_jitter) && !(placed_jitter > 0 && std::isfinite(placed_jitter))) {
    throw Error("--placed-jitter: a length > 0 (replicas not moved would all be the same run)");
  }
  if (ahead()) {
    if (!steady || joint() || preparation != TwinPreparation::experiment) {
      throw Error(
          "--one-cycle-ahead: only for a steady-state fit of mu_s on a twin placed from the "
          "experiment's packing (--deposit experiment, or auto on a simulation or fine scans)");
    }
    if (refined_packings() > 0 || auto_window || placed_cycle) {
      throw Error(
          "--one-cycle-ahead: not with --refine, --window auto or --placed-cycle (its packing "
          "is placed from every cycle's frame, after the design's fit)");
    }
  }
  if (ahead_burn_in < 0) throw Error("--ahead-burn-in: a number of cycles, 0 or more");
  if (placed_cycle && *placed_cycle < 0) throw Error("--placed-cycle: a cycle, 0 or later");
  if (placed_cycle && auto_window) {
    throw Error(
        "--placed-cycle: not with --window auto (the window is chosen from runs that "
        "start from the experiment's first frame)");
  }
  if (degree < 0) throw Error("--degree: at least 1, or 0 (by the twin)");
  const int fitted = degree > 0 ? degree : 2;
  const std::size_t needed = frictions_for_degree(fitted);
  if (mu_s.size() < needed) {
    throw Error("--mu-s: " + std::to_string(mu_s.size()) + " frictions; the fit needs at least " +
                std::to_string(needed) + " (degree " + std::to_string(fitted) + " + 1" +
                (replicas > 1 ? "" : ", and one more to measure the runs' scatter") + ")");
  }
  if (noise != "auto" && noise != "fit" && noise != "none" && noise != "scans") {
    const Quantity q = parse_quantity(noise, "--noise");
    if (!q.unit.empty() || !(q.value >= 0)) {
      throw Error("--noise '" + noise + "': expected none, fit, scans, auto or voxels (0.05)");
    }
  }
  if (!(wall_distance >= 0)) throw Error("--wall-distance: expected a length >= 0");
  if (axis_noise && (!(*axis_noise >= 0) || !std::isfinite(*axis_noise))) {
    throw Error("--axis-noise: expected auto or an angle in degrees >= 0");
  }
  if (axis_noise && *axis_noise > 0 && !steady) {
    throw Error("--axis-noise: only with --observables steady-state (its rotations)");
  }
  if (window && window->first < 1) throw Error("--window: cycles start at 1");
  if (auto_window && !steady) {
    throw Error(
        "--window auto: only with --observables steady-state (a steady window is "
        "where its observables stop changing)");
  }
  if (refined_packings() < 0) throw Error("--refine: a number of packings, 0 or more");
  if (refined_packings() > 0 && !steady) {
    throw Error("--refine: only with --observables steady-state (packings added at the fit)");
  }
  if (auto_window && replicas < 2) {
    throw Error(
        "--window auto: needs --replicas 2 or more (one packing's scatter is what a "
        "change is measured against)");
  }
}

void CalibrateOptions::set_window(const std::string& text, const std::string& option) {
  auto_window = text == "auto";
  window.reset();
  if (!auto_window) window = parse_int_range(text, option);
}

CalibrateSummary calibrate(const CalibrateOptions& given) {
  // The design, and so what is valid, depends on the preparation the experiment resolves.
  const TrajectoryReader experiment(given.experiment);
  const CalibrateOptions options = resolved_options(given, experiment);
  options.validate();
  Twin twin(options, experiment);  // every setting checked before any output
  CalibrateSummary s;
  s.true_mu_s = true_friction(experiment.header(), "mu-s", options.true_mu_s);
  s.true_mu_r = true_friction(experiment.header(), "mu-r", options.true_mu_r);
  const bool steady = options.observables == CalibrationObservables::steady_state;
  if (steady) check_only(options, twin.measured_steady_state());
  // Refused before any run.
  const std::vector<std::int64_t> ahead =
      options.ahead() ? ahead_cycles(twin) : std::vector<std::int64_t>{};
  std::string noise_model;
  const FrictionFitOptions fit_options =
      steady ? FrictionFitOptions{}
             : displacement_fit_options(options, experiment.header(), twin.errors,
                                        twin.observe.diameter, &noise_model);
  fs::create_directories(options.out / "runs");
  twin.announce(protocol_left_to_experiment(given, experiment.header()));
  twin.prepare_shared_packings();
  std::vector<FrictionRunSpec> specs = twin.design();
  twin.run(specs);
  std::ostringstream report;
  if (options.auto_window) report << twin.choose_window(specs) << "\n";
  if (options.refined_packings() > 0) specs = refined_design(twin, std::move(specs), report);
  if (options.ahead()) {
    fit_one_cycle_ahead(twin, specs, ahead, s, report);
  } else if (options.joint()) {
    fit_joint(twin, specs, s, report);
  } else if (steady) {
    fit_steady_state(twin, specs, s, report);
  } else {
    fit_displacements(twin, specs, fit_options, noise_model, s, report);
  }
  s.report_ = report.str();
  return s;
}

double parse_placed_jitter(const std::string& text, const std::string& option) {
  if (trim(text) == "auto") return std::nan("");
  return parse_si(text, Dimension::length, "m", option);
}

std::optional<std::int64_t> parse_placed_cycle(const std::string& text, const std::string& option) {
  const std::string t(trim(text));
  if (t == "auto") return std::nullopt;
  std::size_t used = 0;
  long long cycle = -1;
  try {
    cycle = std::stoll(t, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != t.size() || cycle < 0) {
    throw Error(option + " '" + text + "': expected auto or a cycle, 0 or later");
  }
  return cycle;
}

std::optional<double> parse_axis_noise(const std::string& text, const std::string& option) {
  if (trim(text) == "auto") return std::nullopt;
  const Quantity q = parse_quantity(text, option);
  if ((!q.unit.empty() && q.unit != "deg") || !(q.value >= 0) || !std::isfinite(q.value)) {
    throw Error(option + " '" + text + "': expected auto or an angle in degrees >= 0");
  }
  return q.value * M_PI / 180;
}

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

bool is_twin_setting(const std::string& name) {
  static const std::set<std::string> calibrate_sets{
      "out",  "checkpoint", "checkpoint-every",  "cycles",
      "mu-s", "track",      "samples-per-cycle", "full-compression"};
  return default_simulate_settings().count(name) && !calibrate_sets.count(name);
}

std::string friction_run_progress(const FrictionRunSpec& run, const CyclicProgress& p) {
  char rate[32];
  std::snprintf(rate, sizeof rate, "%.2e", p.particle_steps_per_second);
  return "mu_s " + number_text(run.mu_s) + (run.mu_r >= 0 ? " mu_r " + number_text(run.mu_r) : "") +
         " seed " + std::to_string(run.seed) + ": cycle " + std::to_string(p.cycle) + "/" +
         std::to_string(p.cycles) + "  " + rate + " particle-steps/s  " +
         std::to_string(std::llround(p.seconds_left)) + " s left";
}

}  // namespace granmem
