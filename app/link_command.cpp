#include <cstdio>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "commands.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/units.hpp"
#include "granmem/core/xdmf.hpp"
#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/link.hpp"
#include "tracking_steps.hpp"

namespace granmem::app {
namespace {

std::string vector_text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::setprecision(4) << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return s.str();
}

// What could not be linked, one row per event: a track seen in the scan before and not
// found in this one (lost = 1, at its last position, detection -1), or a detection of this
// scan starting a new track (lost = 0).
Table unlinked_table(const Trajectories& run, const LinkSummary& summary,
                     const std::vector<Detections>& scans) {
  Table t;
  Column& frame = t.add("frame", "", true);
  Column& particle = t.add("particle", "", true);
  Column& detection = t.add("detection", "", true);
  Column& lost = t.add("lost", "", true);
  Column* x[3] = {&t.add("x", summary.length_unit), &t.add("y", summary.length_unit),
                  &t.add("z", summary.length_unit)};
  for (std::size_t s = 1; s < summary.scans.size(); ++s) {
    const ScanLinks& r = summary.scans[s];
    auto row = [&](std::int64_t track, std::int64_t det, bool gone, const auto& where) {
      frame.values.push_back(double(r.frame));
      particle.values.push_back(double(run.header.id[std::size_t(track)]));
      detection.values.push_back(double(det));
      lost.values.push_back(gone ? 1 : 0);
      for (int a = 0; a < 3; ++a)
        x[a]->values.push_back(where(a));
    };
    for (std::int64_t track : r.unlinked_tracks)
      row(track, -1, true, run.frames[s - 1].position.row(Eigen::Index(track)));
    for (std::size_t k = 0; k < r.new_detections.size(); ++k) {
      const std::size_t j = r.new_detections[k];
      row(r.first_new_track + std::int64_t(k), std::int64_t(j), false,
          scans[s].position.row(Eigen::Index(j)));
    }
  }
  return t;
}

}  // namespace

void add_link_options(CLI::App* cmd, LinkArgs& args) {
  cmd->add_option("--max-displacement", args.max_displacement,
                  "largest distance of a grain from where it is expected, in the detections' "
                  "unit or with a unit (0.4mm); auto: 0.7 median grain diameter")
      ->capture_default_str();
  cmd->add_option("--memory", args.memory, "scans a grain may go unseen and still rejoin its track")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--no-drift", args.no_drift,
                "do not estimate the collective motion (drift, uniform deformation, local "
                "displacement field) between scans");
  cmd->add_option("--container", args.container,
                  "the container in the scans' frame, xmin,ymin,zmin,xmax,ymax,zmax with a unit "
                  "(e.g. 1.2,0.8,0.5,6.2,5.8,7.5cm): positions are stored in its frame and it "
                  "is the store's box, as the DEM's");
  cmd->add_option("--container-size", args.container_size,
                  "the container's edges LX,LY,LZ with a unit, its position found from the "
                  "packing's extent in the first scan (lowest x - r, y - r, z - r: grains "
                  "pressed into it touch its floor and walls); instead of --container");
  cmd->add_option("--report", args.report,
                  "CSV of what could not be linked: tracks lost and detections starting a track");
}

std::vector<NamedPath> link_outputs(const LinkArgs& args, const std::string& out) {
  std::vector<NamedPath> outputs{{"--out", out}, {"--out's XDMF", xdmf_path(out)}};
  if (!args.report.empty()) outputs.push_back({"--report", args.report});
  return outputs;
}

void validate(const LinkArgs& args) {
  if (!args.container.empty() && !args.container_size.empty()) {
    throw Error("--container and --container-size: give the container or its size, not both");
  }
  if (!args.container_size.empty()) parse_edges(args.container_size, "m", "--container-size");
  if (args.container.empty()) return;
  const Quantity last = parse_quantity_list(args.container, "--container").back();
  if (!is_physical_length_unit(last.unit)) {
    throw Error("--container '" + args.container +
                "': expected xmin,ymin,zmin,xmax,ymax,zmax with a length unit, e.g. "
                "0,0,0,5,5,7cm");
  }
  parse_box(args.container, "--container", last.unit);  // six values, each max above its min
}

