#include "granmem/tracking/detections.hpp"

#include <cmath>
#include <fstream>
#include <limits>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/hdf5.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
const char* const kAxisColumns[] = {"ax", "ay", "az", "axis_quality", "hole_contact"};
const char* const kPositionErrorColumns[] = {"ep_x", "ep_y", "ep_z"};

// A column's values, or none where the table has no such column.
const std::vector<double>* values_of(const Table& t, const char* column) {
  return t.has(column) ? &t[column].values : nullptr;
}

}  // namespace

void Detections::add(const Eigen::Vector3d& x, double r, double q, bool on_edge) {
  const Eigen::Index n = position.rows();
  position.conservativeResize(n + 1, 3);
  position.row(n) = x.transpose();
  radius.push_back(r);
  quality.push_back(q);
  edge.push_back(on_edge ? 1 : 0);
  position_error.conservativeResize(n + 1, 3);
  position_error.row(n).setConstant(kNaN);
  if (has_axis) {
    axis.conservativeResize(n + 1, 3);
    axis.row(n).setConstant(kNaN);
    axis_quality.push_back(kNaN);
    axis_error.push_back(kNaN);
    hole_contact.push_back(0);
  }
}

Table to_table(const Detections& d) {
  Table t;
  const std::string& L = d.length_unit == "voxel" ? std::string("voxel") : d.length_unit;
  Column& frame = t.add("frame", "", true);
  Column& particle = t.add("particle", "", true);
  Column& x = t.add("x", L);
  Column& y = t.add("y", L);
  Column& z = t.add("z", L);
  Column& radius = t.add("radius", L);
  Column& quality = t.add("quality");
  Column& edge = t.add("edge", "", true);
  for (std::size_t i = 0; i < d.size(); ++i) {
    const auto r = Eigen::Index(i);
    frame.values.push_back(double(d.frame));
    particle.values.push_back(double(i));
    x.values.push_back(d.position(r, 0));
    y.values.push_back(d.position(r, 1));
    z.values.push_back(d.position(r, 2));
    radius.values.push_back(d.radius[i]);
    quality.values.push_back(d.quality[i]);
    edge.values.push_back(d.edge[i]);
  }
  for (int a = 0; a < 3; ++a) {
    Column& ep = t.add(kPositionErrorColumns[a], L);
    for (std::size_t i = 0; i < d.size(); ++i)
      ep.values.push_back(d.position_error(Eigen::Index(i), a));
  }
  if (d.has_axis) {
    Column& ax = t.add("ax");
    Column& ay = t.add("ay");
    Column& az = t.add("az");
    Column& aq = t.add("axis_quality");
    Column& ae = t.add("axis_error", "rad");
    Column& hole = t.add("hole_contact", "", true);
    for (std::size_t i = 0; i < d.size(); ++i) {
      const auto r = Eigen::Index(i);
      ax.values.push_back(d.axis(r, 0));
      ay.values.push_back(d.axis(r, 1));
      az.values.push_back(d.axis(r, 2));
      aq.values.push_back(d.axis_quality[i]);
      ae.values.push_back(d.axis_error[i]);
      hole.values.push_back(d.hole_contact[i]);
    }
  }
  return t;
}

Detections from_table(const Table& t, const std::string& where) {
  for (const char* c : {"x", "y", "z", "radius", "quality", "edge"}) {
    if (!t.has(c)) throw Error(where + ": detections lack the column '" + c + "'");
  }
  Detections d;
  d.length_unit = t["x"].unit.empty() ? "voxel" : t["x"].unit;
  if (t.has("frame") && t.rows() > 0) d.frame = std::int64_t(t["frame"].values[0]);
  d.has_axis = t.has("ax");
  if (d.has_axis) {
    for (const char* c : kAxisColumns) {
      if (!t.has(c)) throw Error(where + ": detections with an axis lack the column '" + c + "'");
    }
  }
  // The standard errors where the table has them: trackpy's one `ep` stands for all three
  // where it has no ep_x, ep_y, ep_z.
  const std::vector<double>* ep[3];
  for (int a = 0; a < 3; ++a) {
    ep[a] = values_of(t, kPositionErrorColumns[a]);
    if (!ep[a]) ep[a] = values_of(t, "ep");
  }
  const std::vector<double>* axis_error = values_of(t, "axis_error");
  for (std::size_t i = 0; i < t.rows(); ++i) {
    d.add({t["x"].values[i], t["y"].values[i], t["z"].values[i]}, t["radius"].values[i],
          t["quality"].values[i], t["edge"].values[i] != 0);
    const auto r = Eigen::Index(i);
    for (int a = 0; a < 3; ++a)
      d.position_error(r, a) = ep[a] ? (*ep[a])[i] : kNaN;
    if (d.has_axis) {
      d.axis.row(r) << t["ax"].values[i], t["ay"].values[i], t["az"].values[i];
      d.axis_quality[i] = t["axis_quality"].values[i];
      d.axis_error[i] = axis_error ? (*axis_error)[i] : kNaN;
      d.hole_contact[i] = t["hole_contact"].values[i] != 0;
    }
  }
  return d;
}

