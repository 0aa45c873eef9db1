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

}  // namespace

RunHeader cyclic_run_header(const Simulation& sim, const std::vector<std::size_t>& grains,
                            const char* sample,
                            const std::map<std::string, std::string>& parameters) {
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

namespace {

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

// The store indices of the tracked grains' ids.
std::vector<std::size_t> tracked_indices(const Grains& g, const std::vector<std::int64_t>& ids) {
  std::unordered_map<std::int64_t, std::size_t> index;
  for (std::size_t i = 0; i < g.size(); ++i)
    index[g.id[i]] = i;
  std::vector<std::size_t> tracked;
  for (std::int64_t id : ids) {
    const auto it = index.find(id);
    if (it == index.end()) throw Error("tracked grain " + std::to_string(id) + ": no such grain");
    tracked.push_back(it->second);
  }
  return tracked;
}

// One call of run_cycles, stage by stage: the outputs opened (new, or continued after the
// frames a checkpoint counted), the cycles stepped with the wall following the drive, the
// frames, observables, kept states and checkpoints written as they fall due.
class CycleRunner {
 public:
  CycleRunner(Simulation& sim, const CyclicOptions& o, ProtocolState& state,
              const std::function<void(const CyclicProgress&)>& progress,
              const std::atomic<bool>* stop)
      : sim_(sim),
        o_(o),
        state_(state),
        progress_(progress),
        stop_(stop),
        steps_per_cycle_(std::llround(o.drive.period / sim.physics().dt)),
        full_step_(std::llround(o.drive.full_compression_time() / o.drive.period *
                                double(steps_per_cycle_))),
        tracked_(tracked_indices(sim.grains(), o.tracked_grains)),
        samples_(tracked_.empty() ? 0 : o.samples_per_cycle) {}

  CyclicSummary run() {
    open_outputs();
    if (fresh_) start_fresh();
    clock_start_ = last_report_ = std::chrono::steady_clock::now();
    steps_total_ = (o_.cycles - state_.cycles_done) * steps_per_cycle_ - state_.step_in_cycle;
    // The wall follows the drive by step count, so that a resumed run moves it identically;
    // step k of n is at k/n of the period, so that a cycle ends exactly where it began. The
    // motion refers to this object: it is removed however run() ends.
    sim_.set_wall_motion([this](double) {
      return o_.drive.at(o_.drive.period * double(sim_.step_count() - cycle_start_) /
                         double(steps_per_cycle_));
    });
    struct ClearWallMotion {
      Simulation& sim;
      ~ClearWallMotion() { sim.set_wall_motion({}); }
    } clear_wall_motion{sim_};
    while (state_.cycles_done < o_.cycles) {
      if (!run_cycle()) {
        save(false);
        summary_.interrupted = true;
        summary_.cycles_done = state_.cycles_done;
        return summary_;
      }
      end_cycle();
    }
    save(true);
    return finished();
  }

 private:
  // In-cycle samples at the steps where step * samples / steps_per_cycle moves on: exactly
  // samples_per_cycle of them, evenly spread, the last at the end of the cycle.
  bool sample_due(std::int64_t step) const {
    return samples_ > 0 &&
           (step * samples_) / steps_per_cycle_ != ((step - 1) * samples_) / steps_per_cycle_;
  }

  void open_outputs() {
    std::vector<std::size_t> all(sim_.grains().size());
    for (std::size_t i = 0; i < all.size(); ++i)
      all[i] = i;
    fresh_ = state_.frames_written.empty();
    open(kEnd, o_.out, all);
    if (o_.full_compression_frames) open(kFull, full_compression_path(o_.out), all);
    if (samples_ > 0) open(kInCycle, in_cycle_path(o_.out), tracked_);
    observables_ = outputs_[kEnd].writer->observables();
  }

  void open(const char* kind, const std::filesystem::path& path,
            const std::vector<std::size_t>& grains) {
    Output& out = outputs_[kind];
    out.grains = grains;
    if (fresh_) {
      out.header = cyclic_run_header(sim_, grains, kind, o_.parameters);
      out.writer = std::make_unique<TrajectoryWriter>(path, out.header);
      state_.frames_written[kind] = 0;
      return;
    }
    const auto it = state_.frames_written.find(kind);
    if (it == state_.frames_written.end()) {
      throw Error(std::string("resume: the checkpoint's run wrote no ") + kind + " frames");
    }
    out.writer =
        std::make_unique<TrajectoryWriter>(TrajectoryWriter::resume(path, std::size_t(it->second)));
    out.writer->set_parameters(o_.parameters);  // a resumed run may have more cycles
    out.header = out.writer->header();
  }

  // The prepared packing, before the first cycle: frame 0, its observables, and the state
  // kept if cycle 0 is asked for (the untrained packing, the read-out's reference).
  void start_fresh() {
    state_.cycles_done = o_.first_cycle;
    state_.step_in_cycle = 0;
    append(kEnd, o_.first_cycle);
    end_of_cycle_observables(driven_wall_force(sim_));
    keep_if_asked();
  }

  void record(const char* name, const char* unit, double value) {
    Observable& obs = observables_[name];
    obs.unit = unit;
    obs.value.push_back(value);
    obs.step.push_back(state_.cycles_done);
    obs.time.push_back(sim_.time());
  }

  void append(const char* kind, std::int64_t step) {
    Output& out = outputs_.at(kind);
    out.writer->append(frame_of(sim_, out.header, out.grains, step));
    ++state_.frames_written[kind];
  }

  void end_of_cycle_observables(double full_compression_force) {
    const Grains& g = sim_.grains();
    record("wall_force", "N", driven_wall_force(sim_));
    record("wall_force_full_compression", "N", full_compression_force);
    record("lid_height", "m", packing_height(sim_));
    record("packing_fraction", "1", packing_fraction(sim_));
    record("kinetic_energy", "J", sim_.kinetic_energy());
    record("contacts_per_grain", "1", 2.0 * double(sim_.contact_count()) / double(g.size()));
  }

  // The outputs so far (published, or committed at the end) and the checkpoint.
  void save(bool final) {
    for (auto& [kind, out] : outputs_) {
      if (kind == kEnd) {
        for (auto& [name, obs] : observables_)
          out.writer->set_observable(name, obs);
      }
      if (final)
        out.writer->commit();
      else
        out.writer->publish();
    }
    if (!o_.checkpoint.empty()) write_checkpoint(o_.checkpoint, sim_, state_);
  }

  // The state after the cycles just completed, if asked for (with the outputs so far).
  bool keep_if_asked() {
    const auto& keep = o_.keep_states;
    if (std::find(keep.begin(), keep.end(), state_.cycles_done) == keep.end()) return false;
    save(false);
    const std::filesystem::path kept = kept_state_path(o_.out, state_.cycles_done);
    write_checkpoint(kept, sim_, state_);
    summary_.written.push_back(kept);
    return true;
  }

  void report(bool force) {
    const auto now = std::chrono::steady_clock::now();
    if (!progress_ || (!force && now - last_report_ < std::chrono::seconds(10))) return;
    last_report_ = now;
    const double seconds = std::chrono::duration<double>(now - clock_start_).count();
    CyclicProgress p;
    p.cycle = state_.cycles_done;
    p.cycles = o_.cycles;
    p.particle_steps_per_second =
        seconds > 0 ? double(steps_run_) * double(sim_.grains().size()) / seconds : 0;
    p.seconds_left =
        steps_run_ > 0 ? seconds * double(steps_total_ - steps_run_) / double(steps_run_) : 0;
    progress_(p);
  }

  // The rest of the current cycle, in runs of steps up to the next step that is read (a
  // run saves a pass per step). False if stopped before its end.
  bool run_cycle() {
    if (state_.step_in_cycle == 0) state_.pending.clear();
    while (state_.step_in_cycle < steps_per_cycle_) {
      if (stop_ && stop_->load(std::memory_order_relaxed)) return false;
      std::int64_t next = state_.step_in_cycle + 1;
      while (next < steps_per_cycle_ && next - state_.step_in_cycle < kStepsPerRun &&
             next != full_step_ && !sample_due(next))
        ++next;
      cycle_start_ = sim_.step_count() - state_.step_in_cycle;
      sim_.run(next - state_.step_in_cycle);
      steps_run_ += next - state_.step_in_cycle;
      state_.step_in_cycle = next;
      if (state_.step_in_cycle == full_step_) {
        state_.pending["wall_force_full_compression"] = driven_wall_force(sim_);
        if (o_.full_compression_frames) append(kFull, state_.cycles_done + 1);
      }
      if (sample_due(state_.step_in_cycle)) append(kInCycle, sim_.step_count());
      report(false);
    }
    return true;
  }

  // A cycle completed: its frame and observables, a kept state or a checkpoint when due.
  void end_cycle() {
    ++state_.cycles_done;
    state_.step_in_cycle = 0;
    check_finite(sim_, state_.cycles_done);
    append(kEnd, state_.cycles_done);
    const auto pending = state_.pending.find("wall_force_full_compression");
    end_of_cycle_observables(pending != state_.pending.end() ? pending->second : std::nan(""));
    report(true);
    if (!keep_if_asked() && o_.checkpoint_every > 0 &&
        state_.cycles_done % o_.checkpoint_every == 0 && state_.cycles_done < o_.cycles) {
      save(false);
    }
  }

  CyclicSummary finished() {
    summary_.cycles_done = state_.cycles_done;
    summary_.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - clock_start_).count();
    summary_.particle_steps_per_second =
        summary_.wall_seconds > 0
            ? double(steps_run_) * double(sim_.grains().size()) / summary_.wall_seconds
            : 0;
    for (auto& [kind, out] : outputs_) {
      summary_.written.push_back(kind == kEnd    ? o_.out
                                 : kind == kFull ? full_compression_path(o_.out)
                                                 : in_cycle_path(o_.out));
    }
    return summary_;
  }

  Simulation& sim_;
  const CyclicOptions& o_;
  ProtocolState& state_;
  const std::function<void(const CyclicProgress&)>& progress_;
  const std::atomic<bool>* stop_;
  const std::int64_t steps_per_cycle_, full_step_;
  const std::vector<std::size_t> tracked_;
  const std::int64_t samples_;
  bool fresh_ = true;
  std::map<std::string, Output> outputs_;
  std::map<std::string, Observable> observables_;
  CyclicSummary summary_;
  std::chrono::steady_clock::time_point clock_start_, last_report_;
  std::int64_t steps_run_ = 0, steps_total_ = 0;
  std::int64_t cycle_start_ = 0;  // the simulation's step count where this cycle began
};

}  // namespace

void CyclicOptions::validate(double box_y, double dt) const {
  if (cycles < 1) throw Error("cycles: at least one cycle is needed");
  if (first_cycle < 0 || first_cycle >= cycles) {
    throw Error("first cycle " + std::to_string(first_cycle) + ": from 0 to the last cycle's " +
                std::to_string(cycles - 1));
  }
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
    if (c < first_cycle) {
      throw Error("kept state after cycle " + std::to_string(c) + ": the run starts after cycle " +
                  std::to_string(first_cycle));
    }
  }
}

CyclicSummary run_cycles(Simulation& sim, const CyclicOptions& o, ProtocolState& state,
                         const std::function<void(const CyclicProgress&)>& progress,
                         const std::atomic<bool>* stop) {
  o.validate(sim.container().size.y(), sim.physics().dt);
  return CycleRunner(sim, o, state, progress, stop).run();
}

}  // namespace granmem
