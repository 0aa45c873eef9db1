#include "granmem/tracking/link_run.hpp"

#include <iomanip>
#include <optional>
#include <sstream>

#include "granmem/core/apparatus_readings.hpp"
#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/units.hpp"
#include "granmem/core/xdmf.hpp"

namespace granmem {
namespace {

std::string vector_text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << std::setprecision(4) << "(" << v[0] << ", " << v[1] << ", " << v[2] << ")";
  return s.str();
}

// Detections located one stack at a time all say frame 0: numbered as given, from the
// first cycle.
void number_frames(std::vector<Detections>& scans, std::int64_t first,
                   std::vector<std::string>& notes) {
  bool same_frame = true;
  for (const Detections& d : scans)
    same_frame = same_frame && d.frame == scans.front().frame;
  bool from_first = true;  // already numbered so (track numbers its scans as it locates them)
  for (std::size_t t = 0; t < scans.size(); ++t)
    from_first = from_first && scans[t].frame == first + std::int64_t(t);
  if (from_first) return;
  if (!same_frame && first != 0) {
    throw Error("--first-cycle " + std::to_string(first) + ": the scans say their own frames (" +
                std::to_string(scans.front().frame) + ", " + std::to_string(scans[1].frame) +
                ", ...); it numbers scans that do not");
  }
  if (!same_frame || (scans.size() < 2 && first == 0)) return;
  notes.push_back("every scan says frame " + std::to_string(scans.front().frame) + ": numbered " +
                  std::to_string(first) + ".." +
                  std::to_string(first + std::int64_t(scans.size()) - 1) + " in the order given");
  for (std::size_t t = 0; t < scans.size(); ++t)
    scans[t].frame = first + std::int64_t(t);
}

void check_units(const std::vector<Detections>& scans, const std::vector<std::string>& names) {
  const std::string& unit = scans.front().length_unit;
  for (std::size_t t = 1; t < scans.size(); ++t) {
    if (scans[t].length_unit != unit) {
      throw Error(names[t] + ": lengths in " + scans[t].length_unit + ", but " + names[0] + " in " +
                  unit + ": all scans must use one length unit");
    }
  }
}

LinkOptions link_options(const LinkRunOptions& o, const std::string& unit) {
  LinkOptions options;
  if (o.max_displacement != "auto") {
    options.max_displacement = parse_length(o.max_displacement, unit, "--max-displacement");
  }
  options.memory = o.memory;
  options.estimate_drift = o.collective_motion;
  options.local_field = o.collective_motion;
  options.log = o.log;
  options.stop = o.stop;
  return options;
}

// The run in the container's frame, given or found from the packing's extent.
void register_run(LinkRun& r, const LinkRunOptions& o, const std::string& unit) {
  if (!o.container.empty()) {
    const Box container = parse_box(o.container, "--container", unit);
    r.origin = container.lower;
    register_to_container(r.run, container);
  } else if (!o.container_size.empty()) {
    r.found_container =
        container_from_extent(r.run, parse_edges(o.container_size, unit, "--container-size"));
    std::ostringstream note;
    note << "container found from the packing's extent: lower corner "
         << r.found_container->lower.x() << "," << r.found_container->lower.y() << ","
         << r.found_container->lower.z() << " " << unit;
    r.notes.push_back(note.str());
    r.origin = r.found_container->lower;
    register_to_container(r.run, *r.found_container);
  }
}

}  // namespace

void LinkRunOptions::validate() const {
  if (memory < 0) throw Error("--memory: 0 or more scans");
  if (first_cycle < 0) throw Error("--first-cycle: a cycle, 0 or more");
  if (!container.empty() && !container_size.empty()) {
    throw Error("--container and --container-size: give the container or its size, not both");
  }
  if (!container_size.empty()) parse_edges(container_size, "m", "--container-size");
  if (!readings.empty()) read_apparatus_readings(readings);  // its errors before any scan's
  if (container.empty()) return;
  const Quantity last = parse_quantity_list(container, "--container").back();
  if (!is_physical_length_unit(last.unit)) {
    throw Error("--container '" + container +
                "': expected xmin,ymin,zmin,xmax,ymax,zmax with a length unit, e.g. "
                "0,0,0,5,5,7cm");
  }
  parse_box(container, "--container", last.unit);  // six values, each max above its min
}

