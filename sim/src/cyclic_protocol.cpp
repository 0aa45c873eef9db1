#include "granmem/sim/cyclic_protocol.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <unordered_map>

#include "granmem/core/error.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/deposit.hpp"

namespace granmem {

std::filesystem::path full_compression_path(const std::filesystem::path& out) {
  return out.parent_path() / (out.stem().string() + "_full_compression" + out.extension().string());
}
std::filesystem::path in_cycle_path(const std::filesystem::path& out) {
  return out.parent_path() / (out.stem().string() + "_in_cycle" + out.extension().string());
}

bool finished_run(const std::filesystem::path& out,
                  const std::map<std::string, std::string>& parameters, std::int64_t cycles) {
  if (!std::filesystem::exists(out)) return false;
  const TrajectoryReader run(out);
  const auto& have = run.header().parameters;
  for (const auto& [key, value] : parameters) {
    const auto it = have.find(key);
    if (it == have.end() || it->second != value) return false;
  }
  return !run.steps().empty() && run.steps().back() >= cycles;
}

std::filesystem::path kept_state_path(const std::filesystem::path& out, std::int64_t cycle) {
  return out.parent_path() / (out.stem().string() + "_state_cycle" + std::to_string(cycle) + ".h5");
}

namespace {

constexpr const char* kEnd = "end_of_cycle";
constexpr const char* kFull = "full_compression";
constexpr const char* kInCycle = "in_cycle";
// Most steps run between two looks at the stop flag and the progress clock.
constexpr std::int64_t kStepsPerRun = 256;

RunHeader header_for(const Simulation& sim, const std::vector<std::size_t>& grains,
                     const char* sample, const std::map<std::string, std::string>& parameters) {
  RunHeader h;
  h.length_unit = "m";
  h.time_unit = "s";
  h.sample = sample;
  h.has_axis = true;
  h.has_orientation = true;
  for (std::size_t i : grains) {
    h.id.push_back(sim.grains().id[i]);
    h.radius.push_back(sim.grains().radius[i]);
  }
  const Container& c = sim.container();
  h.box =
      Box{Eigen::Vector3d::Zero(), Eigen::Vector3d(c.size.x(), c.size.y(), packing_height(sim))};
  h.parameters = parameters;
  return h;
}

Frame frame_of(const Simulation& sim, const RunHeader& h, const std::vector<std::size_t>& grains,
               std::int64_t step) {
  Frame f = Frame::unknown(h);
  f.step = step;
  f.time = sim.time();
  const Grains& g = sim.grains();
  for (std::size_t k = 0; k < grains.size(); ++k) {
    const std::size_t i = grains[k];
    const auto row = Eigen::Index(k);
    f.position.row(row) = g.x[i].transpose();
    f.orientation.row(row) << g.q[i].w(), g.q[i].x(), g.q[i].y(), g.q[i].z();
    f.axis.row(row) = (g.q[i] * Eigen::Vector3d::UnitZ()).transpose();  // the cavity axis
  }
  return f;
}

// The packing's push on the driven wall (it pushes towards -y).
double driven_wall_force(const Simulation& sim) {
  return -sim.wall_loads().force[int(Wall::y_low)].y();
}

// A run whose state became non-finite (a time step too large for the forces at hand) must
// stop before NaN positions are written, where they would read as "grain not seen".
void check_finite(const Simulation& sim, std::int64_t cycle) {
  const Grains& g = sim.grains();
  for (std::size_t i = 0; i < g.size(); ++i) {
    if (!g.x[i].allFinite() || !g.v[i].allFinite() || !g.w[i].allFinite()) {
      throw Error("cycle " + std::to_string(cycle) + ": grain " + std::to_string(g.id[i]) +
                  " has a non-finite position or velocity; the run is unstable (try a smaller "
                  "time step)");
    }
  }
  if (!std::isfinite(sim.container().lid.z)) {
    throw Error("cycle " + std::to_string(cycle) + ": the lid's height is not finite");
  }
}

struct Output {
  std::unique_ptr<TrajectoryWriter> writer;
  RunHeader header;
  std::vector<std::size_t> grains;
};

}  // namespace

void CyclicOptions::validate(double box_y, double dt) const {
  if (cycles < 1) throw Error("cycles: at least one cycle is needed");
  // 0 keeps the wall still for the period: the read-out's reference of no drive.
  if (!(drive.amplitude >= 0)) throw Error("amplitude: must be zero or positive");
  if (drive.amplitude >= 0.5 * box_y) {
    throw Error("amplitude " + std::to_string(drive.amplitude) +
                " m: must be less than half the box (" + std::to_string(box_y) + " m)");
  }
  if (!(std::llround(drive.period / dt) >= 4)) {
    throw Error("cycle period: shorter than four time steps");
  }
  if (samples_per_cycle < 0 || checkpoint_every < 0) {
    throw Error("samples per cycle and checkpoint interval must be zero or positive");
  }
  for (std::int64_t c : keep_states) {
    if (c < 0) throw Error("kept state after cycle " + std::to_string(c) + ": cycles count from 0");
  }
}

CyclicSummary run_cycles(Simulation& sim, const CyclicOptions& o, ProtocolState& state,
                         const std::function<void(const CyclicProgress&)>& progress,
                         const std::atomic<bool>* stop) {
  const double dt = sim.physics().dt;
  const WallDrive& drive = o.drive;
  o.validate(sim.container().size.y(), dt);
  const auto steps_per_cycle = std::llround(drive.period / dt);
  const auto full_step =
      std::llround(drive.full_compression_time() / drive.period * double(steps_per_cycle));
  const Grains& g = sim.grains();
  std::vector<std::size_t> all(g.size()), tracked;
  for (std::size_t i = 0; i < g.size(); ++i)
    all[i] = i;
  {
    std::unordered_map<std::int64_t, std::size_t> index;
    for (std::size_t i = 0; i < g.size(); ++i)
      index[g.id[i]] = i;
    for (std::int64_t id : o.tracked_grains) {
      const auto it = index.find(id);
      if (it == index.end()) throw Error("tracked grain " + std::to_string(id) + ": no such grain");
      tracked.push_back(it->second);
    }
  }

  // In-cycle samples at the steps where step * samples / steps_per_cycle moves on: exactly
  // samples_per_cycle of them, evenly spread, the last at the end of the cycle.
  const std::int64_t samples = tracked.empty() ? 0 : o.samples_per_cycle;
  auto sample_due = [&](std::int64_t step) {
    return samples > 0 &&
           (step * samples) / steps_per_cycle != ((step - 1) * samples) / steps_per_cycle;
  };

  // Outputs: new, or continued after the frames a checkpoint counted.
  const bool fresh = state.frames_written.empty();
  std::map<std::string, Output> outputs;
  auto open = [&](const char* kind, const std::filesystem::path& path,
                  const std::vector<std::size_t>& grains) {
    Output& out = outputs[kind];
    out.grains = grains;
    if (fresh) {
      out.header = header_for(sim, grains, kind, o.parameters);
      out.writer = std::make_unique<TrajectoryWriter>(path, out.header);
      state.frames_written[kind] = 0;
    } else {
      const auto it = state.frames_written.find(kind);
      if (it == state.frames_written.end()) {
        throw Error(std::string("resume: the checkpoint's run wrote no ") + kind + " frames");
      }
      out.writer = std::make_unique<TrajectoryWriter>(
          TrajectoryWriter::resume(path, std::size_t(it->second)));
      out.writer->set_parameters(o.parameters);  // a resumed run may have more cycles
      out.header = out.writer->header();
    }
  };
  open(kEnd, o.out, all);
  if (o.full_compression_frames) open(kFull, full_compression_path(o.out), all);
  if (samples > 0) open(kInCycle, in_cycle_path(o.out), tracked);
  std::map<std::string, Observable> observables = outputs[kEnd].writer->observables();

  auto record = [&](const char* name, const char* unit, double value) {
    Observable& obs = observables[name];
    obs.unit = unit;
    obs.value.push_back(value);
    obs.step.push_back(state.cycles_done);
    obs.time.push_back(sim.time());
  };
  auto append = [&](const char* kind, std::int64_t step) {
    Output& out = outputs.at(kind);
    out.writer->append(frame_of(sim, out.header, out.grains, step));
    ++state.frames_written[kind];
  };
  auto end_of_cycle_observables = [&](double full_compression_force) {
    record("wall_force", "N", driven_wall_force(sim));
    record("wall_force_full_compression", "N", full_compression_force);
    record("lid_height", "m", packing_height(sim));
    record("packing_fraction", "1", packing_fraction(sim));
    record("kinetic_energy", "J", sim.kinetic_energy());
    record("contacts_per_grain", "1", 2.0 * double(sim.contact_count()) / double(g.size()));
  };
  CyclicSummary summary;
  auto save = [&](bool final) {
    for (auto& [kind, out] : outputs) {
      if (kind == kEnd) {
        for (auto& [name, obs] : observables)
          out.writer->set_observable(name, obs);
      }
      if (final)
        out.writer->commit();
      else
        out.writer->publish();
    }
    if (!o.checkpoint.empty()) write_checkpoint(o.checkpoint, sim, state);
  };

  // The state after the cycles just completed, if asked for (with the outputs so far).
  auto keep_if_asked = [&] {
    const auto& keep = o.keep_states;
    if (std::find(keep.begin(), keep.end(), state.cycles_done) == keep.end()) return false;
    save(false);
    const std::filesystem::path kept = kept_state_path(o.out, state.cycles_done);
    write_checkpoint(kept, sim, state);
    summary.written.push_back(kept);
    return true;
  };

  if (fresh) {
    state.cycles_done = 0;
    state.step_in_cycle = 0;
    append(kEnd, 0);  // the prepared packing, before the first cycle
    end_of_cycle_observables(driven_wall_force(sim));
    keep_if_asked();  // 0: the untrained packing, the read-out's reference
  }

  const auto clock_start = std::chrono::steady_clock::now();
  auto last_report = clock_start;
  std::int64_t steps_run = 0;
  const std::int64_t steps_total =
      (o.cycles - state.cycles_done) * steps_per_cycle - state.step_in_cycle;
  auto report = [&](bool force) {
    const auto now = std::chrono::steady_clock::now();
    if (!progress || (!force && now - last_report < std::chrono::seconds(10))) return;
    last_report = now;
    const double seconds = std::chrono::duration<double>(now - clock_start).count();
    CyclicProgress p;
    p.cycle = state.cycles_done;
    p.cycles = o.cycles;
    p.particle_steps_per_second = seconds > 0 ? double(steps_run) * double(g.size()) / seconds : 0;
    p.seconds_left =
        steps_run > 0 ? seconds * double(steps_total - steps_run) / double(steps_run) : 0;
    progress(p);
  };

  // The wall follows the drive by step count, so that a resumed run moves it identically;
  // step k of n is at k/n of the period, so that a cycle ends exactly where it began. The
  // motion refers to this function's locals: it is removed however the function ends.
  std::int64_t cycle_start = 0;  // the simulation's step count where this cycle began
  sim.set_wall_motion([&](double) {
    return drive.at(drive.period * double(sim.step_count() - cycle_start) /
                    double(steps_per_cycle));
  });
  struct ClearWallMotion {
    Simulation& sim;
    ~ClearWallMotion() { sim.set_wall_motion({}); }
  } clear_wall_motion{sim};

  while (state.cycles_done < o.cycles) {
    if (state.step_in_cycle == 0) state.pending.clear();
    while (state.step_in_cycle < steps_per_cycle) {
      if (stop && stop->load(std::memory_order_relaxed)) {
        save(false);
        summary.interrupted = true;
        summary.cycles_done = state.cycles_done;
        return summary;
      }
      // Steps in one run up to the next that is read (a run saves a pass per step).
      std::int64_t next = state.step_in_cycle + 1;
      while (next < steps_per_cycle && next - state.step_in_cycle < kStepsPerRun &&
             next != full_step && !sample_due(next))
        ++next;
      cycle_start = sim.step_count() - state.step_in_cycle;
      sim.run(next - state.step_in_cycle);
      steps_run += next - state.step_in_cycle;
      state.step_in_cycle = next;
      if (state.step_in_cycle == full_step) {
        state.pending["wall_force_full_compression"] = driven_wall_force(sim);
        if (o.full_compression_frames) append(kFull, state.cycles_done + 1);
      }
      if (sample_due(state.step_in_cycle)) append(kInCycle, sim.step_count());
      report(false);
    }
    ++state.cycles_done;
    state.step_in_cycle = 0;
    check_finite(sim, state.cycles_done);
    append(kEnd, state.cycles_done);
    const auto pending = state.pending.find("wall_force_full_compression");
    end_of_cycle_observables(pending != state.pending.end() ? pending->second : std::nan(""));
    report(true);
    if (!keep_if_asked() && o.checkpoint_every > 0 && state.cycles_done % o.checkpoint_every == 0 &&
        state.cycles_done < o.cycles) {
      save(false);
    }
  }
  save(true);
  summary.cycles_done = state.cycles_done;
  summary.wall_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start).count();
  summary.particle_steps_per_second =
      summary.wall_seconds > 0 ? double(steps_run) * double(g.size()) / summary.wall_seconds : 0;
  for (auto& [kind, out] : outputs) {
    summary.written.push_back(kind == kEnd    ? o.out
                              : kind == kFull ? full_compression_path(o.out)
                                              : in_cycle_path(o.out));
  }
  return summary;
}

}  // namespace granmem
