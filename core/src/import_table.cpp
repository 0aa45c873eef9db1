#include "granmem/core/import_table.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "granmem/core/apparatus_readings.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/lammps_dump.hpp"
#include "granmem/core/memory_budget.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/units.hpp"

namespace granmem {

void ImportOptions::validate() const {
  if (!is_length_unit(length_unit)) {
    throw Error("--length-unit '" + length_unit + "': expected one of m, cm, mm, um, voxel");
  }
  if (voxel_size) {
    if (length_unit != "voxel") {
      throw Error("--voxel-size applies to voxel coordinates, but --length-unit is " + length_unit);
    }
    if (!is_physical_length_unit(voxel_size_unit)) {
      throw Error("--voxel-size needs a length unit (m, cm, mm or um), e.g. 0.05,0.05,0.075mm");
    }
    if (!(voxel_size->array() > 0).all() || !voxel_size->allFinite()) {
      throw Error("--voxel-size: expected three positive sizes");
    }
  }
  if (radius && !(*radius > 0 && std::isfinite(*radius))) {
    throw Error("--radius: expected a positive radius");
  }
  if (!readings.empty()) read_apparatus_readings(readings);
}

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
  // positions, axes, standard errors (3 + 1), rows, flags
  const double bytes = slots * (3 + 3 + 4 + 2) * sizeof(double);
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
  Scaling s{Eigen::Vector3d::Ones(), options.length_unit};
  if (options.voxel_size) {
    s.scale = *options.voxel_size;
    s.unit = options.voxel_size_unit;
  }
  return s;
}

const std::vector<std::string> kRequiredColumns{"frame", "particle", "x", "y", "z"};
const std::vector<std::string> kOptionalColumns{"ax",   "ay",   "az",   "radius",    "hole_contact",
                                                "qw",   "qx",   "qy",   "qz",        "ep",
                                                "ep_x", "ep_y", "ep_z", "axis_error"};
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

// The optional columns the table has, checked: an axis or an orientation whole, a radius
// from the table or from the options, not both.
struct Layout {
  bool axis = false, orientation = false, hole_contact = false, radius = false;
  // A scan's standard errors: per axis (ep_x, ep_y, ep_z) or trackpy's one `ep` for all
  // three; the axis' (rad).
  std::vector<std::string> position_error;
  bool axis_error = false;
};

Layout layout_of(const Table& t, const Source& csv, const ImportOptions& options) {
  if (t.rows() == 0) {
    throw Error(csv.name +
                (std::string(csv.row_word) == "line" ? ": no rows after the header" : ": no rows"));
  }
  Layout l;
  l.axis = t.has("ax") || t.has("ay") || t.has("az");
  if (l.axis && !(t.has("ax") && t.has("ay") && t.has("az"))) {
    throw Error(csv.name + ": an axis needs all three columns ax, ay, az");
  }
  l.orientation = t.has("qw") || t.has("qx") || t.has("qy") || t.has("qz");
  if (l.orientation && !(t.has("qw") && t.has("qx") && t.has("qy") && t.has("qz"))) {
    throw Error(csv.name + ": an orientation needs all four columns qw, qx, qy, qz");
  }
  l.radius = t.has("radius");
  if (l.radius && options.radius) {
    throw Error(csv.name + ": has a radius column; --radius is for tables without one");
  }
  l.hole_contact = t.has("hole_contact");
  const bool per_axis = t.has("ep_x") || t.has("ep_y") || t.has("ep_z");
  if (per_axis && !(t.has("ep_x") && t.has("ep_y") && t.has("ep_z"))) {
    throw Error(csv.name + ": a position error per axis needs all three columns ep_x, ep_y, ep_z");
  }
  if (per_axis && t.has("ep")) {
    throw Error(csv.name + ": give the position error as ep or as ep_x, ep_y, ep_z, not both");
  }
  if (per_axis) l.position_error = {"ep_x", "ep_y", "ep_z"};
  if (t.has("ep")) l.position_error = {"ep", "ep", "ep"};
  l.axis_error = t.has("axis_error");
  return l;
}

// Each row's frame and particle labels, and the labels sorted: the run's frames and grains.
struct Labels {
  std::vector<std::int64_t> frame_of, particle_of;  // per row
  std::vector<std::int64_t> frames, particles;      // sorted, each once
};

Labels labels_of(const Table& t, const std::vector<std::size_t>& lines, const Source& csv) {
  Labels l;
  l.frame_of.resize(t.rows());
  l.particle_of.resize(t.rows());
  for (std::size_t r = 0; r < t.rows(); ++r) {
    l.frame_of[r] = label(t["frame"].values[r], csv, lines[r], "frame");
    l.particle_of[r] = label(t["particle"].values[r], csv, lines[r], "particle");
  }
  l.frames = sorted_unique(l.frame_of);
  l.particles = sorted_unique(l.particle_of);
  return l;
}