LinkRun link_run(std::vector<Detections> scans, const std::vector<std::string>& names,
                 const LinkRunOptions& options) {
  options.validate();
  if (scans.empty()) throw Error("link: no scans");
  if (names.size() != scans.size()) throw Error("link: a name per scan");
  LinkRun r;
  number_frames(scans, options.first_cycle, r.notes);
  check_units(scans, names);
  const std::string unit = scans.front().length_unit;
  r.run = link_scans(scans, link_options(options, unit), &r.summary);
  register_run(r, options, unit);
  if (!options.readings.empty())
    r.notes.push_back(attach_apparatus_readings(r.run, options.readings));
  r.scans = std::move(scans);
  return r;
}

std::string LinkRun::Report() const {
  const std::string& unit = summary.length_unit;
  std::ostringstream out;
  out << "linked " << scans.size() << " scans: " << summary.tracks << " tracks, max displacement "
      << summary.max_displacement << " " << unit << "\n";
  out << std::setw(7) << "frame" << std::setw(9) << "grains" << std::setw(10) << "linked"
      << std::setw(8) << "from_mem" << std::setw(9) << "started" << std::setw(8) << "lost"
      << std::setw(7) << "kept" << std::setw(7) << "ended"
      << "  drift [" << unit << "], rms residual\n";
  for (const ScanLinks& s : summary.scans) {
    out << std::setw(7) << s.frame << std::setw(9) << s.detections;
    std::ostringstream linked;
    if (s.previous > 0) {
      linked << std::fixed << std::setprecision(2) << 100 * s.linked_fraction() << "%";
    } else {
      linked << "-";
    }
    out << std::setw(10) << linked.str() << std::setw(8) << s.relinked << std::setw(9) << s.started
        << std::setw(8) << s.unlinked << std::setw(7) << s.kept << std::setw(7) << s.ended;
    if (s.previous > 0) {
      out << "  " << vector_text(s.mean_displacement) << ", " << std::setprecision(3)
          << s.rms_residual;
    }
    out << "\n";
  }
  return out.str();
}

Table unlinked_table(const LinkRun& linked) {
  const LinkSummary& summary = linked.summary;
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
      particle.values.push_back(double(linked.run.header.id[std::size_t(track)]));
      detection.values.push_back(double(det));
      lost.values.push_back(gone ? 1 : 0);
      for (int a = 0; a < 3; ++a)
        x[a]->values.push_back(where(a));
    };
    for (std::int64_t track : r.unlinked_tracks)
      row(track, -1, true, linked.run.frames[s - 1].position.row(Eigen::Index(track)));
    for (std::size_t k = 0; k < r.new_detections.size(); ++k) {
      const std::size_t j = r.new_detections[k];
      const Eigen::RowVector3d at =
          linked.scans[s].position.row(Eigen::Index(j)) - linked.origin.transpose();
      row(r.first_new_track + std::int64_t(k), std::int64_t(j), false, at);
    }
  }
  return t;
}

std::vector<std::filesystem::path> write_link_run(
    const LinkRun& linked, const std::filesystem::path& out, const std::filesystem::path& report,
    const std::map<std::string, std::string>& parameters) {
  RunHeader header = linked.run.header;
  for (const auto& [key, value] : parameters)
    header.parameters[key] = value;
  TrajectoryWriter writer(out, header);
  for (const Frame& frame : linked.run.frames)
    writer.append(frame);
  for (const auto& [name, observable] : linked.run.observables)
    writer.set_observable(name, observable);
  std::optional<AtomicFile> table;
  if (!report.empty()) {
    table.emplace(report);
    write_csv(unlinked_table(linked), *table,
              {"granmem link: what could not be linked, lengths in " + linked.summary.length_unit,
               "lost=1: track seen in the scan before (at x,y,z) and not found in this frame",
               "lost=0: detection of this frame starting a new track"});
  }
  writer.commit();
  std::vector<std::filesystem::path> written{out, xdmf_path(out)};
  if (table) {
    table->commit();
    written.push_back(report);
  }
  return written;
}

}  // namespace granmem
