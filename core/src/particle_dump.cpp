#include "granmem/core/particle_dump.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/trajectory_table.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

void number(std::string& out, double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, r.ptr);
}

// The box of a frame: the container if the run has one, else the grains' bounding box.
Box frame_box(const RunHeader& h, const Frame& f) {
  if (h.box) return *h.box;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(0), hi = lo;
  bool any = false;
  for (Eigen::Index i = 0; i < f.position.rows(); ++i) {
    const Eigen::Vector3d x = f.position.row(i);
    if (!x.allFinite()) continue;
    lo = any ? lo.cwiseMin(x) : x;
    hi = any ? hi.cwiseMax(x) : x;
    any = true;
  }
  return Box{lo, hi - lo};
}

// LAMMPS numbers atoms from 1 (a granmem id + 1), up to its 32-bit tagint's largest.
void check_lammps_ids(const std::vector<std::int64_t>& ids, const std::filesystem::path& out) {
  for (std::int64_t id : ids) {
    if (id < 0 || id >= std::int64_t(std::numeric_limits<std::int32_t>::max())) {
      throw Error(out.string() + ": grain id " + std::to_string(id) +
                  " has no LAMMPS atom id (LAMMPS ids are 1 to 2147483647, a granmem id + 1); "
                  "use --format extxyz");
    }
  }
}

// Frame by frame, so that a run larger than memory streams through.
void write_track_table(const TrajectoryReader& run, const std::filesystem::path& out) {
  const RunHeader& h = run.header();
  AtomicFile file(out);
  std::ofstream s(file.temp_path(), std::ios::binary);
  if (!s) throw Error(out.string() + ": cannot open for writing");
  s << csv_header(trajectory_table(h), {"granmem tracks of " + run.file_name() + ", lengths in " +
                                        h.length_unit + ", time in " + h.time_unit});
  for (std::size_t t = 0; t < run.frame_count(); ++t) {
    Table rows = trajectory_table(h);
    append_frame(rows, h, run.read_frame(t));
    write_csv_rows(rows, s);
  }
  s.close();
  if (!s) throw Error(out.string() + ": write failed (disk full?)");
  file.commit();
}

}  // namespace

void write_particle_dump(const TrajectoryReader& run, const std::filesystem::path& out,
                         DumpFormat format) {
  if (format == DumpFormat::csv) return write_track_table(run, out);
  const RunHeader& h = run.header();
  const bool lammps = format == DumpFormat::lammps;
  if (lammps) check_lammps_ids(h.id, out);
  AtomicFile file(out);
  std::ofstream s(file.temp_path(), std::ios::binary);
  if (!s) throw Error(out.string() + ": cannot open for writing");

  std::string names = "id type x y z radius";
  std::string properties = "id:I:1:pos:R:3:radius:R:1";
  if (h.has_axis) {
    names += " ax ay az";
    properties += ":axis:R:3";
  }
  if (h.has_orientation) {
    names += " quatw quati quatj quatk";
    properties += ":orientation:R:4";
  }
  if (h.has_hole_contact) {
    names += " hole_contact";
    properties += ":hole_contact:I:1";
  }

  std::string text;
  for (std::size_t t = 0; t < run.frame_count(); ++t) {
    const Frame f = run.read_frame(t);
    std::size_t seen = 0;
    for (Eigen::Index i = 0; i < f.position.rows(); ++i)
      seen += f.position.row(i).allFinite();
    const Box box = frame_box(h, f);
    const Eigen::Vector3d hi = box.lower + box.edges;
    if (lammps) {
      text += "ITEM: TIMESTEP\n" + std::to_string(f.step) + "\nITEM: NUMBER OF ATOMS\n" +
              std::to_string(seen) + "\nITEM: BOX BOUNDS ff ff ff\n";
      for (int k = 0; k < 3; ++k) {
        number(text, box.lower[k]);
        text += ' ';
        number(text, hi[k]);
        text += '\n';
      }
      text += "ITEM: ATOMS " + names + "\n";
    } else {
      text += std::to_string(seen) + "\nLattice=\"";
      for (int k = 0; k < 3; ++k) {
        for (int j = 0; j < 3; ++j) {
          number(text, j == k ? box.edges[k] : 0.0);
          text += (k == 2 && j == 2) ? "\" Origin=\"" : " ";
        }
      }
      std::string origin;
      for (int k = 0; k < 3; ++k) {
        number(origin, box.lower[k]);
        origin += k == 2 ? "\"" : " ";
      }
      // OVITO 3 reads the cell's corner as Origin, OVITO 2 and QUIP as cell_origin.
      text += origin + " cell_origin=\"" + origin + " Properties=" + properties + " Time=";
      number(text, f.time);
      text += " Step=" + std::to_string(f.step) + " Units=" + h.length_unit + " pbc=\"F F F\"\n";
    }
    for (Eigen::Index i = 0; i < f.position.rows(); ++i) {
      if (!f.position.row(i).allFinite()) continue;
      const std::int64_t id = h.id[std::size_t(i)];
      text += lammps ? std::to_string(id + 1) + " 1" : std::to_string(id);
      auto put = [&](double v) {
        text += ' ';
        number(text, v);
      };
      for (int k = 0; k < 3; ++k)
        put(f.position(i, k));
      put(h.radius[std::size_t(i)]);
      if (h.has_axis) {
        for (int k = 0; k < 3; ++k)
          put(f.axis(i, k));
      }
      if (h.has_orientation) {
        // LAMMPS's columns are named (quatw first); OVITO maps an extended XYZ
        // `orientation` onto its Orientation property, whose components are X, Y, Z, W.
        for (int k : lammps ? std::array<int, 4>{0, 1, 2, 3} : std::array<int, 4>{1, 2, 3, 0})
          put(f.orientation(i, k));
      }
      if (h.has_hole_contact) text += f.hole_contact[std::size_t(i)] ? " 1" : " 0";
      text += '\n';
    }
    s << text;
    text.clear();
  }
  s.close();
  if (!s) throw Error(out.string() + ": write failed (disk full?)");
  file.commit();
}

