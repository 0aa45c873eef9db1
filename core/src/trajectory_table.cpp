#include "granmem/core/trajectory_table.hpp"

#include <cmath>

namespace granmem {

Table trajectory_table(const RunHeader& header) {
  Table t;
  const std::string& length = header.length_unit;
  t.add("frame", "", true);
  t.add("particle", "", true);
  t.add("time", header.time_unit);
  for (const char* c : {"x", "y", "z", "radius"})
    t.add(c, length);
  if (header.has_axis) {
    for (const char* c : {"ax", "ay", "az"})
      t.add(c);
  }
  if (header.has_orientation) {
    for (const char* c : {"qw", "qx", "qy", "qz"})
      t.add(c);
  }
  if (header.has_hole_contact) t.add("hole_contact", "", true);
  if (header.has_position_error) {
    for (const char* c : {"ep_x", "ep_y", "ep_z"})
      t.add(c, length);
  }
  if (header.has_axis_error) t.add("axis_error", "rad");
  return t;
}

void append_frame(Table& table, const RunHeader& header, const Frame& frame) {
  auto column = [&](const std::string& name) { return &table[name].values; };
  std::vector<double>*frame_col = column("frame"), *particle = column("particle"),
  *time = column("time"), *radius = column("radius");
  std::vector<double>* x[3] = {column("x"), column("y"), column("z")};
  std::vector<double>* axis[3] = {};
  std::vector<double>* q[4] = {};
  for (int a = 0; a < 3 && header.has_axis; ++a)
    axis[a] = column(std::string("a") + "xyz"[a]);
  for (int a = 0; a < 4 && header.has_orientation; ++a)
    q[a] = column(std::string("q") + "wxyz"[a]);
  std::vector<double>* hole = header.has_hole_contact ? column("hole_contact") : nullptr;
  std::vector<double>* ep[3] = {};
  for (int a = 0; a < 3 && header.has_position_error; ++a)
    ep[a] = column(std::string("ep_") + "xyz"[a]);
  std::vector<double>* axis_error = header.has_axis_error ? column("axis_error") : nullptr;
  for (std::size_t g = 0; g < header.grain_count(); ++g) {
    const auto r = Eigen::Index(g);
    if (!frame.position.row(r).allFinite()) continue;  // not seen in this frame
    frame_col->push_back(double(frame.step));
    particle->push_back(double(header.id[g]));
    time->push_back(frame.time);
    for (int a = 0; a < 3; ++a)
      x[a]->push_back(frame.position(r, a));
    radius->push_back(header.radius[g]);
    for (int a = 0; a < 3 && header.has_axis; ++a)
      axis[a]->push_back(frame.axis(r, a));
    for (int a = 0; a < 4 && header.has_orientation; ++a)
      q[a]->push_back(frame.orientation(r, a));
    if (hole) hole->push_back(frame.hole_contact[g]);
    for (int a = 0; a < 3 && header.has_position_error; ++a)
      ep[a]->push_back(frame.position_error(r, a));
    if (axis_error) axis_error->push_back(frame.axis_error[g]);
  }
}

Table trajectory_table(const Trajectories& run) {
  Table t = trajectory_table(run.header);
  for (const Frame& frame : run.frames)
    append_frame(t, run.header, frame);
  return t;
}

}  // namespace granmem
