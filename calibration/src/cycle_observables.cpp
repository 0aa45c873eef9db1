#include "granmem/calibration/cycle_observables.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "granmem/core/error.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double diameter_for(const TrajectoryReader& run, const ObservableOptions& options) {
  return options.diameter > 0 ? options.diameter : median_diameter(run);
}

// The motion options in the run's own length unit.
MotionOptions in_run_units(MotionOptions motion, double metres) {
  motion.wall_distance /= metres;
  return motion;
}

void check_rotations(const TrajectoryReader& run, const ObservableOptions& options) {
  if (options.rotations && !run.header().has_axis && !run.header().has_orientation) {
    throw Error(run.file_name() +
                ": has no cavity axes or orientations, so no rotations (leave rotations out)");
  }
}

// The frame with its hole axes, each tilted at random by `sigma` (rad, the standard
// deviation in each of two directions across it), as a scan would locate them.
Frame with_axis_noise(const RunHeader& h, Frame f, double sigma, std::mt19937_64& random) {
  std::normal_distribution<double> normal(0, sigma);
  Vectors3 axis(Eigen::Index(h.grain_count()), 3);
  for (Eigen::Index i = 0; i < axis.rows(); ++i) {
    const Eigen::Vector3d a = axis_of(h, f, std::size_t(i));
    const double tilt_u = normal(random), tilt_v = normal(random);  // drawn for every grain
    if (!a.allFinite() || a.isZero()) {
      axis.row(i) = a.transpose();
      continue;
    }
    const Eigen::Vector3d unit = a.normalized(), u = unit.unitOrthogonal(), v = unit.cross(u);
    axis.row(i) = (unit + tilt_u * u + tilt_v * v).normalized().transpose();
  }
  f.axis = std::move(axis);
  return f;
}

}  // namespace

double median_diameter(const TrajectoryReader& run) {
  std::vector<double> r;
  for (double x : run.header().radius) {
    if (std::isfinite(x) && x > 0) r.push_back(x);
  }
  if (r.empty()) throw Error(run.file_name() + ": no grain radius; give the grain diameter");
  return 2 * median(r) * metres_per_length(run);
}