void write_detections(const Detections& d, const std::filesystem::path& path) {
  const Table t = to_table(d);
  AtomicFile out(path);
  if (path.extension() == ".csv") {
    std::vector<std::string> comment{"granmem detections of " + d.source + ", frame " +
                                     std::to_string(d.frame) + ", lengths in " + d.length_unit};
    if (d.voxel_size) {
      comment.push_back("voxel size " + std::to_string((*d.voxel_size)[0]) + "," +
                        std::to_string((*d.voxel_size)[1]) + "," +
                        std::to_string((*d.voxel_size)[2]) + " " + d.length_unit);
    }
    write_csv(t, out, comment);
  } else {
    h5::File f = h5::File::create(out);
    h5::write_table(f.id(), "/detections", t);
    h5::Handle g = h5::open_group(f, "/detections");
    h5::write_attribute(g.get(), "length_unit", d.length_unit);
    h5::write_attribute(g.get(), "source", d.source);
    h5::write_attribute(g.get(), "frame", std::to_string(d.frame));
    if (d.voxel_size) h5::write(g.get(), "voxel_size", d.voxel_size->data(), {3}, d.length_unit);
    f.close();
  }
  out.commit();
}

Detections read_detections(const std::filesystem::path& path) {
  const std::string where = path.string();
  if (path.extension() == ".csv") {
    const CsvColumns c =
        read_csv(path, {"frame", "particle", "x", "y", "z", "radius", "quality", "edge"},
                 {"ep", "ep_x", "ep_y", "ep_z", "ax", "ay", "az", "axis_quality", "axis_error",
                  "hole_contact"});
    Detections d = from_table(c.table, where);
    d.source = where;
    // The unit is named in the header comment that write_detections() puts first.
    std::ifstream in(path);
    for (std::string line; std::getline(in, line) && !line.empty() && line[0] == '#';) {
      const std::size_t at = line.find("lengths in ");
      if (at != std::string::npos) {
        std::string unit = line.substr(at + 11);
        unit = unit.substr(0, unit.find_first_of(" ,;"));
        if (is_length_unit(unit)) d.length_unit = unit;
      }
    }
    return d;
  }
  const h5::File f = h5::File::open(path);
  if (!h5::exists(f.id(), "/detections")) {
    throw Error(where + ": not a granmem detections file (no /detections group)");
  }
  Table t = h5::read_table(f, "/detections");
  // The columns' own unit attribute (voxel or a length) is the length unit.
  Detections d = from_table(t, where);
  h5::Handle g = h5::open_group(f, "/detections");
  d.length_unit = h5::read_string_attribute(g.get(), "length_unit").value_or(d.length_unit);
  d.source = h5::read_string_attribute(g.get(), "source").value_or(where);
  const std::string frame = h5::read_string_attribute(g.get(), "frame").value_or("0");
  try {
    d.frame = std::stoll(frame);
  } catch (const std::exception&) {
    throw Error(where + ": /detections frame attribute '" + frame + "' is not a number");
  }
  if (h5::exists(f.id(), "/detections/voxel_size")) {
    const std::vector<double> v = h5::read<double>(f, "/detections/voxel_size");
    if (v.size() == 3) d.voxel_size = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  return d;
}

}  // namespace granmem
