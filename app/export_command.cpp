#include <iostream>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/particle_dump.hpp"

namespace granmem::app {

void add_export(CLI::App& app) {
  struct Args {
    std::string run, out, format;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Write a run as a LAMMPS text dump or extended XYZ (OVITO), or as trackpy's long CSV table");
  cmd->add_option("run", args->run, "trajectory store (.h5)")->required()->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out, "file to write (.dump, .lammpstrj, .xyz, .extxyz, .csv)")
      ->required();
  cmd->add_option("--format", args->format, "lammps, extxyz or csv; default from the file name")
      ->check(CLI::IsMember({"lammps", "extxyz", "csv"}));
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
      else
        throw Error("--out " + args->out + ": say --format lammps, extxyz or csv");
    }
    const TrajectoryReader run(args->run);
    write_particle_dump(run, args->out,
                        format == "lammps"   ? DumpFormat::lammps
                        : format == "extxyz" ? DumpFormat::extxyz
                                             : DumpFormat::csv);
    std::cout << "wrote " << args->out << " (" << format << ", " << run.frame_count()
              << " frames)\n";
  });
}

}  // namespace granmem::app