namespace {

double grain_density(const RunHeader& h, std::optional<double> given,
                     const std::filesystem::path& out) {
  if (given) return *given;
  const auto simulated = h.parameters.find("simulate/density");
  if (simulated == h.parameters.end()) {
    throw Error(out.string() +
                ": the run does not say its grains' density; give it (e.g. 1.18g/cm^3)");
  }
  return parse_si(simulated->second, Dimension::density, "", "simulate/density");
}

}  // namespace

void write_lammps_data(const TrajectoryReader& run, std::optional<std::size_t> frame,
                       std::optional<double> given_density, const std::filesystem::path& out) {
  const RunHeader& h = run.header();
  const double density = grain_density(h, given_density, out);
  const std::size_t frame_index = frame.value_or(run.frame_count() - 1);
  if (!is_physical_length_unit(h.length_unit)) {
    throw Error(out.string() + ": a LAMMPS data file needs lengths; the run is in " +
                h.length_unit + " (import it with --voxel-size)");
  }
  if (!(density > 0) || !std::isfinite(density)) {
    throw Error(out.string() + ": the grains' density must be positive");
  }
  if (run.frame_count() == 0 || frame_index >= run.frame_count()) {
    throw Error(out.string() + ": the run has no frame " + std::to_string(frame_index) + " (" +
                std::to_string(run.frame_count()) + " frames)");
  }
  check_lammps_ids(h.id, out);
  const double m = metres_per(h.length_unit);
  const Frame f = run.read_frame(frame_index);
  Box box = frame_box(h, f);
  if (!h.box) {  // the grains' bounding box, widened so that every grain lies inside it
    double largest = 0;
    for (double r : h.radius)
      if (std::isfinite(r)) largest = std::max(largest, r);
    box.lower.array() -= largest;
    box.edges.array() += 2 * largest;
  }
  std::string atoms;
  std::size_t count = 0;
  for (Eigen::Index i = 0; i < f.position.rows(); ++i) {
    if (!f.position.row(i).allFinite()) continue;
    const double r = h.radius[std::size_t(i)];
    if (!(r > 0) || !std::isfinite(r)) {
      throw Error(out.string() + ": grain " + std::to_string(h.id[std::size_t(i)]) +
                  " has no radius; a data file needs every grain's diameter");
    }
    atoms += std::to_string(h.id[std::size_t(i)] + 1) + " 1";
    for (double v :
         {2 * r * m, density, f.position(i, 0) * m, f.position(i, 1) * m, f.position(i, 2) * m}) {
      atoms += ' ';
      number(atoms, v);
    }
    atoms += '\n';
    ++count;
  }
  std::string text = "LAMMPS data file (units si, atom_style sphere) from granmem: frame " +
                     std::to_string(frame_index) + " (step " + std::to_string(f.step) + ") of " +
                     run.file_name() + "\n\n" + std::to_string(count) + " atoms\n1 atom types\n\n";
  const char* axes[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    number(text, box.lower[k] * m);
    text += ' ';
    number(text, (box.lower[k] + box.edges[k]) * m);
    text += std::string(" ") + axes[k] + "lo " + axes[k] + "hi\n";
  }
  text += "\nAtoms # sphere\n\n" + atoms;
  AtomicFile file(out);
  std::ofstream s(file.temp_path(), std::ios::binary);
  if (!s) throw Error(out.string() + ": cannot open for writing");
  s << text;
  s.close();
  if (!s) throw Error(out.string() + ": write failed (disk full?)");
  file.commit();
}

}  // namespace granmem
