#include <iomanip>
#include <iostream>

#include "commands.hpp"
#include "granmem/calibration/readout.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/sim/ranks.hpp"

namespace granmem::app {

void add_readout(CLI::App& app) {
  struct Args {
    std::vector<std::string> from;
    std::string amplitudes = "0.05%:2.5%:12", out, drive = "asymmetric", wall_motion = "cosine";
    std::int64_t cycles = 1;
    double inertial_number = ReadoutSweepOptions{}.inertial_number;
    bool training_amplitude = true;
    int parallel = 0;
    std::size_t bootstrap = 200;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "readout",
      "Read a trained packing's memory out: one cycle at each amplitude of a sweep, "
      "every run from the same trained state");
  cmd->add_option("--from", args->from,
                  "trained states (checkpoints, e.g. simulate --keep-states), one curve each")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--amplitudes", args->amplitudes,
                  "read-out amplitudes A', % of the box: lo%:hi%:count (log-spaced) or a list")
      ->capture_default_str();
  cmd->add_option("--cycles", args->cycles, "read-out cycles per amplitude")->capture_default_str();
  cmd->add_option("--drive", args->drive, "asymmetric (0 -> A' -> 0) or symmetric")
      ->capture_default_str();
  cmd->add_option("--wall-motion", args->wall_motion, "cosine or linear")->capture_default_str();
  cmd->add_option("--inertial-number", args->inertial_number,
                  "quasi-static limit that times each cycle (the wall's peak speed)")
      ->capture_default_str();
  cmd->add_option("--training-amplitude", args->training_amplitude,
                  "add each state's training amplitude to its sweep")
      ->capture_default_str();
  cmd->add_option("--parallel", args->parallel,
                  "runs at once, and the cores they use (0: one per core; the last run also takes "
                  "the cores the others leave)")
      ->capture_default_str();
  cmd->add_option("--bootstrap", args->bootstrap, "resamples of the grains for the errors")
      ->capture_default_str();
  cmd->add_option("--out,-o", args->out,
                  "output folder: one store per run, readout.csv; finished runs are reused")
      ->required();

  cmd->callback([args] {
    ReadoutOptions o;
    for (const std::string& s : args->from)
      o.sweep.states.emplace_back(s);
    o.sweep.amplitudes = parse_amplitude_sweep(args->amplitudes);
    o.sweep.cycles = args->cycles;
    o.sweep.symmetry = parse_drive_symmetry(args->drive);
    o.sweep.shape = parse_drive_shape(args->wall_motion);
    o.sweep.inertial_number = args->inertial_number;
    o.sweep.include_training_amplitude = args->training_amplitude;
    o.sweep.pool.parallel = args->parallel;
    o.sweep.dir = args->out;
    o.bootstrap = args->bootstrap;
    const bool root = mpi_ranks().root();  // in an MPI job, rank 0 speaks
    const ReadoutSummary s = readout(o, [root](const ReadoutSweepProgress& p) {
      if (!root) return;
      std::cerr << "readout: " << p.done << "/" << p.runs << " runs done, "
                << duration_text(p.seconds_left) << " left\n";
    });
    if (!root) return;
    std::size_t reused = 0;
    for (const ReadoutRun& r : s.sweep.runs)
      reused += r.reused;
    std::cout << "read out " << o.sweep.states.size() << " state(s) at " << s.sweep.runs.size()
              << " amplitudes in all (" << reused << " runs reused) in "
              << duration_text(s.sweep.wall_seconds) << "\n";
    std::cout << std::setw(6) << "state" << std::setw(9) << "trained" << std::setw(9) << "A' [%]"
              << std::setw(7) << "cycle" << std::setw(12) << "dr [d]" << std::setw(12) << "rot1 [d]"
              << std::setw(12) << "rot [d]\n";
    for (const ReadoutPoint& p : s.points) {
      std::cout << std::setprecision(4) << std::setw(6) << p.state << std::setw(9)
                << p.trained_cycles << std::setw(9) << p.amplitude * 100 << std::setw(7) << p.cycle
                << std::setw(12) << p.dr << std::setw(12) << p.rot_single << std::setw(12)
                << p.rot_full << "\n";
    }
    for (const StateSignature& m : s.signatures) {
      std::cout << "state " << m.state << " (" << m.trained_cycles << " cycles at "
                << m.training_amplitude * 100 << " %): dr dip " << m.dr_dip.depth << " +- "
                << m.dr_dip.depth_error << ", dr / untrained " << m.dr_untrained.ratio << " +- "
                << m.dr_untrained.error << ", rot1 exponents " << m.rot_single.below.exponent
                << " below, " << m.rot_single.above.exponent << " above\n";
    }
    std::cout << "wrote " << s.table.string() << ", " << s.signature_table.string() << "\n";
  });
}

}  // namespace granmem::app
