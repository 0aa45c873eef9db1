#include <algorithm>
#include <iostream>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/units.hpp"
#include "granmem/tracking/locate_scan.hpp"
#include "granmem/tracking/stack.hpp"
#include "granmem/tracking/track_run.hpp"
#include "tracking_steps.hpp"

namespace granmem::app {

void add_locate_options(CLI::App* cmd, LocateArgs& args) {
  cmd->add_option("--diameter,-d", args.diameter,
                  "grain diameter: in voxels along x (12, 12vox) or a length (1.5mm)")
      ->required();
  cmd->add_option("--voxel-size", args.voxel_size,
                  "voxel size x,y,z (or one for cubic voxels) with a unit (0.1,0.1,0.15mm); "
                  "replaces the file's; without either, positions are in voxels");
  cmd->add_option("--dataset", args.dataset, "HDF5 sources: the (z,y,x) dataset to read");
  cmd->add_option("--region", args.region,
                  "read only the box x0,y0,z0,nx,ny,nz (voxels; 0: to the end)");
  cmd->add_option("--polarity", args.polarity,
                  "dark: dark grains with bright holes in bright fluid; bright: bright grains "
                  "on dark fluid, no hole")
      ->check(CLI::IsMember({"dark", "bright"}))
      ->capture_default_str();
  cmd->add_option("--hole-fraction", args.hole_fraction,
                  "hole diameter over grain diameter (dark grains); 0: no hole")
      ->check(CLI::Range(0.0, 0.8))
      ->capture_default_str();
  cmd->add_option("--beam", args.beam,
                  "the laser sheet's path across the slices: x or y (or the side it enters, as "
                  "render takes it: +x, -x, +y, -y)")
      ->check(CLI::IsMember({"x", "y", "+x", "-x", "+y", "-y"}))
      ->capture_default_str();
  cmd->add_option("--axis", args.axis,
                  "the hole's axis: fitted with the grain model, or the lab's classical "
                  "estimate (principal axis of the bright hole voxels within 0.8 R)")
      ->check(CLI::IsMember({"fit", "lab"}))
      ->capture_default_str();
  cmd->add_option("--passes", args.passes,
                  "model fits of every grain (neighbours modelled from the second)")
      ->check(CLI::Range(1, 10))
      ->capture_default_str();
  cmd->add_flag("--no-illumination", args.no_illumination,
                "skip the illumination correction (evenly lit or corrected scans)");
}

ScanLocateOptions scan_locate_options(const LocateArgs& args) {
  ScanLocateOptions o;
  o.read.dataset = args.dataset;
  if (!args.region.empty()) o.read.region = parse_region(args.region, "--region");
  if (!args.voxel_size.empty()) {
    const VoxelSize v = parse_voxel_size(args.voxel_size, "--voxel-size");
    if (v.unit.empty() || !is_physical_length_unit(v.unit)) {
      throw Error("--voxel-size '" + args.voxel_size + "': give a unit (m, cm, mm, um)");
    }
    o.read.voxel_size = v.size;
    o.read.unit = v.unit;
  }
  o.diameter = args.diameter;
  o.locate.dark_grains = args.polarity == "dark";
  o.locate.hole_fraction = o.locate.dark_grains ? args.hole_fraction : 0.0;
  o.locate.beam_axis = args.beam.back() == 'y' ? 1 : 0;
  o.locate.passes = args.passes;
  o.locate.fit_axis = args.axis == "fit";
  o.locate.correct_illumination = !args.no_illumination;
  return o;
}

Detections locate_scan(const std::string& path, const LocateArgs& args, std::int64_t frame) {
  ScanLocateOptions o = scan_locate_options(args);
  o.frame = frame;
  LocatedScan s = granmem::locate_scan(path, o);
  std::cout << s.Report();
  return std::move(s.detections);
}

void add_locate(CLI::App& app) {
  struct Args {
    std::string stack, out, csv;
    std::int64_t frame = 0;
    LocateArgs locate;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "locate", "Locate every grain of a scan: centre, radius, hole axis, quality");
  cmd->add_option("stack", args->stack,
                  "multi-page TIFF, folder of slice images (TIFF/PNG) or HDF5 file")
      ->required();
  cmd->add_option("--out,-o", args->out, "detections to write (.h5, or .csv)")->required();
  cmd->add_option("--csv", args->csv, "also write the detections as CSV");
  cmd->add_option("--frame", args->frame, "the scan's index, written in the frame column")
      ->capture_default_str();
  add_locate_options(cmd, args->locate);
  cmd->callback([args] {
    std::vector<NamedPath> outputs{{"--out", args->out}};
    if (!args->csv.empty()) outputs.push_back({"--csv", args->csv});
    check_outputs(outputs, {{"stack", args->stack}});
    const Detections d = locate_scan(args->stack, args->locate, args->frame);
    write_detections(d, args->out);
    if (!args->csv.empty()) write_detections(d, args->csv);
    std::cout << "wrote " << args->out << (args->csv.empty() ? "" : " and " + args->csv) << "\n";
  });
}

void add_track(CLI::App& app) {
  struct Args {
    std::vector<std::string> scans;
    std::string out, detections, analyze;
    LocateArgs locate;
    LinkArgs link;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "track", "Locate the grains of a series of scans and link them into trajectories");
  cmd->add_option("scans", args->scans,
                  "the scans (TIFF, folder of slices or HDF5), taken in the natural order of "
                  "their names (scan2 before scan10)")
      ->required();
  cmd->add_option("--out,-o", args->out, "trajectory store to write (.h5)")->required();
  cmd->add_option("--detections", args->detections,
                  "folder to keep each scan's detections in (scan name + .h5)");
  cmd->add_option("--analyze", args->analyze,
                  "then analyze the trajectories into this folder (as granmem analyze, "
                  "grains touching through their hole left out of the rotations)");
  add_locate_options(cmd, args->locate);
  add_link_options(cmd, args->link);
  cmd->callback([args, cmd] {
    std::vector<std::string> scans = args->scans;
    std::stable_sort(scans.begin(), scans.end(), natural_less);
    TrackRunOptions options;
    options.scans.assign(scans.begin(), scans.end());
    options.locate = scan_locate_options(args->locate);
    options.detections = args->detections;
    options.link = link_run_options(args->link);
    options.out = args->out;
    options.report = args->link.report;
    options.parameters = used_options(*cmd);
    options.log = [](const std::string& line) { std::cout << line << std::flush; };
    // Every option good, every scan there and every output safe to write, before the first
    // is located.
    options.validate();
    std::vector<NamedPath> inputs, outputs = link_outputs(args->link, args->out);
    if (!args->detections.empty()) std::filesystem::create_directories(args->detections);
    for (const std::string& scan : scans) {
      inputs.push_back({"scan", scan});
      if (!args->detections.empty()) {
        outputs.push_back({"--detections of " + scan, detections_path(args->detections, scan)});
      }
    }
    if (!args->link.readings.empty()) inputs.push_back({"--readings", args->link.readings});
    check_outputs(outputs, inputs);
    const TrackSummary tracked = track_run(options);
    for (const std::string& note : tracked.linked.notes)
      std::cerr << "granmem: note: " << note << "\n";
    std::cout << tracked.Report();
    if (!args->analyze.empty()) {
      AnalysisOptions options;
      options.motion.hole_contacts = HoleContactPolicy::exclude_rotations;  // the paper's choice
      analyze_and_report(TrajectoryReader(args->out), options, args->analyze,
                         {{"hole-contacts", "exclude-rotations"}});
    }
  });
}

}  // namespace granmem::app
