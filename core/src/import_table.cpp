#include "granmem/core/import_table.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "granmem/core/error.hpp"
#include "granmem/core/lammps_dump.hpp"
#include "granmem/core/memory_budget.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

// Where the rows come from, for messages: a CSV file's lines, or an in-memory table's rows.
struct Source {
  std::string name;
  const char* row_word = "line";
};

std::string at(const Source& source, std::size_t line) {
  return source.name + " " + source.row_word + " " + std::to_string(line);
}

// An integer label (frame or particle) stored in a double column.
std::int64_t label(double v, const Source& csv, std::size_t line, const char* column) {
  if (!std::isfinite(v) || v != std::floor(v) || std::abs(v) > 9e15) {
    throw Error(at(csv, line) + ", column '" + column + "': expected an integer label, found " +
                (std::isnan(v) ? std::string("nothing") : std::to_string(v)));
  }
  return static_cast<std::int64_t>(v);
}

std::vector<std::int64_t> sorted_unique(std::vector<std::int64_t> v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

std::size_t index_of(const std::vector<std::int64_t>& sorted, std::int64_t value) {
  return static_cast<std::size_t>(std::lower_bound(sorted.begin(), sorted.end(), value) -
                                  sorted.begin());
}

// The store is a dense frames x particles array. A table whose labels barely repeat (a
// 'particle' that is a row number, or a track id that changes every frame) would make a
// store thousands of times its size: refused before anything is allocated, as is a store
// beyond half of this machine's memory.
void check_dense_size(const Source& csv, std::size_t rows, std::size_t frames,
                      std::size_t particles) {
  const double slots = double(frames) * double(particles);
  const double bytes = slots * (3 + 3 + 2) * sizeof(double);  // positions, axes, rows, flags
  const double filled = double(rows) / slots;
  const std::string shape = std::to_string(rows) + " rows label " + std::to_string(frames) +
                            " frames x " + std::to_string(particles) + " particles";
  if (slots > 1e6 && filled < 0.01) {
    std::ostringstream fill;
    fill.precision(2);
    fill << 100 * filled;
    throw Error(csv.name + ": " + shape + ", of which " + fill.str() +
                " % are in the table: is 'particle' a track id that is the same grain in every "
                "frame? (the store holds every frame of every particle, " +
                gibibytes(bytes) + ")");
  }
  check_memory_budget(bytes, csv.name + ": " + shape + ": the store");
}

// The stored length unit and the scale from the table's unit to it, per axis, from the
// options (checked).
struct Scaling {
  Eigen::Vector3d scale = Eigen::Vector3d::Ones();
  std::string unit;
};

Scaling scaling_of(const ImportOptions& options) {
  const std::string& unit = options.length_unit;
  if (!is_length_unit(unit)) {
    throw Error("--length-unit '" + unit + "': expected one of m, cm, mm, um, voxel");
  }
  Scaling s{Eigen::Vector3d::Ones(), unit};
  if (options.voxel_size) {
    if (unit != "voxel") {
      throw Error("--voxel-size applies to voxel coordinates, but --length-unit is " + unit);
    }
    if (!is_physical_length_unit(options.voxel_size_unit)) {
      throw Error("--voxel-size needs a length unit (m, cm, mm or um), e.g. 0.05,0.05,0.075mm");
    }
    if (!(options.voxel_size->array() > 0).all() || !options.voxel_size->allFinite()) {
      throw Error("--voxel-size: expected three positive sizes");
    }
    s.scale = *options.voxel_size;
    s.unit = options.voxel_size_unit;
  }
  if (options.radius && !(*options.radius > 0 && std::isfinite(*options.radius))) {
    throw Error("--radius: expected a positive radius");
  }
  return s;
}

const std::vector<std::string> kRequiredColumns{"frame", "particle", "x", "y", "z"};
const std::vector<std::string> kOptionalColumns{"ax", "ay", "az", "radius", "hole_contact",
                                                "qw", "qx", "qy", "qz"};
const std::vector<std::string> kOrientation{"qw", "qx", "qy", "qz"};

// A row's orientation (qw, qx, qy, qz; scalar first, as LAMMPS and trajectory_table write
// it): all empty where it is unknown, else a unit quaternion to the precision a table
// keeps, stored normalised.
void read_orientation(const Table& t, std::size_t r, const std::string& where, Frame& frame,
                      Eigen::Index row) {
  Eigen::Vector4d q;
  for (int k = 0; k < 4; ++k)
    q[k] = t[kOrientation[std::size_t(k)]].values[r];
  const int unknown = int(q.array().isNaN().count());
  if (unknown == 4) return;
  if (unknown > 0 || !q.allFinite() || std::abs(q.norm() - 1) > 1e-3) {
    throw Error(where + ": orientation (qw,qx,qy,qz) must be a unit quaternion or all empty");
  }
  frame.orientation.row(row) = q.normalized().transpose();
}

Trajectories import_rows(const Table& t, const std::vector<std::size_t>& lines, const Source& csv,
                         const ImportOptions& options, ImportSummary* summary) {
  const Scaling scaling = scaling_of(options);
  const Eigen::Vector3d& scale = scaling.scale;
  const std::string& stored_unit = scaling.unit;
  const std::size_t rows = t.rows();
  if (rows == 0) {
    throw Error(csv.name +
                (std::string(csv.row_word) == "line" ? ": no rows after the header" : ": no rows"));
  }
  const bool has_axis = t.has("ax") || t.has("ay") || t.has("az");
  if (has_axis && !(t.has("ax") && t.has("ay") && t.has("az"))) {
    throw Error(csv.name + ": an axis needs all three columns ax, ay, az");
  }
  const bool has_orientation = t.has("qw") || t.has("qx") || t.has("qy") || t.has("qz");
  if (has_orientation && !(t.has("qw") && t.has("qx") && t.has("qy") && t.has("qz"))) {
    throw Error(csv.name + ": an orientation needs all four columns qw, qx, qy, qz");
  }
  if (t.has("radius") && options.radius) {
    throw Error(csv.name + ": has a radius column; --radius is for tables without one");
  }

  std::vector<std::int64_t> frame_of(rows), particle_of(rows);
  for (std::size_t r = 0; r < rows; ++r) {
    frame_of[r] = label(t["frame"].values[r], csv, lines[r], "frame");
    particle_of[r] = label(t["particle"].values[r], csv, lines[r], "particle");
  }
  const std::vector<std::int64_t> frames = sorted_unique(frame_of);
  const std::vector<std::int64_t> particles = sorted_unique(particle_of);
  const std::size_t n = particles.size();
  check_dense_size(csv, rows, frames.size(), n);

  Trajectories run;
  RunHeader& h = run.header;
  h.length_unit = stored_unit;
  h.time_unit = "cycle";  // a table of scans knows their order, not their times
  h.sample = options.sample;
  h.id = particles;
  h.has_axis = has_axis;
  h.has_hole_contact = t.has("hole_contact");
  h.has_orientation = has_orientation;
  if (has_orientation && options.voxel_size && (scale.array() != scale.x()).any()) {
    throw Error(csv.name +
                ": orientations with voxels of unequal sides would need turning; "
                "give the table in lengths");
  }
  if (options.voxel_size) h.voxel_size = *options.voxel_size;
  if (options.box) {
    Box b = *options.box;
    b.lower = b.lower.cwiseProduct(scale);
    b.edges = b.edges.cwiseProduct(scale);
    h.box = b;
  }
  for (std::int64_t f : frames) {
    Frame frame = Frame::unknown(h);
    frame.step = f;
    frame.time = static_cast<double>(f);
    run.frames.push_back(std::move(frame));
  }

  std::vector<double> radius_sum(n, 0);
  std::vector<std::size_t> radius_count(n, 0);
  std::vector<std::size_t> seen_at(frames.size() * n, 0);  // line of the row, 0 = none
  std::size_t axes_known = 0;
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t line = lines[r];
    const std::size_t ti = index_of(frames, frame_of[r]);
    const std::size_t gi = index_of(particles, particle_of[r]);
    std::size_t& first = seen_at[ti * n + gi];
    if (first) {
      throw Error(at(csv, line) + ": particle " + std::to_string(particle_of[r]) +
                  " appears twice in frame " + std::to_string(frame_of[r]) + " (first at line " +
                  std::to_string(first) + ")");
    }
    first = line;
    Frame& frame = run.frames[ti];
    const auto row = static_cast<Eigen::Index>(gi);
    const Eigen::Vector3d x(t["x"].values[r], t["y"].values[r], t["z"].values[r]);
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(x[k])) {
        throw Error(at(csv, line) + ", column '" + "xyz"[k] +
                    "': expected a finite coordinate, found " +
                    (std::isnan(x[k]) ? "nothing or nan" : "infinity"));
      }
    }
    const Eigen::Vector3d scaled = x.cwiseProduct(scale);
    if (!scaled.allFinite()) {
      throw Error(at(csv, line) +
                  ": position (x,y,z) times the voxel size is beyond a double's range");
    }
    frame.position.row(row) = scaled;
    if (has_axis) {
      const Eigen::Vector3d a(t["ax"].values[r], t["ay"].values[r], t["az"].values[r]);
      const int unknown = a.array().isNaN().count();
      if (unknown == 3) {
        // The axis was not seen in this scan: keep NaN.
      } else if (unknown > 0 || !a.allFinite()) {
        throw Error(at(csv, line) + ": axis (ax,ay,az) must be three finite numbers or all empty");
      } else {
        // A direction in voxel space becomes a physical direction by the same scaling.
        const Eigen::Vector3d p = a.cwiseProduct(scale);
        // Any length: the stable norm neither overflows (1e200) nor underflows (1e-200).
        if (p.stableNorm() == 0) throw Error(at(csv, line) + ": axis (ax,ay,az) has zero length");
        frame.axis.row(row) = p.stableNormalized();
        ++axes_known;
      }
    }
    if (has_orientation) read_orientation(t, r, at(csv, line), frame, row);
    if (h.has_hole_contact) {
      const double flag = t["hole_contact"].values[r];
      if (flag != 0 && flag != 1) {
        throw Error(at(csv, line) + ", column 'hole_contact': expected 0 or 1");
      }
      frame.hole_contact[gi] = static_cast<std::uint8_t>(flag);
    }
    if (t.has("radius")) {
      const double rad = t["radius"].values[r];
      if (!std::isnan(rad)) {
        if (!(rad > 0) || !std::isfinite(rad)) {
          throw Error(at(csv, line) + ", column 'radius': expected a positive radius");
        }
        radius_sum[gi] += rad;
        ++radius_count[gi];
      }
    }
  }

  // A grain's radius is a property of the grain: average what the scans measured.
  h.radius.assign(n, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t g = 0; g < n; ++g) {
    if (radius_count[g])
      h.radius[g] = radius_sum[g] / double(radius_count[g]) * scale.x();
    else if (options.radius)
      h.radius[g] = *options.radius * scale.x();
  }

  if (summary) {
    summary->source = csv.name;
    summary->has_axis = has_axis;
    summary->rows = rows;
    summary->frames = frames.size();
    summary->grains = n;
    summary->missing = frames.size() * n - rows;
    summary->axes_known = axes_known;
    summary->length_unit = stored_unit;
  }
  return run;
}

}  // namespace