CycleObservables cycle_observables(const TrajectoryReader& run, const ObservableOptions& options) {
  const RunHeader& h = run.header();
  const double metres = metres_per_length(run);
  check_rotations(run, options);
  const std::vector<std::int64_t>& steps = run.steps();
  if (steps.size() < 2) {
    throw Error(run.file_name() + ": needs at least two end-of-cycle frames, has " +
                std::to_string(steps.size()));
  }
  CycleObservables o;
  o.diameter = diameter_for(run, options);
  o.grains = h.grain_count();
  o.window = options.window;
  if (o.window == std::pair<std::int64_t, std::int64_t>{0, 0}) o.window = {steps[1], steps.back()};
  const auto [first, last] = o.window;
  if (first > last) {
    throw Error("window " + std::to_string(first) + ":" + std::to_string(last) +
                ": the first cycle is after the last");
  }
  // Every cycle of the window needs its frame and the one before it.
  for (std::int64_t c = first; c <= last; ++c) {
    for (std::int64_t s : {c - 1, c}) {
      if (std::find(steps.begin(), steps.end(), s) == steps.end()) {
        throw Error(run.file_name() + ": window " + std::to_string(first) + ":" +
                    std::to_string(last) + " needs the frame of cycle " + std::to_string(s) +
                    ", which the run does not have (cycles " + std::to_string(steps.front()) +
                    " to " + std::to_string(steps.back()) + ")");
      }
    }
  }

  const double to_d = metres / o.diameter;  // run's length unit -> diameters
  const MotionOptions motion = in_run_units(options.motion, metres);
  // With an axis noise the frames carry noisy axes, which the rotations are measured from.
  const bool noisy = options.rotations && options.axis_noise > 0;
  RunHeader with_axes;
  if (noisy) {
    with_axes = h;
    with_axes.has_axis = true;
  }
  const RunHeader& measured_header = noisy ? with_axes : h;
  std::mt19937_64 random(1);  // a fixed seed: the same noise for a run each time
  Random position_random(1);
  const Eigen::Vector3d position_sigma = options.position_noise / metres;
  auto read = [&](std::size_t t) {
    Frame f = run.read_frame(t);
    if (!position_sigma.isZero()) {
      for (Eigen::Index i = 0; i < f.position.rows(); ++i)
        f.position.row(i) +=
            position_sigma.cwiseProduct(normal_vector(position_random)).transpose();
    }
    return noisy ? with_axis_noise(h, std::move(f), options.axis_noise, random) : f;
  };
  std::vector<Eigen::Vector3d> displacement;
  Frame before = read(0);
  for (std::size_t t = 1; t < steps.size(); ++t) {
    Frame after = read(t);
    const bool consecutive = steps[t] == steps[t - 1] + 1;
    if (consecutive) {
      const FrameMotion m = grain_motion(measured_header, before, after, motion);
      const bool pooled = steps[t] >= first && steps[t] <= last;
      double sum_dr = 0, sum_rot = 0;
      std::size_t n_rot = 0;
      for (std::size_t k = 0; k < m.grain.size(); ++k) {
        const double dr = m.dr[k] * to_d;
        const double rot = options.rotations ? m.theta_axis[k] * 0.5 : kNaN;  // angle d/2 / d
        sum_dr += dr;
        if (std::isfinite(rot)) {
          sum_rot += rot;
          ++n_rot;
        }
        if (!pooled) continue;
        displacement.push_back(m.displacement.row(Eigen::Index(k)).transpose() * to_d);
        o.dr.push_back(dr);
        o.dr_grain.push_back(m.grain[k]);
        o.dr_cycle.push_back(steps[t]);
        if (std::isfinite(rot)) {
          o.rot_disp.push_back(rot);
          o.rot_grain.push_back(m.grain[k]);
        }
        if (!m.theta_full.empty()) o.full_rot_disp.push_back(m.theta_full[k] * 0.5);
      }
      o.cycle.push_back(steps[t]);
      o.mean_dr.push_back(m.grain.empty() ? kNaN : sum_dr / double(m.grain.size()));
      o.mean_rot_disp.push_back(n_rot ? sum_rot / double(n_rot) : kNaN);
    }
    before = std::move(after);
  }
  o.displacement.resize(Eigen::Index(displacement.size()), 3);
  for (std::size_t k = 0; k < displacement.size(); ++k)
    o.displacement.row(Eigen::Index(k)) = displacement[k].transpose();
  if (o.dr.empty()) {
    throw Error(run.file_name() + ": no grain is seen at both ends of a cycle of the window");
  }
  return o;
}

DisplacementField full_compression_field(const TrajectoryReader& end_of_cycle,
                                         const TrajectoryReader& full_compression,
                                         std::int64_t cycle, const ObservableOptions& options) {
  const RunHeader& h = end_of_cycle.header();
  if (full_compression.header().id != h.id) {
    throw Error(full_compression.file_name() + ": not the same grains as " +
                end_of_cycle.file_name());
  }
  check_rotations(end_of_cycle, options);
  auto frame_of = [&](const TrajectoryReader& run, std::int64_t step) {
    const auto& s = run.steps();
    const auto it = std::find(s.begin(), s.end(), step);
    if (it == s.end()) {
      throw Error(run.file_name() + ": has no frame of cycle " + std::to_string(step));
    }
    return run.read_frame(std::size_t(it - s.begin()));
  };
  const Frame before = frame_of(end_of_cycle, cycle - 1);
  const Frame full = frame_of(full_compression, cycle);
  const double metres = metres_per_length(end_of_cycle);
  const double to_d = metres / diameter_for(end_of_cycle, options);
  const FrameMotion m = grain_motion(h, before, full, in_run_units(options.motion, metres));
  DisplacementField f;
  f.cycle = cycle;
  f.position.resize(Eigen::Index(m.grain.size()), 3);
  for (std::size_t k = 0; k < m.grain.size(); ++k) {
    f.position.row(Eigen::Index(k)) = full.position.row(Eigen::Index(m.grain[k])) * to_d;
    f.dr.push_back(m.dr[k] * to_d);
    f.rot_disp.push_back(options.rotations ? m.theta_axis[k] * 0.5 : kNaN);
  }
  return f;
}

namespace {
// The entry of `per_name` (one per name, or none) for `name`; `missing` where there is none.
double named_entry(const std::vector<std::string>& names, const std::vector<double>& per_name,
                   const std::string& name, double missing) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() || per_name.empty() ? missing
                                               : per_name[std::size_t(it - names.begin())];
}
}  // namespace

double SteadyState::operator[](const std::string& name) const {
  return named_entry(names, values, name, std::nan(""));
}

