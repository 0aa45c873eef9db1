#include "granmem/calibration/readout.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/units.hpp"
#include "granmem/sim/ranks.hpp"

namespace granmem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A run's bootstrap seed from its store's name, so that its error bars do not depend on
// where the run stands in the sweep (FNV-1a: the same on every platform).
std::uint64_t run_seed(std::uint64_t seed, const std::filesystem::path& store) {
  const std::string name = store.filename().string();
  return seed ^ fnv1a(name.data(), name.size());
}

struct MeanWithError {
  double mean = kNaN, error = kNaN;
};
MeanWithError mean_with_error(const std::vector<double>& values, const ReadoutOptions& o,
                              Random& random) {
  return {summarize(values).mean, bootstrap_standard_error(values, o.bootstrap, random)};
}

}  // namespace

std::vector<ReadoutPoint> readout_points(const ReadoutRun& run, const ReadoutOptions& o) {
  const TrajectoryReader store(run.store);
  const RunHeader& h = store.header();
  if (store.frame_count() < 2) {
    throw Error(run.store.string() + ": a read-out run needs the trained state and a cycle");
  }
  const double metres = metres_per(h.length_unit);
  const double to_d = metres / median_diameter(store);
  MotionOptions motion = o.motion;
  motion.wall_distance /= metres;
  Random random(run_seed(o.seed, run.store));
  const Frame trained = store.read_frame(0);
  Frame before = trained;
  std::vector<ReadoutPoint> points;
  for (std::size_t t = 1; t < store.frame_count(); ++t) {
    const Frame after = store.read_frame(t);
    const FrameMotion m = grain_motion(h, trained, after, motion);
    std::vector<double> dr, dr2, single, full;
    for (std::size_t k = 0; k < m.grain.size(); ++k) {
      dr.push_back(m.dr[k] * to_d);
      dr2.push_back(dr.back() * dr.back());
      single.push_back(m.has_rotation ? m.theta_axis[k] * 0.5 : kNaN);  // angle d/2, in d
      if (!m.theta_full.empty()) full.push_back(m.theta_full[k] * 0.5);
    }
    ReadoutPoint p;
    p.state = run.state;
    p.trained_cycles = run.trained_cycles;
    p.training_amplitude = run.training_amplitude;
    p.amplitude = run.amplitude;
    p.cycle = store.steps()[t];
    p.grains = m.grain.size();
    MeanWithError e = mean_with_error(dr, o, random);
    p.dr = e.mean;
    p.dr_error = e.error;
    e = mean_with_error(dr2, o, random);
    p.msd = e.mean;
    p.msd_error = e.error;
    e = mean_with_error(single, o, random);
    p.rot_single = e.mean;
    p.rot_single_error = e.error;
    e = mean_with_error(full, o, random);
    p.rot_full = e.mean;
    p.rot_full_error = e.error;
    p.reversibility = kNaN;
    if (t > 1) {
      const FrameMotion step = grain_motion(h, before, after, motion);
      p.reversibility = summarize(step.dr).mean * to_d;
    }
    points.push_back(p);
    before = after;
  }
  return points;
}

Table readout_table(const std::vector<ReadoutPoint>& points) {
  Table t;
  Column& state = t.add("state", "", true);
  Column& trained = t.add("trained_cycles", "", true);
  Column& training = t.add("training_amplitude_pct", "%");
  Column& amplitude = t.add("amplitude_pct", "%");
  Column& cycle = t.add("cycle", "", true);
  Column& grains = t.add("grains", "", true);
  std::vector<std::pair<Column*, double ReadoutPoint::*>> lengths = {
      {&t.add("dr_d", "d"), &ReadoutPoint::dr},
      {&t.add("dr_err_d", "d"), &ReadoutPoint::dr_error},
      {&t.add("msd_d2", "d^2"), &ReadoutPoint::msd},
      {&t.add("msd_err_d2", "d^2"), &ReadoutPoint::msd_error},
      {&t.add("rot_single_d", "d"), &ReadoutPoint::rot_single},
      {&t.add("rot_single_err_d", "d"), &ReadoutPoint::rot_single_error},
      {&t.add("rot_full_d", "d"), &ReadoutPoint::rot_full},
      {&t.add("rot_full_err_d", "d"), &ReadoutPoint::rot_full_error},
      {&t.add("reversibility_d", "d"), &ReadoutPoint::reversibility}};
  for (const ReadoutPoint& p : points) {
    state.values.push_back(double(p.state));
    trained.values.push_back(double(p.trained_cycles));
    training.values.push_back(p.training_amplitude * 100);
    amplitude.values.push_back(p.amplitude * 100);
    cycle.values.push_back(double(p.cycle));
    grains.values.push_back(double(p.grains));
    for (auto& [column, field] : lengths)
      column->values.push_back(p.*field);
  }
  return t;
}

namespace {

// A state's curve of one quantity over its first read-out cycle, amplitudes ascending.
ReadoutCurve curve_of(const std::vector<ReadoutPoint>& points, std::size_t state,
                      double ReadoutPoint::*value, double ReadoutPoint::*error) {
  ReadoutCurve c;
  for (const ReadoutPoint& p : points) {
    if (p.state != state || p.cycle != 1 || !(p.amplitude > 0)) continue;
    c.amplitude.push_back(p.amplitude);
    c.value.push_back(p.*value);
    c.error.push_back(p.*error);
  }
  return c;
}

bool between_others(const ReadoutCurve& c, double a) {
  for (std::size_t k = 1; k + 1 < c.amplitude.size(); ++k) {
    if (std::abs(c.amplitude[k] - a) <= 1e-9 * a) return true;
  }
  return false;
}

}  // namespace

