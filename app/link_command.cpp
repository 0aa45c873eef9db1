#include <iostream>
#include <optional>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/units.hpp"
#include "granmem/core/xdmf.hpp"
#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/link_run.hpp"
#include "tracking_steps.hpp"

namespace granmem::app {

LinkRunOptions link_run_options(const LinkArgs& args) {
  LinkRunOptions o;
  o.max_displacement = args.max_displacement;
  o.memory = args.memory;
  o.collective_motion = !args.no_drift;
  o.container = args.container;
  o.container_size = args.container_size;
  o.first_cycle = args.first_cycle;
  o.readings = args.readings;
  return o;
}

void add_link_options(CLI::App* cmd, LinkArgs& args) {
  cmd->add_option("--max-displacement", args.max_displacement,
                  "largest distance of a grain from where it is expected, in the detections' "
                  "unit or with a unit (0.4mm); auto: 0.7 median grain diameter")
      ->capture_default_str();
  cmd->add_option("--memory", args.memory, "scans a grain may go unseen and still rejoin its track")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--no-collective-motion", args.no_drift,
                "do not estimate the collective motion (drift, uniform deformation, local "
                "displacement field) between scans");
  cmd->add_option("--container", args.container,
                  "the container in the scans' frame, xmin,ymin,zmin,xmax,ymax,zmax with a unit "
                  "(e.g. 1.2,0.8,0.5,6.2,5.8,7.5cm): positions are stored in its frame and it "
                  "is the store's box, as the DEM's");
  cmd->add_option("--container-size", args.container_size,
                  "the container's edges LX,LY,LZ with a unit, its position found from the "
                  "packing's extent in the first scan (grains pressed into it touch its floor "
                  "and walls: centred between the walls across x and y, its bottom layer "
                  "resting on the floor); instead of --container");
  cmd->add_option("--first-cycle", args.first_cycle,
                  "the cycle at whose end the first scan was taken, where the scans do not say "
                  "theirs: frames numbered from it in the order given (the last 10 of 500: "
                  "491)")
      ->capture_default_str();
  add_readings_option(cmd, args.readings);
  cmd->add_option("--report", args.report,
                  "CSV of what could not be linked: tracks lost and detections starting a track");
}

std::vector<NamedPath> link_outputs(const LinkArgs& args, const std::string& out) {
  std::vector<NamedPath> outputs{{"--out", out}, {"--out's XDMF", xdmf_path(out)}};
  if (!args.report.empty()) outputs.push_back({"--report", args.report});
  return outputs;
}

void link_and_write(std::vector<Detections> scans, const std::vector<std::string>& names,
                    const LinkArgs& args, const std::string& out, const CLI::App& cmd) {
  const LinkRun linked = link_run(std::move(scans), names, link_run_options(args));
  for (const std::string& note : linked.notes)
    std::cerr << "granmem: note: " << note << "\n";
  const std::vector<std::filesystem::path> written =
      write_link_run(linked, out, args.report, used_options(cmd));
  std::cout << linked.Report() << "wrote";
  for (std::size_t k = 0; k < written.size(); ++k)
    std::cout << (k ? (k + 1 == written.size() ? " and " : ", ") : " ") << written[k].string();
  std::cout << "\n";
}

void add_link(CLI::App& app) {
  struct Args {
    std::vector<std::string> scans;
    std::string out;
    LinkArgs link;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd =
      app.add_subcommand("link", "Link the detections of successive scans into grain trajectories");
  cmd->add_option("scans", args->scans, "detections of each scan (.h5 or .csv), in scan order")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out, "trajectory store to write (.h5)")->required();
  add_link_options(cmd, args->link);
  cmd->callback([args, cmd] {
    std::vector<NamedPath> inputs;
    for (const std::string& path : args->scans)
      inputs.push_back({"scan", path});
    if (!args->link.readings.empty()) inputs.push_back({"--readings", args->link.readings});
    link_run_options(args->link).validate();
    check_outputs(link_outputs(args->link, args->out), inputs);
    std::vector<Detections> scans;
    scans.reserve(args->scans.size());
    for (const std::string& path : args->scans) {
      scans.push_back(read_detections(path));
      scans.back().source = path;  // names the scan in messages
    }
    link_and_write(std::move(scans), args->scans, args->link, args->out, *cmd);
  });
}

}  // namespace granmem::app