void link_and_write(std::vector<Detections> scans, const std::vector<std::string>& names,
                    const LinkArgs& args, const std::string& out, const CLI::App& cmd) {
  // Detections located one stack at a time all say frame 0: number them as given.
  bool same_frame = true;
  for (const Detections& d : scans)
    same_frame = same_frame && d.frame == scans.front().frame;
  if (same_frame && scans.size() > 1) {
    for (std::size_t t = 0; t < scans.size(); ++t)
      scans[t].frame = std::int64_t(t);
    std::cerr << "granmem: note: every scan says frame " << scans.front().frame << ": numbered 0.."
              << scans.size() - 1 << " in the order given\n";
  }
  const std::string unit = scans.front().length_unit;
  for (std::size_t t = 1; t < scans.size(); ++t) {
    if (scans[t].length_unit != unit) {
      throw Error(names[t] + ": lengths in " + scans[t].length_unit + ", but " + names[0] + " in " +
                  unit + ": all scans must use one length unit");
    }
  }

  LinkOptions options;
  if (args.max_displacement != "auto") {
    options.max_displacement = parse_length(args.max_displacement, unit, "--max-displacement");
  }
  options.memory = args.memory;
  options.estimate_drift = !args.no_drift;
  options.local_field = !args.no_drift;

  LinkSummary summary;
  Trajectories run = link_scans(scans, options, &summary);
  if (!args.container.empty()) {
    register_to_container(run, parse_box(args.container, "--container", unit));
  } else if (!args.container_size.empty()) {
    const Box found =
        container_from_extent(run, parse_edges(args.container_size, unit, "--container-size"));
    std::cerr << "container found from the packing's extent: lower corner " << found.lower.x()
              << "," << found.lower.y() << "," << found.lower.z() << " " << unit << "\n";
    register_to_container(run, found);
  }
  for (const auto& [key, value] : used_options(cmd))
    run.header.parameters[key] = value;

  // Everything is written under temporary names first, then renamed into place.
  TrajectoryWriter writer(out, run.header);
  for (const Frame& frame : run.frames)
    writer.append(frame);
  std::optional<AtomicFile> report;
  if (!args.report.empty()) {
    report.emplace(args.report);
    write_csv(unlinked_table(run, summary, scans), *report,
              {"granmem link: what could not be linked, lengths in " + unit,
               "lost=1: track seen in the scan before (at x,y,z) and not found in this frame",
               "lost=0: detection of this frame starting a new track"});
  }
  writer.commit();
  if (report) report->commit();

  std::cout << "linked " << scans.size() << " scans: " << summary.tracks
            << " tracks, max displacement " << summary.max_displacement << " " << unit << "\n";
  std::cout << std::setw(7) << "frame" << std::setw(9) << "grains" << std::setw(10) << "linked"
            << std::setw(8) << "from_mem" << std::setw(9) << "started" << std::setw(8) << "lost"
            << std::setw(7) << "kept" << std::setw(7) << "ended"
            << "  drift [" << unit << "], rms residual\n";
  for (const ScanLinks& r : summary.scans) {
    std::cout << std::setw(7) << r.frame << std::setw(9) << r.detections;
    std::ostringstream linked;
    if (r.previous > 0) {
      linked << std::fixed << std::setprecision(2) << 100 * r.linked_fraction() << "%";
    } else {
      linked << "-";
    }
    std::cout << std::setw(10) << linked.str() << std::setw(8) << r.relinked << std::setw(9)
              << r.started << std::setw(8) << r.unlinked << std::setw(7) << r.kept << std::setw(7)
              << r.ended;
    if (r.previous > 0) {
      std::cout << "  " << vector_text(r.mean_displacement) << ", " << std::setprecision(3)
                << r.rms_residual;
    }
    std::cout << "\n";
  }
  std::cout << "wrote " << out << " and " << xdmf_path(out).string();
  if (report) std::cout << " and " << args.report;
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
    validate(args->link);
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
