#include <iostream>

#include "commands.hpp"
#include "comparison_report.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"

namespace granmem::app {

void add_compare(CLI::App& app) {
  struct Args {
    std::string a, b, out, window, diameter, label_a = "A", label_b = "B", wall_distance = "0";
    bool keep_drift = false;
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
  cmd->add_flag("--keep-drift", args->keep_drift,
                "keep the packing's mean displacement (default: subtracted)");
  cmd->add_option("--steady-points", args->steady_points,
                  "relaxation (Fig. 3): hold the steady state at the mean of the last N cycles, "
                  "the paper's way (20 of its 500), instead of fitting it (0)")
      ->capture_default_str();
  cmd->callback([args] {
    const TrajectoryReader a(args->a), b(args->b);
    ObservableOptions o;
    o.motion.subtract_drift = !args->keep_drift;
    o.motion.wall_distance =
        parse_si(args->wall_distance, Dimension::length, "m", "--wall-distance");
    o.diameter = args->diameter.empty()
                     ? median_diameter(a)
                     : parse_si(args->diameter, Dimension::length, "", "--diameter");
    if (args->window.empty()) {
      const std::int64_t last = std::min(a.steps().back(), b.steps().back());
      const std::int64_t first = std::max(a.steps().front(), b.steps().front()) + 1;
      o.window = {std::max(first, last - 9), last};
    } else {
      o.window = parse_int_range(args->window, "--window");
    }
    PowerLawOptions relaxation;
    relaxation.steady_points = args->steady_points;
    const Comparison c = compare_runs(a, b, args->label_a, args->label_b, o,
                                      Eigen::Vector3d::Ones(), 0.0, args->out, relaxation);
    std::cout << "wrote " << c.written.size() << " files in " << args->out << "\n";
  });
}

}  // namespace granmem::app