std::vector<StateSignature> readout_signatures(const std::vector<ReadoutPoint>& points) {
  std::vector<StateSignature> out;
  std::vector<std::size_t> untrained;
  for (const ReadoutPoint& p : points) {
    if (p.trained_cycles == 0 && p.cycle == 1 && p.amplitude > 0 &&
        std::find(untrained.begin(), untrained.end(), p.state) == untrained.end()) {
      untrained.push_back(p.state);
    }
  }
  for (const ReadoutPoint& p : points) {
    if (p.cycle != 1 || !std::isfinite(p.training_amplitude)) continue;
    if (!out.empty() && out.back().state == p.state) continue;
    const double a = p.training_amplitude;
    const ReadoutCurve dr = curve_of(points, p.state, &ReadoutPoint::dr, &ReadoutPoint::dr_error);
    if (!between_others(dr, a)) continue;
    StateSignature s;
    s.state = p.state;
    s.trained_cycles = p.trained_cycles;
    s.training_amplitude = a;
    s.dr_dip = interpolation_dip(dr, a);
    if (!untrained.empty()) {
      const ReadoutCurve base =
          curve_of(points, untrained.front(), &ReadoutPoint::dr, &ReadoutPoint::dr_error);
      if (between_others(base, a)) s.dr_untrained = trained_ratio(dr, base, a);
    }
    const ReadoutCurve rot =
        curve_of(points, p.state, &ReadoutPoint::rot_single, &ReadoutPoint::rot_single_error);
    s.rot_single_dip = interpolation_dip(rot, a);
    s.rot_single = readout_exponents(rot, a);
    s.rot_full = readout_exponents(
        curve_of(points, p.state, &ReadoutPoint::rot_full, &ReadoutPoint::rot_full_error), a);
    out.push_back(s);
  }
  return out;
}

Table signature_table(const std::vector<StateSignature>& signatures) {
  Table t;
  Column& state = t.add("state", "", true);
  Column& trained = t.add("trained_cycles", "", true);
  Column& training = t.add("training_amplitude_pct", "%");
  Column& dip = t.add("dr_dip");
  Column& dip_err = t.add("dr_dip_err");
  Column& ratio = t.add("dr_over_untrained");
  Column& ratio_err = t.add("dr_over_untrained_err");
  Column& rot_dip = t.add("rot_single_dip");
  Column& rot_dip_err = t.add("rot_single_dip_err");
  auto exponent = [](const PowerLawFit& f, bool value) {
    if (!f.converged) return std::nan("");
    return value ? f.exponent : f.exponent_sigma;
  };
  std::vector<std::pair<Column*, std::function<double(const StateSignature&)>>> fits;
  for (const char* q : {"rot_single", "rot_full"}) {
    const bool single = std::string(q) == "rot_single";
    for (const char* side : {"below", "above"}) {
      const bool below = std::string(side) == "below";
      auto fit = [single, below](const StateSignature& s) -> const PowerLawFit& {
        const ReadoutExponents& e = single ? s.rot_single : s.rot_full;
        return below ? e.below : e.above;
      };
      const std::string name = std::string(q) + "_exp_" + side;
      fits.push_back(
          {&t.add(name), [=](const StateSignature& s) { return exponent(fit(s), true); }});
      fits.push_back({&t.add(name + "_err"),
                      [=](const StateSignature& s) { return exponent(fit(s), false); }});
    }
  }
  for (const StateSignature& s : signatures) {
    state.values.push_back(double(s.state));
    trained.values.push_back(double(s.trained_cycles));
    training.values.push_back(s.training_amplitude * 100);
    dip.values.push_back(s.dr_dip.depth);
    dip_err.values.push_back(s.dr_dip.depth_error);
    ratio.values.push_back(s.dr_untrained.ratio);
    ratio_err.values.push_back(s.dr_untrained.error);
    rot_dip.values.push_back(s.rot_single_dip.depth);
    rot_dip_err.values.push_back(s.rot_single_dip.depth_error);
    for (auto& [column, get] : fits)
      column->values.push_back(get(s));
  }
  return t;
}

void ReadoutOptions::validate() const {
  sweep.validate();
  motion.validate();
}

ReadoutSummary readout(const ReadoutOptions& o,
                       const std::function<void(const ReadoutSweepProgress&)>& progress) {
  o.validate();
  ReadoutSummary s;
  s.sweep = run_readout_sweep(o.sweep, progress);
  if (!mpi_ranks().root()) return s;  // in an MPI job, rank 0 reads every run and writes
  for (const ReadoutRun& run : s.sweep.runs) {
    const std::vector<ReadoutPoint> points = readout_points(run, o);
    s.points.insert(s.points.end(), points.begin(), points.end());
  }
  s.diameter = median_diameter(TrajectoryReader(s.sweep.runs.front().store));
  s.table = o.sweep.dir / "readout.csv";
  std::vector<std::string> comment = {
      "granmem readout: displacements from each trained state at the end of each read-out "
      "cycle, in grain diameters d = " +
      std::to_string(s.diameter) + " m; errors: bootstrap over grains"};
  for (std::size_t k = 0; k < o.sweep.states.size(); ++k)
    comment.push_back("state " + std::to_string(k) + ": " + o.sweep.states[k].string());
  write_csv(readout_table(s.points), s.table, comment);
  s.signatures = readout_signatures(s.points);
  s.signature_table = o.sweep.dir / "memory.csv";
  comment[0] =
      "granmem readout: memory signature of each state's first read-out cycle: dip of dr at "
      "the training amplitude below its neighbours' power law (1 - value / interpolated), dr "
      "over the untrained state's, the same dip of the single-axis rotation, power-law exponents "
      "of the rotations at and below / at and "
      "above it (Ceres fit, standard errors)";
  write_csv(signature_table(s.signatures), s.signature_table, comment);
  return s;
}

}  // namespace granmem
