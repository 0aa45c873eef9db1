#include <iostream>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/import_table.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/units.hpp"
#include "granmem/core/xdmf.hpp"

namespace granmem::app {

void add_import(CLI::App& app) {
  struct Args {
    std::string table, out, length_unit = "voxel", voxel_size, container,
                            sample = kSampleEndOfCycle, columns, readings;
    double radius = 0;
    std::size_t skip_rows = 0;
    std::vector<long long> types;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "import",
      "Read a long-form CSV of tracked grains (frame,particle,x,y,z[,ax,ay,az][,radius]"
      "[,qw,qx,qy,qz][,hole_contact][,ep_x,ep_y,ep_z or ep][,axis_error]) or a LAMMPS text "
      "dump into a trajectory store");
  cmd->add_option("table", args->table,
                  "CSV (or tab-separated) table, one row per grain per frame, or a LAMMPS dump")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", args->out, "trajectory store to write (.h5)")->required();
  cmd->add_option("--length-unit", args->length_unit, "unit of x,y,z and radius in the table")
      ->check(CLI::IsMember({"m", "cm", "mm", "um", "voxel"}))
      ->capture_default_str();
  cmd->add_option("--voxel-size", args->voxel_size,
                  "voxel size X[,Y,Z] with a unit, e.g. 0.05,0.05,0.075mm (voxel tables)");
  CLI::Option* radius =
      cmd->add_option("--radius", args->radius, "grain radius for tables without a radius column");
  cmd->add_option("--container", args->container,
                  "container xmin,ymin,zmin,xmax,ymax,zmax in the table's unit");
  cmd->add_option("--sample", args->sample, "what a frame is")
      ->check(CLI::IsMember({kSampleEndOfCycle, kSampleFullCompression, kSampleInCycle}))
      ->capture_default_str();
  cmd->add_option("--columns", args->columns,
                  "the table's names for granmem's columns, NAME=column,... e.g. TrackMate's "
                  "FRAME=frame,TRACK_ID=particle,POSITION_X=x,POSITION_Y=y,POSITION_Z=z");
  cmd->add_option("--types", args->types,
                  "LAMMPS dumps: the atom types that are grains, e.g. 1 (default: every atom)")
      ->delimiter(',');
  add_readings_option(cmd, args->readings);
  cmd->add_option("--skip-rows", args->skip_rows,
                  "lines after the header that are not data (TrackMate's CSV: 3)")
      ->capture_default_str();

  cmd->callback([args, cmd, radius] {
    check_outputs({{"--out", args->out}, {"--out's XDMF", xdmf_path(args->out)}},
                  {{"table", args->table}, {"--readings", args->readings}});
    ImportOptions options;
    options.length_unit = args->length_unit;
    if (radius->count()) options.radius = args->radius;
    options.sample = args->sample;
    if (!args->voxel_size.empty()) {
      const std::vector<Quantity> v = parse_quantity_list(args->voxel_size, "--voxel-size");
      if (v.size() != 1 && v.size() != 3) {
        throw Error("--voxel-size '" + args->voxel_size + "': expected one size or three (x,y,z)");
      }
      options.voxel_size = v.size() == 1 ? Eigen::Vector3d::Constant(v[0].value)
                                         : Eigen::Vector3d(v[0].value, v[1].value, v[2].value);
      options.voxel_size_unit = v[0].unit;
    }
    if (!args->container.empty()) options.box = parse_box(args->container, "--container");
    options.csv.rename = parse_renames(args->columns, "--columns");
    options.csv.skip_rows = args->skip_rows;
    options.types.insert(args->types.begin(), args->types.end());
    options.readings = args->readings;

    ImportSummary summary;
    Trajectories run = import_table(args->table, options, &summary);
    run.header.parameters = used_options(*cmd);
    write_trajectories(args->out, run);

    std::cout << summary.Report() << "wrote " << args->out << " and "
              << xdmf_path(args->out).string() << "\n";
  });
}

}  // namespace granmem::app
