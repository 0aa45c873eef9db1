#include <omp.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/quasi_static.hpp"
#include "granmem/sim/run_settings.hpp"
#include "simulation_settings.hpp"

namespace granmem::app {
namespace {

// Ctrl-C (SIGINT) and SIGTERM (what Slurm, systemd and container stops send) stop a run
// between two steps with a checkpoint; the exit status is then 128 + the signal's number.
std::atomic<bool> g_stop{false};
std::atomic<int> g_stop_signal{0};
extern "C" void request_stop(int signal) {
  g_stop_signal.store(signal);
  g_stop.store(true);
}

// The options set on the command line or in the config.
std::set<std::string> explicitly_given(const std::map<std::string, CLI::Option*>& options) {
  std::set<std::string> given;
  for (const auto& [name, option] : options) {
    if (option->count()) given.insert(name);
  }
  return given;
}

}  // namespace

SimulateSettings add_simulate(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  auto threads = std::make_shared<int>(0);
  auto resume = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Deposit grains in the box under a lid and compress them cyclically (DEM)");
  std::map<std::string, CLI::Option*> given;
  for (std::size_t k = 0; k < kSimulateOptionCount; ++k) {
    const OptionSpec& o = kSimulateOptions[k];
    args->value[o.name] = o.default_value;
    given[o.name] = cmd->add_option(std::string("--") + o.name, args->value[o.name], o.help)
                        ->capture_default_str();
  }
  cmd->add_option("--threads", *threads,
                  "OpenMP threads (default: one per 2,500 grains, up to all cores)");
  auto start_from = std::make_shared<std::string>();
  CLI::Option* resume_option =
      cmd->add_option("--resume", *resume, "continue the run of this checkpoint")
          ->check(CLI::ExistingFile);
  cmd->add_option("--start-from", *start_from,
                  "start a new protocol (drive, amplitude, cycles, outputs) from the packing in "
                  "this checkpoint, e.g. a trained state for a memory read-out")
      ->check(CLI::ExistingFile)
      ->excludes(resume_option);

  cmd->callback([args, threads, resume, start_from, given] {
    if (*threads > 0) omp_set_num_threads(*threads);  // deposit's and the cycles' simulations
    std::map<std::string, std::string> v = args->value;
    ProtocolState state;
    std::optional<Simulation> sim;
    if (!resume->empty()) {
      sim.emplace(read_checkpoint(*resume, &state));
      // The run goes on with the settings it started with; more cycles may be asked for.
      v = resumed_settings(state.settings, args->value, explicitly_given(given),
                           {"checkpoint-every", "cycles"});
      std::cerr << "resuming " << *resume << " after cycle " << state.cycles_done
                << (state.step_in_cycle ? " (+" + std::to_string(state.step_in_cycle) + " steps)"
                                        : std::string())
                << "\n";
    }
    if (!start_from->empty()) {
      ProtocolState trained;
      sim.emplace(read_checkpoint(*start_from, &trained));
      if (trained.step_in_cycle != 0) {
        throw Error(*start_from +
                    ": written in the middle of a cycle; a new protocol starts "
                    "between cycles (--resume finishes that run)");
      }
      // The packing and its physics are the checkpoint's; the protocol is new. A checkpoint
      // written before --lid-pressure existed has an explicit lid mass.
      v = started_from_settings(
          trained.settings, args->value, explicitly_given(given),
          std::vector<std::string>(kPackingOptions, kPackingOptions + kPackingOptionCount),
          {"lid-pressure"}, *start_from);
      v["start-from"] = *start_from;
      state.settings = v;
      std::cerr << "starting from " << *start_from << " (after cycle " << trained.cycles_done
                << " of its run)\n";
    }
    const PhysicsOptions physics = physics_from(v);
    const DepositOptions d = deposit_from(v);
    d.validate();  // before any work or output
    const double box = d.box_side;
    const double radius = d.radius;
    const std::string out = v.at("out");
    std::string checkpoint = v.at("checkpoint");
    if (checkpoint.empty()) {
      const std::filesystem::path o(out);
      checkpoint = (o.parent_path() / (o.stem().string() + ".checkpoint.h5")).string();
      v["checkpoint"] = checkpoint;
    }

    physics.validate("simulate", d.radius * (1 - d.polydispersity));
    const double box_y = sim ? sim->container().size.y() : box;
    const double lid_mass =
        sim ? (sim->container().lid.present ? sim->container().lid.mass : 0) : d.lid_mass;

    // Every setting is checked before the packing is made.
    CyclicOptions c;
    c.cycles = whole(v, "cycles");
    c.drive = drive_from(v, physics, box, box_y, lid_mass, radius);
    c.out = out;
    c.full_compression_frames = yes_no(v, "full-compression");
    c.tracked_grains = whole_list(v, "track", "3,17,250");
    c.samples_per_cycle = whole(v, "samples-per-cycle");
    if (c.tracked_grains.empty() != (c.samples_per_cycle == 0)) {
      throw Error("--track and --samples-per-cycle go together: which grains, and how often");
    }
    {
      // Tracked grains must exist: a new packing's ids are 0 .. grains - 1.
      std::set<std::int64_t> ids;
      if (sim) ids.insert(sim->grains().id.begin(), sim->grains().id.end());
      for (std::int64_t id : c.tracked_grains) {
        const bool exists = sim ? ids.count(id) > 0 : id >= 0 && id < d.grains;
        if (!exists) throw Error("--track: there is no grain " + std::to_string(id));
      }
      std::set<std::int64_t> once(c.tracked_grains.begin(), c.tracked_grains.end());
      if (once.size() != c.tracked_grains.size()) throw Error("--track: a grain is listed twice");
    }
    c.checkpoint = checkpoint;
    c.checkpoint_every = whole(v, "checkpoint-every");
    c.keep_states = whole_list(v, "keep-states", "10,50,100");
    c.validate(box_y, physics.dt);
    {
      // The files a run writes: distinct, not the checkpoint it starts from, in folders
      // that exist (--resume writes its own checkpoint again, by design).
      std::vector<NamedPath> outputs{{"--out", c.out}, {"--checkpoint", c.checkpoint}};
      for (std::int64_t cycle : c.keep_states)
        outputs.push_back({"--keep-states", kept_state_path(c.out, cycle)});
      if (c.full_compression_frames)
        outputs.push_back({"--full-compression-frames", full_compression_path(c.out)});
      if (c.samples_per_cycle > 0) outputs.push_back({"--samples-per-cycle", in_cycle_path(c.out)});
      std::vector<NamedPath> inputs;
      if (!start_from->empty()) inputs.push_back({"--start-from", *start_from});
      check_outputs(outputs, inputs);
    }

    if (!sim) {
      std::cerr << "depositing " << d.grains << " grains (seed " << d.seed << ")\n";
      DepositSummary s;
      sim.emplace(deposit(d, physics, &s, print_deposit_progress(std::cerr)));
      std::cerr << "settled: packing fraction " << s.packing_fraction << ", lid at "
                << s.lid_height * 100 << " cm";
      if (d.lid_mass > 0) {
        std::cerr << " (" << d.lid_mass * 1e3 << " g, "
                  << lid_pressure(d.lid_mass, physics.gravity, d.box_side, d.box_side) << " Pa)";
      }
      std::cerr << ", " << s.contacts_per_grain << " contacts per grain\n";
      state.settings = v;
    }
    sim->set_threads(*threads);  // 0: by the number of grains
    for (const auto& [key, value] : v)
      c.parameters["simulate/" + key] = value;
    const double steps_per_cycle = std::round(c.drive.period / physics.dt);
    std::cerr << "cycling: A = " << c.drive.amplitude * 100 << " cm, period " << c.drive.period
              << " s (" << std::int64_t(steps_per_cycle) << " steps, peak wall speed "
              << c.drive.peak_speed() * 100 << " cm/s), " << c.cycles << " cycles\n";

    std::signal(SIGINT, request_stop);  // from here on, Ctrl-C writes a checkpoint
    std::signal(SIGTERM, request_stop);
    const CyclicSummary summary = run_cycles(
        *sim, c, state,
        [](const CyclicProgress& p) {
          std::cerr << "cycle " << p.cycle << "/" << p.cycles << "  " << std::scientific
                    << std::setprecision(2) << p.particle_steps_per_second << std::defaultfloat
                    << std::setprecision(6) << " particle-steps/s  "
                    << duration_text(p.seconds_left) << " left\n";
        },
        &g_stop);
    if (summary.interrupted) {
      std::cerr << "stopped after cycle " << summary.cycles_done << ": checkpoint " << checkpoint
                << " (continue with --resume " << checkpoint << ")\n";
      std::signal(SIGINT, SIG_DFL);
      std::signal(SIGTERM, SIG_DFL);
      throw CLI::RuntimeError(128 + g_stop_signal.load());
    }
    std::cout << "simulated " << summary.cycles_done << " cycles of " << sim->grains().size()
              << " grains: " << std::scientific << std::setprecision(3)
              << summary.particle_steps_per_second << std::defaultfloat << " particle-steps/s\n";
    for (const auto& p : summary.written)
      std::cout << "wrote " << p.string() << "\n";
    std::cout << "wrote " << checkpoint << "\n";
  });
  return {args, given};
}

}  // namespace granmem::app
