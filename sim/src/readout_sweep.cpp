#include "granmem/sim/readout_sweep.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <sstream>

#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/units.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/quasi_static.hpp"

namespace granmem {
namespace {

std::string exact_text(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", x);
  return text;
}

struct TrainedState {
  Simulation sim;
  std::int64_t cycles = 0;
  double amplitude = std::nan("");  // fraction of the box
};

// The trained states, read once and checked: between cycles, one box and one set of grains.
std::vector<TrainedState> read_states(const std::vector<std::filesystem::path>& paths) {
  std::vector<TrainedState> states;
  for (const std::filesystem::path& path : paths) {
    ProtocolState protocol;
    Simulation sim = read_checkpoint(path, &protocol);
    const double box_y = sim.container().size.y();
    double amplitude = std::nan("");
    const auto setting = protocol.settings.find("amplitude");
    if (setting != protocol.settings.end()) {
      amplitude = parse_amplitude(setting->second, box_y, path.string() + ": amplitude") / box_y;
    }
    states.push_back({std::move(sim), protocol.cycles_done, amplitude});
    if (protocol.step_in_cycle != 0) {
      throw Error(path.string() + ": written in the middle of a cycle; a read-out starts from a " +
                  "state between cycles (simulate --keep-states)");
    }
    const Simulation& first = states.front().sim;
    const Simulation& s = states.back().sim;
    if (s.container().size != first.container().size ||
        s.grains().size() != first.grains().size()) {
      throw Error(path.string() + ": a state of another box or other grains than " +
                  paths.front().string() + "; one sweep reads out one packing's states");
    }
  }
  return states;
}

// The read-out cycle at `amplitude` (fraction of the box) for this state: the quasi-static
// period of that amplitude, or of `timing_amplitude` when the wall stays still.
WallDrive readout_drive(const Simulation& state, const ReadoutSweepOptions& o, double amplitude,
                        double timing_amplitude) {
  const Container& c = state.container();
  const PhysicsOptions& physics = state.physics();
  const double box_y = c.size.y();
  const double pressure =
      c.lid.present ? lid_pressure(c.lid.mass, physics.gravity, c.size.x(), box_y) : 0.0;
  const double diameter = 2 * median(state.grains().radius);
  const double stress = confining_stress(pressure, physics.density, physics.gravity, diameter);
  WallDrive d;
  d.symmetry = o.symmetry;
  d.shape = o.shape;
  d.amplitude = (amplitude > 0 ? amplitude : timing_amplitude) * box_y;
  d.period = quasi_static_period(o.inertial_number, d, box_y, diameter, stress, physics.density);
  d.amplitude = amplitude * box_y;
  return d;
}

std::map<std::string, std::string> run_parameters(const ReadoutSweepOptions& o,
                                                  const std::filesystem::path& state,
                                                  double amplitude, const WallDrive& drive) {
  return {{"readout/state", std::filesystem::absolute(state).lexically_normal().string()},
          {"readout/amplitude_fraction", exact_text(amplitude)},
          {"readout/amplitude_m", exact_text(drive.amplitude)},
          {"readout/period_s", exact_text(drive.period)},
          {"readout/cycles", std::to_string(o.cycles)},
          {"readout/drive", o.symmetry == DriveSymmetry::symmetric ? "symmetric" : "asymmetric"},
          {"readout/wall_motion", o.shape == DriveShape::linear ? "linear" : "cosine"},
          {"readout/inertial_number", exact_text(o.inertial_number)}};
}

// The state's sweep: the amplitudes given and, if asked, its training amplitude, ascending.
std::vector<double> amplitudes_for(const TrainedState& state, const ReadoutSweepOptions& o) {
  std::vector<double> a = o.amplitudes;
  if (o.include_training_amplitude && std::isfinite(state.amplitude)) {
    const bool listed = std::any_of(a.begin(), a.end(), [&](double x) {
      return std::abs(x - state.amplitude) <= 1e-9 * state.amplitude;
    });
    if (!listed) a.push_back(state.amplitude);
  }
  std::sort(a.begin(), a.end());
  return a;
}

}  // namespace

void ReadoutSweepOptions::validate() const {
  if (amplitudes.empty()) throw Error("readout: no read-out amplitudes");
  for (double a : amplitudes) {
    if (!(std::isfinite(a) && a >= 0 && a < 0.5)) {
      throw Error("readout: amplitude " + exact_text(a * 100) +
                  " % of the box: must be at least 0 and less than half the box");
    }
  }
  if (*std::max_element(amplitudes.begin(), amplitudes.end()) == 0) {
    throw Error("readout: every amplitude is 0; a sweep needs a moving wall to time its cycles");
  }
  if (cycles < 1) throw Error("readout: at least one read-out cycle per amplitude");
  if (!(inertial_number > 0)) throw Error("readout: the inertial number must be positive");
  if (states.empty()) throw Error("readout: no trained state (--from)");
  if (dir.empty()) throw Error("readout: no output folder (--out)");
}

std::vector<double> parse_amplitude_sweep(const std::string& text) {
  const std::string what = "--amplitudes '" + text + "'";
  auto percentage = [&](const std::string& item) {
    const std::string t(trim(item));
    if (t.empty() || t.back() != '%') {
      throw Error(what + ": expected percentages of the box, e.g. 0.05%:2.5%:12 or 0.5%,1%");
    }
    return parse_amplitude(t, 1.0, what);
  };
  std::vector<std::string> parts;
  const char separator = text.find(':') != std::string::npos ? ':' : ',';
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, separator);)
    parts.push_back(item);
  std::vector<double> out;
  if (separator == ',') {
    for (const std::string& p : parts)
      out.push_back(percentage(p));
    return out;
  }
  if (parts.size() != 3) throw Error(what + ": a range is lo%:hi%:count");
  const double lo = percentage(parts[0]), hi = percentage(parts[1]);
  const Quantity count = parse_quantity(parts[2], what);
  if (!count.unit.empty() || count.value != std::floor(count.value) || count.value < 2 ||
      !(lo > 0) || !(hi > lo)) {
    throw Error(what + ": a range needs 0 < lo < hi and a whole count of at least 2");
  }
  const auto n = std::size_t(count.value);
  for (std::size_t k = 0; k < n; ++k)
    out.push_back(lo * std::pow(hi / lo, double(k) / double(n - 1)));
  out.back() = hi;
  return out;
}