// The run before its rows are read: its header and a frame per label, every grain unknown.
Trajectories empty_run(const Labels& labels, const Layout& layout, const Scaling& scaling,
                       const Source& csv, const ImportOptions& options) {
  const Eigen::Vector3d& scale = scaling.scale;
  Trajectories run;
  RunHeader& h = run.header;
  h.length_unit = scaling.unit;
  h.time_unit = "cycle";  // a table of scans knows their order, not their times
  h.sample = options.sample;
  h.id = labels.particles;
  h.has_axis = layout.axis;
  h.has_hole_contact = layout.hole_contact;
  h.has_orientation = layout.orientation;
  h.has_position_error = !layout.position_error.empty();
  h.has_axis_error = layout.axis_error;
  if (layout.orientation && options.voxel_size && (scale.array() != scale.x()).any()) {
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
  for (std::int64_t f : labels.frames) {
    Frame frame = Frame::unknown(h);
    frame.step = f;
    frame.time = static_cast<double>(f);
    run.frames.push_back(std::move(frame));
  }
  return run;
}

// The rows read into the run's frames one by one: each (frame, grain) once, positions and
// axes scaled to the stored unit, the radii each grain's rows give summed for their mean.
class RowReader {
 public:
  RowReader(const Table& t, const Source& csv, const Labels& labels, const Layout& layout,
            const Eigen::Vector3d& scale, Trajectories& run)
      : t_(t),
        csv_(csv),
        labels_(labels),
        layout_(layout),
        scale_(scale),
        run_(run),
        n_(labels.particles.size()),
        radius_sum_(n_, 0),
        radius_count_(n_, 0),
        seen_at_(labels.frames.size() * n_, 0) {}

  // Row r, line `line` of the source.
  void read(std::size_t r, std::size_t line) {
    const std::size_t ti = index_of(labels_.frames, labels_.frame_of[r]);
    const std::size_t gi = index_of(labels_.particles, labels_.particle_of[r]);
    claim(r, line, seen_at_[ti * n_ + gi]);
    Frame& frame = run_.frames[ti];
    const auto row = static_cast<Eigen::Index>(gi);
    frame.position.row(row) = position(r, line);
    if (layout_.axis) read_axis(r, line, frame, row);
    if (layout_.orientation) read_orientation(t_, r, at(csv_, line), frame, row);
    if (layout_.hole_contact) frame.hole_contact[gi] = hole_contact(r, line);
    for (std::size_t a = 0; a < layout_.position_error.size(); ++a) {
      frame.position_error(row, Eigen::Index(a)) =
          standard_error(layout_.position_error[a], r, line) * scale_[Eigen::Index(a)];
    }
    if (layout_.axis_error) frame.axis_error[gi] = standard_error("axis_error", r, line);
    if (layout_.radius) add_radius(r, line, gi);
  }

  // A grain's radius is a property of the grain: the mean of what the scans measured, else
  // `radius` (the table's unit); NaN where neither is known.
  std::vector<double> radii(const std::optional<double>& radius) const {
    std::vector<double> r(n_, std::numeric_limits<double>::quiet_NaN());
    for (std::size_t g = 0; g < n_; ++g) {
      if (radius_count_[g])
        r[g] = radius_sum_[g] / double(radius_count_[g]) * scale_.x();
      else if (radius)
        r[g] = *radius * scale_.x();
    }
    return r;
  }

  std::size_t axes_known() const { return axes_known_; }

 private:
  // The (frame, grain) of row r is taken by its line; `first` is the line of an earlier
  // row there (0: none).
  void claim(std::size_t r, std::size_t line, std::size_t& first) const {
    if (first) {
      throw Error(at(csv_, line) + ": particle " + std::to_string(labels_.particle_of[r]) +
                  " appears twice in frame " + std::to_string(labels_.frame_of[r]) +
                  " (first at line " + std::to_string(first) + ")");
    }
    first = line;
  }

  Eigen::Vector3d position(std::size_t r, std::size_t line) const {
    const Eigen::Vector3d x(t_["x"].values[r], t_["y"].values[r], t_["z"].values[r]);
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(x[k])) {
        throw Error(at(csv_, line) + ", column '" + "xyz"[k] +
                    "': expected a finite coordinate, found " +
                    (std::isnan(x[k]) ? "nothing or nan" : "infinity"));
      }
    }
    const Eigen::Vector3d scaled = x.cwiseProduct(scale_);
    if (!scaled.allFinite()) {
      throw Error(at(csv_, line) +
                  ": position (x,y,z) times the voxel size is beyond a double's range");
    }
    return scaled;
  }

  void read_axis(std::size_t r, std::size_t line, Frame& frame, Eigen::Index row) {
    const Eigen::Vector3d a(t_["ax"].values[r], t_["ay"].values[r], t_["az"].values[r]);
    const int unknown = a.array().isNaN().count();
    if (unknown == 3) return;  // the axis was not seen in this scan: NaN kept
    if (unknown > 0 || !a.allFinite()) {
      throw Error(at(csv_, line) + ": axis (ax,ay,az) must be three finite numbers or all empty");
    }
    // A direction in voxel space becomes a physical direction by the same scaling.
    const Eigen::Vector3d p = a.cwiseProduct(scale_);
    // Any length: the stable norm neither overflows (1e200) nor underflows (1e-200).
    if (p.stableNorm() == 0) throw Error(at(csv_, line) + ": axis (ax,ay,az) has zero length");
    frame.axis.row(row) = p.stableNormalized();
    ++axes_known_;
  }

  std::uint8_t hole_contact(std::size_t r, std::size_t line) const {
    const double flag = t_["hole_contact"].values[r];
    if (flag != 0 && flag != 1) {
      throw Error(at(csv_, line) + ", column 'hole_contact': expected 0 or 1");
    }
    return static_cast<std::uint8_t>(flag);
  }

  // A standard error: empty or nan where unknown, else a finite number >= 0.
  double standard_error(const std::string& column, std::size_t r, std::size_t line) const {
    const double e = t_[column].values[r];
    if (!std::isnan(e) && !(e >= 0 && std::isfinite(e))) {
      throw Error(at(csv_, line) + ", column '" + column +
                  "': expected a standard error (a finite number >= 0) or nothing");
    }
    return e;
  }

  void add_radius(std::size_t r, std::size_t line, std::size_t grain) {
    const double rad = t_["radius"].values[r];
    if (std::isnan(rad)) return;
    if (!(rad > 0) || !std::isfinite(rad)) {
      throw Error(at(csv_, line) + ", column 'radius': expected a positive radius");
    }
    radius_sum_[grain] += rad;
    ++radius_count_[grain];
  }

  const Table& t_;
  const Source& csv_;
  const Labels& labels_;
  const Layout& layout_;
  const Eigen::Vector3d scale_;
  Trajectories& run_;
  const std::size_t n_;
  std::vector<double> radius_sum_;
  std::vector<std::size_t> radius_count_;
  std::vector<std::size_t> seen_at_;  // line of the row of each (frame, grain), 0 = none
  std::size_t axes_known_ = 0;
};

