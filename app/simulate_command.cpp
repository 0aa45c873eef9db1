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
#include "granmem/sim/simulate.hpp"
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
  const RunSettings defaults = default_simulate_settings();
  for (std::size_t k = 0; k < kSimulateOptionCount; ++k) {
    const OptionSpec& o = kSimulateOptions[k];
    args->value[o.name] = defaults.at(o.name);
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
    SimulateOptions o;
    o.settings = args->value;
    o.given = explicitly_given(given);
    o.resume = *resume;
    o.start_from = *start_from;
    o.threads = *threads;
    o.log = [](const std::string& line) { std::cerr << line << "\n"; };
    o.deposit_progress = print_deposit_progress(std::cerr);
    o.progress = [](const CyclicProgress& p) {
      std::cerr << "cycle " << p.cycle << "/" << p.cycles << "  " << std::scientific
                << std::setprecision(2) << p.particle_steps_per_second << std::defaultfloat
                << std::setprecision(6) << " particle-steps/s  " << duration_text(p.seconds_left)
                << " left\n";
    };
    o.stop = &g_stop;
    o.cycles_start = [] {  // from here on, Ctrl-C and SIGTERM write a checkpoint
      std::signal(SIGINT, request_stop);
      std::signal(SIGTERM, request_stop);
    };
    const SimulateSummary summary = simulate(o);
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    if (summary.cycles.interrupted) {
      std::cerr << "stopped after cycle " << summary.cycles.cycles_done << ": checkpoint "
                << summary.checkpoint << " (continue with --resume " << summary.checkpoint << ")\n";
      throw CLI::RuntimeError(128 + g_stop_signal.load());
    }
    std::cout << summary.Report();
  });
  return {args, given};
}

}  // namespace granmem::app