double SteadyState::drift_of(const std::string& name) const {
  return named_entry(names, drift, name, std::nan(""));
}

double SteadyState::systematic_of(const std::string& name) const {
  return named_entry(names, systematic, name, 0.0);
}

std::string steady_state_label(const std::string& name) {
  static const std::map<std::string, std::string> labels{
      {"dr", "end-of-cycle displacement (d)"},
      {"rot_disp", "rotational displacement (d)"},
      {"bulk_packing_fraction", "bulk packing fraction (positions)"},
      {"coordination", "coordination number (positions)"},
      {"height_packing_fraction", "packing fraction (positions' height)"},
      {"height_packing_fraction_before_window", "packing fraction (height before window)"},
      {"packing_fraction", "packing fraction (lid height)"},
      {"wall_force_full_compression", "wall force at full compression (N)"},
      {"wall_force_unloaded", "wall force at the cycle's end (N)"}};
  const auto it = labels.find(name);
  return it == labels.end() ? name : it->second;
}

namespace {

// Cycles, inclusive, with the public functions' (0, 0) read as every cycle.
CycleRange every_cycle_if_unset(CycleRange cycles) {
  if (cycles != CycleRange{0, 0}) return cycles;
  return {std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max()};
}

// The observables from positions, frame by frame over `cycles` (inclusive), each position
// moved by `noise`.
void add_structure_series(ObservableSeries& s, const TrajectoryReader& run,
                          const StructureOptions& structure, const KnownGrains& known,
                          CycleRange cycles, const PositionNoise& noise) {
  const auto in_range = [&](std::int64_t c) { return c >= cycles.first && c <= cycles.second; };
  Random random(noise.seed);
  const Eigen::Vector3d& jitter = noise.sigma;
  ObservableSeries::Entry packing{"bulk_packing_fraction", {}, {}, true},
      coordination{"coordination", {}, {}, true},
      from_height{"height_packing_fraction", {}, {}, true};
  // The container's cross-section, in the positions' unit (NaN: no box).
  const auto& h = run.header();
  const double section = h.box ? h.box->edges(0) * h.box->edges(1) : kNaN;
  const std::vector<double> radius =
      known.radius ? std::vector<double>(h.id.size(), *known.radius / metres_per_length(run))
                   : h.radius;
  for (std::size_t t = 0; t < run.frame_count(); ++t) {
    const std::int64_t c = run.steps()[t];
    if (!in_range(c)) continue;
    Vectors3 position = run.read_frame(t).position;
    if (!jitter.isZero()) {
      for (Eigen::Index i = 0; i < position.rows(); ++i)
        position.row(i) += jitter.cwiseProduct(normal_vector(random)).transpose();
    }
    const PackingStructure p = packing_structure(position, radius, structure);
    for (auto* e : {&packing, &coordination, &from_height})
      e->cycle.push_back(c);
    packing.value.push_back(p.packing_fraction);
    coordination.value.push_back(p.coordination);
    from_height.value.push_back(height_packing_fraction(position, radius, section, known.count));
  }
  s.entries.push_back(std::move(packing));
  s.entries.push_back(std::move(coordination));
  if (h.box) s.entries.push_back(std::move(from_height));
}

}  // namespace

ObservableSeries observable_series(const TrajectoryReader& run, const CycleObservables& observed,
                                   const StructureOptions& structure, const KnownGrains& known,
                                   CycleRange cycles, const PositionNoise& noise) {
  ObservableSeries s;
  s.entries.push_back({"dr", observed.cycle, observed.mean_dr, false});
  if (std::any_of(observed.mean_rot_disp.begin(), observed.mean_rot_disp.end(),
                  [](double v) { return std::isfinite(v); })) {
    s.entries.push_back({"rot_disp", observed.cycle, observed.mean_rot_disp, false});
  }
  add_structure_series(s, run, structure, known, every_cycle_if_unset(cycles), noise);
  // The store's own, under the names the fit knows them by: the wall force at the end of
  // each cycle is the packing's lateral stress with the wall back at its start.
  const std::pair<const char*, const char*> stored[] = {
      {"packing_fraction", "packing_fraction"},
      {"wall_force_full_compression", "wall_force_full_compression"},
      {"wall_force", "wall_force_unloaded"}};
  for (const auto& [in_store, name] : stored) {
    const auto it = run.observables().find(in_store);
    if (it != run.observables().end()) {
      s.entries.push_back({name, it->second.step, it->second.value, false});
    }
  }
  return s;
}