std::filesystem::path readout_run_path(const std::filesystem::path& dir,
                                       const std::filesystem::path& state, double amplitude) {
  char name[64];
  std::snprintf(name, sizeof name, "_A%.4gpct.h5", amplitude * 100);
  return dir / ("readout_" + state.stem().string() + name);
}

ReadoutSweepSummary run_readout_sweep(
    const ReadoutSweepOptions& o,
    const std::function<void(const ReadoutSweepProgress&)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  o.validate();
  const std::vector<TrainedState> states = read_states(o.states);

  // Every run's settings, checked before any runs.
  ReadoutSweepSummary summary;
  std::vector<CyclicOptions> protocol;
  for (std::size_t s = 0; s < states.size(); ++s) {
    const std::vector<double> amplitudes = amplitudes_for(states[s], o);
    double timing_amplitude = 0.5;
    for (double a : amplitudes) {
      if (a > 0) timing_amplitude = std::min(timing_amplitude, a);
    }
    const Simulation& sim = states[s].sim;
    for (double a : amplitudes) {
      CyclicOptions c;
      c.drive = readout_drive(sim, o, a, timing_amplitude);
      c.cycles = o.cycles;
      c.out = readout_run_path(o.dir, o.states[s], a);
      c.parameters = run_parameters(o, o.states[s], a, c.drive);
      c.validate(sim.container().size.y(), sim.physics().dt);
      bool reused = false;
      try {
        reused = finished_run(c.out, c.parameters, o.cycles);
      } catch (const Error&) {
        // not a store we can read: run it again
      }
      summary.runs.push_back({s, states[s].cycles, states[s].amplitude, a, c.out, reused});
      protocol.push_back(std::move(c));
    }
  }
  for (std::size_t k = 0; k < summary.runs.size(); ++k) {
    for (std::size_t m = 0; m < k; ++m) {
      if (summary.runs[m].store == summary.runs[k].store) {
        throw Error("readout: two runs would write " + summary.runs[k].store.string() +
                    " (an amplitude listed twice, or two states of one name)");
      }
    }
  }

  std::filesystem::create_directories(o.dir);  // once every setting is known to be good
  std::vector<std::size_t> todo;
  for (std::size_t k = 0; k < summary.runs.size(); ++k) {
    if (!summary.runs[k].reused) todo.push_back(k);
  }
  std::mutex report;
  std::size_t done = summary.runs.size() - todo.size();
  const auto sweep_start = std::chrono::steady_clock::now();
  run_pool(todo.size(), o.pool, [&](std::size_t t, int cores) {
    const std::size_t k = todo[t];
    Simulation sim = states[summary.runs[k].state].sim;
    sim.set_threads(Simulation::threads_on_own_cores(sim.grains().size(), cores));
    ProtocolState fresh;
    run_cycles(sim, protocol[k], fresh);
    const std::lock_guard<std::mutex> lock(report);
    ++done;
    if (!progress) return;
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - sweep_start).count();
    const std::size_t ran = done - (summary.runs.size() - todo.size());
    progress(
        {done, summary.runs.size(),
         seconds * double(summary.runs.size() - done) / double(std::max<std::size_t>(ran, 1))});
  });
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace granmem