std::string ImportSummary::Report() const {
  std::string s = "imported " + std::to_string(rows) + " rows of " + source + " (" + format +
                  "): " + std::to_string(frames) + " frames, " + std::to_string(grains) +
                  " grains, " + std::to_string(missing) + " missing (grain, frame) entries";
  if (has_axis) s += ", cavity axis in " + std::to_string(axes_known) + " rows";
  s += "\n";
  for (const std::string& note : notes)
    s += note + "\n";
  return s + "lengths in " + length_unit + "\n";
}

namespace {

bool is_lammps_dump(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    const std::string_view t = trim(line);
    if (!t.empty()) return t.rfind("ITEM:", 0) == 0;
  }
  return false;
}

// The dump's options: its unit and its box where the caller gave none.
ImportOptions dump_options(const LammpsDump& dump, const std::string& where,
                           const ImportOptions& given, std::vector<std::string>& notes) {
  ImportOptions o = given;
  const std::string unit = lammps_length_unit(dump.units);
  if (!dump.units.empty() && unit.empty()) {
    throw Error(where + ": LAMMPS units '" + dump.units +
                "' have no length granmem stores (si, cgs and micro do)");
  }
  if (!unit.empty() && given.length_unit != "voxel" && given.length_unit != unit) {
    throw Error(where + ": the dump's units are " + dump.units + " (" + unit +
                "), not --length-unit " + given.length_unit);
  }
  if (!unit.empty()) {
    o.length_unit = unit;
    notes.push_back("lengths in " + unit + ", from the dump's units (" + dump.units + ")");
  } else if (given.length_unit == "voxel") {
    throw Error(where +
                ": a LAMMPS dump without ITEM: UNITS: give its length unit "
                "(--length-unit; m for units si, cm for cgs)");
  }
  if (!o.box && dump.box) {
    o.box = dump.box;
    notes.push_back(dump.box_changes ? "box: the first snapshot's bounds (later ones differ)"
                                     : "box: the dump's bounds");
  }
  return o;
}

