#include <iostream>

#include "commands.hpp"
#include "granmem/calibration/comparison.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"

namespace granmem::app {

void add_compare(CLI::App& app) {
  struct Args {
    std::string a, b, out, window, diameter, label_a = "A", label_b = "B", wall_distance = "0";
    bool subtract_drift = true;
    std::size_t steady_points = 0;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Compare two runs (experiment and simulation, or two simulations): end-of-cycle "
      "displacement and rotation distributions, KS and Wasserstein-1 distances, figures");
  cmd->add_option("a", args->a, "first trajectory store (.h5)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("b", args->b, "second trajectory store (.h5)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out, "output folder")->required();
  cmd->add_option("--window", args->window,
                  "FIRST:LAST cycles pooled into the distributions; default both runs' last 10 "
                  "common cycles");
  cmd->add_option("--diameter", args->diameter,
                  "grain diameter with a unit (0.5cm), the unit of lengths; default twice the "
                  "first run's median radius");
  cmd->add_option("--label-a", args->label_a, "name of the first run in figures")
      ->capture_default_str();
  cmd->add_option("--label-b", args->label_b, "name of the second run in figures")
      ->capture_default_str();
  cmd->add_option("--wall-distance", args->wall_distance,
                  "leave out grains closer than this to a container face (with a unit)")
      ->capture_default_str();
  add_drift_flags(cmd, args->subtract_drift);
  cmd->add_option("--steady-points", args->steady_points,
                  "relaxation (Fig. 3): hold the steady state at the mean of the last N cycles, "
                  "the paper's way (20 of its 500), instead of fitting it (0)")
      ->capture_default_str();
  cmd->callback([args] {
    const TrajectoryReader a(args->a), b(args->b);
    CompareOptions o;
    o.label_a = args->label_a;
    o.label_b = args->label_b;
    if (!args->window.empty()) o.window = parse_int_range(args->window, "--window");
    if (!args->diameter.empty()) {
      o.diameter = parse_si(args->diameter, Dimension::length, "", "--diameter");
    }
    o.wall_distance = parse_si(args->wall_distance, Dimension::length, "m", "--wall-distance");
    o.subtract_drift = args->subtract_drift;
    o.steady_points = args->steady_points;
    o.dir = args->out;
    const Comparison c = compare(a, b, o);
    for (const std::string& note : c.notes)
      std::cerr << "granmem: note: " << note << "\n";
    std::cout << c.Report() << "wrote " << c.written.size() << " files in " << args->out << "\n";
  });
}

}  // namespace granmem::app
