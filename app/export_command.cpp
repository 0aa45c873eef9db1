#include <iostream>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/particle_dump.hpp"
#include "granmem/core/units.hpp"

namespace granmem::app {

void add_export(CLI::App& app) {
  struct Args {
    std::string run, out, format, density;
    std::int64_t frame = -1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a run as a LAMMPS text dump or extended XYZ (OVITO), as trackpy's long CSV table, "
      "or one frame as a LAMMPS data file to start a LAMMPS run from");
  cmd->add_option("run", args->run, "trajectory store (.h5)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out,
                  "file to write (.dump, .lammpstrj, .xyz, .extxyz, .csv, .data)")
      ->required();
  cmd->add_option("--format", args->format,
                  "lammps, extxyz, csv or lammps-data; default from the file name")
      ->check(CLI::IsMember({"lammps", "extxyz", "csv", "lammps-data"}));
  cmd->add_option("--frame", args->frame,
                  "lammps-data: the frame written (index from 0; default the last)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--density", args->density,
                  "lammps-data: the grains' density with a unit (1.18g/cm^3); default the "
                  "simulation's");
  cmd->callback([args] {
    check_outputs({{"--out", args->out}}, {{"run", args->run}});
    std::string format = args->format;
    if (format.empty()) {
      const std::string ext = std::filesystem::path(args->out).extension().string();
      if (ext == ".dump" || ext == ".lammpstrj")
        format = "lammps";
      else if (ext == ".xyz" || ext == ".extxyz")
        format = "extxyz";
      else if (ext == ".csv")
        format = "csv";
      else if (ext == ".data")
        format = "lammps-data";
      else
        throw Error("--out " + args->out + ": say --format lammps, extxyz, csv or lammps-data");
    }
    const TrajectoryReader run(args->run);
    if (format == "lammps-data") {
      std::optional<double> density;
      if (!args->density.empty()) {
        density = parse_si(args->density, Dimension::density, "", "--density");
      }
      std::optional<std::size_t> frame;
      if (args->frame >= 0) frame = static_cast<std::size_t>(args->frame);
      write_lammps_data(run, frame, density, args->out);
      std::cout << "wrote " << args->out << " (LAMMPS data, units si)\n";
      return;
    }
    write_particle_dump(run, args->out,
                        format == "lammps"   ? DumpFormat::lammps
                        : format == "extxyz" ? DumpFormat::extxyz
                                             : DumpFormat::csv);
    std::cout << "wrote " << args->out << " (" << format << ", " << run.frame_count()
              << " frames)\n";
  });
}

}  // namespace granmem::app
