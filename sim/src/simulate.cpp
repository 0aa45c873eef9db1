#include "granmem/sim/simulate.hpp"

#include <omp.h>

#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>
#include <vector>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/lammps_engine.hpp"
#include "granmem/sim/quasi_static.hpp"

namespace granmem {
namespace {

// Where the run starts: a checkpoint to resume, a trained packing, or (neither) a new
// deposit; the settings merged accordingly.
struct Start {
  RunSettings settings;
  ProtocolState state;
  std::optional<Simulation> sim;
};

Start start_of(const SimulateOptions& o, const std::function<void(const std::string&)>& log) {
  Start s;
  s.settings = o.settings;
  if (!o.resume.empty()) {
    s.sim.emplace(read_checkpoint(o.resume, &s.state));
    // The run goes on with the settings it started with; more cycles may be asked for.
    s.settings = resumed_settings(s.state.settings, o.settings, o.given,
                                  {"checkpoint-every", "cycles", "ranks", "lammps"});
    log("resuming " + o.resume + " after cycle " + std::to_string(s.state.cycles_done) +
        (s.state.step_in_cycle ? " (+" + std::to_string(s.state.step_in_cycle) + " steps)"
                               : std::string()));
  }
  if (!o.start_from.empty()) {
    if (!o.resume.empty()) throw Error("resume and start-from: give one of them");
    ProtocolState trained;
    s.sim.emplace(read_checkpoint(o.start_from, &trained));
    if (trained.step_in_cycle != 0) {
      throw Error(o.start_from +
                  ": written in the middle of a cycle; a new protocol starts "
                  "between cycles (--resume finishes that run)");
    }
    // The packing and its physics are the checkpoint's; the protocol is new. A checkpoint
    // written before --lid-pressure existed has an explicit lid mass.
    s.settings = started_from_settings(
        trained.settings, o.settings, o.given,
        std::vector<std::string>(kPackingOptions, kPackingOptions + kPackingOptionCount),
        {"lid-pressure"}, o.start_from);
    s.settings["start-from"] = o.start_from;
    s.state.settings = s.settings;
    log("starting from " + o.start_from + " (after cycle " + std::to_string(trained.cycles_done) +
        " of its run)");
  }
  return s;
}

// Tracked grains must exist (a new packing's ids are 0 .. grains - 1), each once.
void check_tracked(const std::vector<std::int64_t>& tracked, const std::optional<Simulation>& sim,
                   std::int64_t grains) {
  std::set<std::int64_t> ids;
  if (sim) ids.insert(sim->grains().id.begin(), sim->grains().id.end());
  for (std::int64_t id : tracked) {
    const bool exists = sim ? ids.count(id) > 0 : id >= 0 && id < grains;
    if (!exists) throw Error("--track: there is no grain " + std::to_string(id));
  }
  const std::set<std::int64_t> once(tracked.begin(), tracked.end());
  if (once.size() != tracked.size()) throw Error("--track: a grain is listed twice");
}

// The files a run writes: distinct, not the checkpoint it starts from, in folders that
// exist (a resumed run writes its own checkpoint again, by design).
void check_run_outputs(const CyclicOptions& c, const std::string& start_from) {
  std::vector<NamedPath> outputs{{"--out", c.out}, {"--checkpoint", c.checkpoint}};
  for (std::int64_t cycle : c.keep_states)
    outputs.push_back({"--keep-states", kept_state_path(c.out, cycle)});
  if (c.full_compression_frames)
    outputs.push_back({"--full-compression-frames", full_compression_path(c.out)});
  if (c.samples_per_cycle > 0) outputs.push_back({"--samples-per-cycle", in_cycle_path(c.out)});
  std::vector<NamedPath> inputs;
  if (!start_from.empty()) inputs.push_back({"--start-from", start_from});
  check_outputs(outputs, inputs);
}

CyclicOptions protocol_of(RunSettings& v, const PhysicsOptions& physics, const DepositOptions& d,
                          const std::optional<Simulation>& sim) {
  const double box_y = sim ? sim->container().size.y() : d.box_side;
  const double lid_mass =
      sim ? (sim->container().lid.present ? sim->container().lid.mass : 0) : d.lid_mass;
  CyclicOptions c;
  c.cycles = setting_whole(v, "cycles");
  c.drive = drive_from(v, physics, d.box_side, box_y, lid_mass, d.radius);
  c.out = v.at("out");
  c.full_compression_frames = setting_yes_no(v, "full-compression");
  c.tracked_grains = whole_list(v, "track", "3,17,250");
  c.samples_per_cycle = setting_whole(v, "samples-per-cycle");
  if (c.tracked_grains.empty() != (c.samples_per_cycle == 0)) {
    throw Error("--track and --samples-per-cycle go together: which grains, and how often");
  }
  check_tracked(c.tracked_grains, sim, d.grains);
  if (v.at("checkpoint").empty()) {
    const std::filesystem::path o(c.out);
    v["checkpoint"] = (o.parent_path() / (o.stem().string() + ".checkpoint.h5")).string();
  }
  c.checkpoint = v.at("checkpoint");
  c.checkpoint_every = setting_whole(v, "checkpoint-every");
  c.keep_states = whole_list(v, "keep-states", "10,50,100");
  c.validate(box_y, physics.dt);
  return c;
}

// --engine lammps: where and how LAMMPS runs, checked with what it cannot run.
std::optional<LammpsEngineOptions> lammps_engine_from(const RunSettings& v, const CyclicOptions& c,
                                                      const DepositOptions& d,
                                                      const std::optional<Simulation>& sim,
                                                      bool resume) {
  const std::string& engine = v.at("engine");
  if (engine == "granmem") return std::nullopt;
  if (engine != "lammps") throw Error("--engine " + engine + ": expected granmem or lammps");
  LammpsEngineOptions e;
  e.folder = lammps_folder(c.out);
  e.ranks = int(std::min<std::int64_t>(setting_whole(v, "ranks"), 1 << 20));
  e.lmp = v.at("lammps");
  e.resume = resume;
  const bool lid = sim ? sim->container().lid.present : d.lid_mass > 0;
  check_lammps_protocol(c, sim ? true : d.polydispersity == 0, lid);  // sizes: checked on the run
  e.validate();
  return e;
}

std::string deposited_text(const DepositSummary& s, const DepositOptions& d,
                           const PhysicsOptions& physics) {
  std::ostringstream t;
  t << "settled: packing fraction " << s.packing_fraction << ", lid at " << s.lid_height * 100
    << " cm";
  if (d.lid_mass > 0) {
    t << " (" << d.lid_mass * 1e3 << " g, "
      << lid_pressure(d.lid_mass, physics.gravity, d.box_side, d.box_side) << " Pa)";
  }
  t << ", " << s.contacts_per_grain << " contacts per grain";
  return t.str();
}

}  // namespace

SimulateSummary simulate(const SimulateOptions& o) {
  const auto log = o.log ? o.log : [](const std::string&) {};
  if (o.threads > 0) omp_set_num_threads(o.threads);  // deposit's and the cycles' simulations
  Start start = start_of(o, log);
  RunSettings& v = start.settings;
  const PhysicsOptions physics = physics_from(v);
  DepositOptions d = deposit_from(v);
  d.threads = o.threads;
  d.validate();  // before any work or output
  physics.validate("simulate", d.radius * (1 - d.polydispersity));
  // Every setting is checked before the packing is made.
  CyclicOptions c = protocol_of(v, physics, d, start.sim);
  check_run_outputs(c, o.start_from);
  const std::optional<LammpsEngineOptions> lammps =
      lammps_engine_from(v, c, d, start.sim, !o.resume.empty());

  if (!start.sim) {
    log("depositing " + std::to_string(d.grains) + " grains (seed " + std::to_string(d.seed) + ")");
    DepositSummary s;
    start.sim.emplace(deposit(d, physics, &s, o.deposit_progress));
    log(deposited_text(s, d, physics));
    start.state.settings = v;
  }
  Simulation& sim = *start.sim;
  sim.set_threads(o.threads);  // 0: by the number of grains
  for (const auto& [key, value] : v)
    c.parameters["simulate/" + key] = value;
  std::ostringstream cycling;
  cycling << "cycling: A = " << c.drive.amplitude * 100 << " cm, period " << c.drive.period
          << " s (" << std::int64_t(std::round(c.drive.period / physics.dt))
          << " steps, peak wall speed " << c.drive.peak_speed() * 100 << " cm/s), " << c.cycles
          << " cycles";
  log(cycling.str());

  if (o.cycles_start) o.cycles_start();
  SimulateSummary summary;
  if (lammps) {
    // The packing before the first cycle is the checkpoint: --resume reads it and LAMMPS
    // goes on from its newest restart.
    if (o.resume.empty()) write_checkpoint(c.checkpoint, sim, start.state);
    log("running the cycles on LAMMPS in " + lammps->folder.string() + " (" +
        std::to_string(lammps->ranks) + (lammps->ranks > 1 ? " ranks)" : " rank)"));
    summary.cycles = run_cycles_on_lammps(sim, c, *lammps, o.progress, o.stop);
  } else {
    summary.cycles = run_cycles(sim, c, start.state, o.progress, o.stop);
  }
  summary.settings = v;
  summary.grains = sim.grains().size();
  summary.checkpoint = c.checkpoint;
  return summary;
}

std::string SimulateSummary::Report() const {
  std::ostringstream t;
  t << "simulated " << cycles.cycles_done << " cycles of " << grains
    << " grains: " << std::scientific << std::setprecision(3) << cycles.particle_steps_per_second
    << std::defaultfloat << " particle-steps/s\n";
  for (const auto& p : cycles.written)
    t << "wrote " << p.string() << "\n";
  t << "wrote " << checkpoint << "\n";
  return t.str();
}

}  // namespace granmem