SteadyState window_means(const ObservableSeries& series, CycleRange window) {
  const auto [first, last] = window;
  SteadyState s;
  for (const ObservableSeries::Entry& e : series.entries) {
    std::vector<double> c, v;
    for (std::size_t k = 0; k < e.cycle.size() && k < e.value.size(); ++k) {
      if (e.cycle[k] >= first && e.cycle[k] <= last && std::isfinite(e.value[k])) {
        c.push_back(double(e.cycle[k]));
        v.push_back(e.value[k]);
      }
    }
    if (v.empty() && !e.always) continue;
    // The window's mean, and its least-squares change across the window (slope x cycles).
    const double n = double(v.size());
    double mc = 0, mv = 0, scc = 0, scv = 0;
    for (std::size_t k = 0; k < v.size(); ++k) {
      mc += c[k] / n;
      mv += v[k] / n;
    }
    for (std::size_t k = 0; k < v.size(); ++k) {
      scc += (c[k] - mc) * (c[k] - mc);
      scv += (c[k] - mc) * (v[k] - mv);
    }
    s.names.push_back(e.name);
    s.values.push_back(v.empty() ? kNaN : mv);
    s.drift.push_back(scc > 0 ? scv / scc * double(last - first) : kNaN);
  }
  return s;
}

SteadyState structure_noise_effect(const TrajectoryReader& run, CycleRange window,
                                   const Eigen::Vector3d& sigma, const StructureOptions& structure,
                                   const KnownGrains& known, std::uint64_t seed) {
  ObservableSeries plain, jittered;
  add_structure_series(plain, run, structure, known, every_cycle_if_unset(window), {});
  add_structure_series(jittered, run, structure, known, every_cycle_if_unset(window),
                       {sigma, seed});
  SteadyState effect = window_means(jittered, window);
  const SteadyState as_measured = window_means(plain, window);
  for (std::size_t k = 0; k < effect.values.size(); ++k)
    effect.values[k] -= as_measured.values[k];
  effect.drift.clear();
  return effect;
}

std::optional<std::size_t> frame_of_cycle(const TrajectoryReader& run, std::int64_t cycle) {
  const auto& steps = run.steps();
  const auto at = std::find(steps.begin(), steps.end(), cycle);
  if (at == steps.end()) return std::nullopt;
  return std::size_t(at - steps.begin());
}

SteadyState frame_structure(const TrajectoryReader& run, std::int64_t cycle,
                            const StructureOptions& structure, const KnownGrains& known,
                            const PositionNoise& noise) {
  if (!frame_of_cycle(run, cycle)) {
    throw Error(run.file_name() + ": has no frame of cycle " + std::to_string(cycle));
  }
  ObservableSeries s;
  add_structure_series(s, run, structure, known, {cycle, cycle}, noise);
  SteadyState at = window_means(s, {cycle, cycle});
  at.drift.assign(at.values.size(), 0.0);
  return at;
}

namespace {
constexpr char kBeforeWindow[] = "_before_window";
}

void add_height_before_window(SteadyState& s, const TrajectoryReader& run, std::int64_t cycle,
                              const KnownGrains& known, const PositionNoise& noise) {
  const std::string name = "height_packing_fraction";
  s.names.push_back(name + kBeforeWindow);
  s.values.push_back(frame_structure(run, cycle, {}, known, noise)[name]);
  s.drift.push_back(0.0);
}

std::string structure_read_as(const std::string& name) {
  const std::string suffix = kBeforeWindow;
  const bool before = name.size() > suffix.size() &&
                      name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  return before ? name.substr(0, name.size() - suffix.size()) : name;
}

SteadyState steady_state(const TrajectoryReader& run, const CycleObservables& observed,
                         const StructureOptions& structure, const KnownGrains& known,
                         const PositionNoise& noise) {
  return window_means(observable_series(run, observed, structure, known, observed.window, noise),
                      observed.window);
}

double metres_per_length(const TrajectoryReader& run) {
  const RunHeader& h = run.header();
  if (is_physical_length_unit(h.length_unit)) return metres_per(h.length_unit);
  throw Error(run.file_name() + ": positions are in " + h.length_unit +
              " without a physical length; import or track it with --voxel-size");
}

}  // namespace granmem