Trajectories import_dump(const std::filesystem::path& path, const ImportOptions& options,
                         ImportSummary* summary) {
  const LammpsDump dump = read_lammps_dump(path, options.types);
  std::vector<std::string> notes;
  const ImportOptions o = dump_options(dump, path.string(), options, notes);
  Trajectories run = import_rows(dump.table, dump.lines, Source{path.string(), "line"}, o, summary);
  if (summary) {
    summary->format = "lammps dump";
    summary->notes = notes;
  }
  return run;
}

}  // namespace

Trajectories import_table(const std::filesystem::path& csv, const ImportOptions& options,
                          ImportSummary* summary) {
  if (is_lammps_dump(csv)) return import_dump(csv, options, summary);
  scaling_of(options);  // bad options refused before the file is read
  const CsvColumns read = read_csv(csv, kRequiredColumns, kOptionalColumns, options.csv);
  Trajectories run =
      import_rows(read.table, read.lines, Source{csv.string(), "line"}, options, summary);
  if (summary) summary->format = "csv";
  return run;
}

Trajectories import_table(const Table& table, const std::string& source,
                          const ImportOptions& options, ImportSummary* summary) {
  for (const std::string& c : kRequiredColumns) {
    if (!table.has(c)) throw Error(source + ": no column '" + c + "'");
  }
  std::vector<std::size_t> rows(table.rows());
  std::iota(rows.begin(), rows.end(), std::size_t{1});
  return import_rows(table, rows, Source{source, "row"}, options, summary);
}

}  // namespace granmem