Trajectories import_rows(const Table& t, const std::vector<std::size_t>& lines, const Source& csv,
                         const ImportOptions& options, ImportSummary* summary) {
  const Scaling scaling = scaling_of(options);
  const Layout layout = layout_of(t, csv, options);
  const Labels labels = labels_of(t, lines, csv);
  const std::size_t rows = t.rows(), frames = labels.frames.size(), n = labels.particles.size();
  check_dense_size(csv, rows, frames, n);
  Trajectories run = empty_run(labels, layout, scaling, csv, options);
  RowReader reader(t, csv, labels, layout, scaling.scale, run);
  for (std::size_t r = 0; r < rows; ++r)
    reader.read(r, lines[r]);
  run.header.radius = reader.radii(options.radius);

  if (summary) {
    summary->source = csv.name;
    summary->has_axis = layout.axis;
    summary->rows = rows;
    summary->frames = frames;
    summary->grains = n;
    summary->missing = frames * n - rows;
    summary->axes_known = reader.axes_known();
    summary->length_unit = scaling.unit;
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
  o.validate();  // the dump's unit may not be voxels, as a voxel size needs
  Trajectories run = import_rows(dump.table, dump.lines, Source{path.string(), "line"}, o, summary);
  if (summary) {
    summary->format = "lammps dump";
    summary->notes = notes;
  }
  return run;
}

// The run with the apparatus' readings of options.readings, said in the summary's notes.
Trajectories with_readings(Trajectories run, const ImportOptions& options, ImportSummary* summary) {
  if (options.readings.empty()) return run;
  const std::string said = attach_apparatus_readings(run, options.readings);
  if (summary) summary->notes.push_back(said);
  return run;
}

}  // namespace

Trajectories import_table(const std::filesystem::path& csv, const ImportOptions& options,
                          ImportSummary* summary) {
  options.validate();  // before the file is read
  if (is_lammps_dump(csv))
    return with_readings(import_dump(csv, options, summary), options, summary);
  const CsvColumns read = read_csv(csv, kRequiredColumns, kOptionalColumns, options.csv);
  Trajectories run =
      import_rows(read.table, read.lines, Source{csv.string(), "line"}, options, summary);
  if (summary) summary->format = "csv";
  return with_readings(std::move(run), options, summary);
}

Trajectories import_table(const Table& table, const std::string& source,
                          const ImportOptions& options, ImportSummary* summary) {
  options.validate();
  for (const std::string& c : kRequiredColumns) {
    if (!table.has(c)) throw Error(source + ": no column '" + c + "'");
  }
  std::vector<std::size_t> rows(table.rows());
  std::iota(rows.begin(), rows.end(), std::size_t{1});
  return with_readings(import_rows(table, rows, Source{source, "row"}, options, summary), options,
                       summary);
}

}  // namespace granmem
