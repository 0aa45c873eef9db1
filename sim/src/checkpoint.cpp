#include "granmem/sim/checkpoint.hpp"

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/hdf5.hpp"
#include "granmem/core/version.hpp"

namespace granmem {
namespace {

constexpr const char* kFormat = "granmem checkpoint 1";

// Named numbers as a one-row table: readable in h5py, read back by name.
Table scalars(const std::map<std::string, double>& values) {
  Table t;
  for (const auto& [name, value] : values)
    t.add(name).values.push_back(value);
  return t;
}
double scalar(const Table& t, const std::string& name, const std::string& where) {
  if (!t.has(name) || t[name].values.size() != 1) {
    throw Error(where + ": checkpoint lacks '" + name + "'");
  }
  return t[name].values[0];
}

std::map<std::string, double> physics_values(const PhysicsOptions& p) {
  return {{"k_n", p.contact.k_n},
          {"restitution_n", p.contact.restitution_n},
          {"k_t_over_k_n", p.contact.k_t_over_k_n},
          {"restitution_t", p.contact.restitution_t},
          {"mu_s", p.contact.mu_s},
          {"mu_r", p.contact.mu_r},
          {"mu_t", p.contact.mu_t},
          {"beta", p.contact.beta},
          {"wall_mu_s", p.wall.mu_s},
          {"wall_mu_r", p.wall.mu_r},
          {"wall_mu_t", p.wall.mu_t},
          {"density", p.density},
          {"gravity", p.gravity},
          {"dt", p.dt},
          {"skin", p.skin},
          {"background_damping", p.background_damping},
          {"min_steps_per_collision", p.min_steps_per_collision}};
}

PhysicsOptions physics_from(const Table& t, const std::string& where) {
  PhysicsOptions p;
  auto get = [&](const char* name) { return scalar(t, name, where); };
  p.contact.k_n = get("k_n");
  p.contact.restitution_n = get("restitution_n");
  p.contact.k_t_over_k_n = get("k_t_over_k_n");
  p.contact.restitution_t = get("restitution_t");
  p.contact.mu_s = get("mu_s");
  p.contact.mu_r = get("mu_r");
  p.contact.mu_t = get("mu_t");
  p.contact.beta = get("beta");
  p.wall = {get("wall_mu_s"), get("wall_mu_r"), get("wall_mu_t")};
  p.density = get("density");
  p.gravity = get("gravity");
  p.dt = get("dt");
  p.skin = get("skin");
  p.background_damping = get("background_damping");
  p.min_steps_per_collision = get("min_steps_per_collision");
  return p;
}

const double* flat(const std::vector<Eigen::Vector3d>& v) {
  return v.empty() ? nullptr : v[0].data();
}

std::vector<Eigen::Vector3d> vectors(const std::vector<double>& flat_values, std::size_t n,
                                     const std::string& what) {
  if (flat_values.size() != 3 * n) throw Error(what + ": expected " + std::to_string(n) + " x 3");
  std::vector<Eigen::Vector3d> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    out[i] = Eigen::Vector3d(flat_values[3 * i], flat_values[3 * i + 1], flat_values[3 * i + 2]);
  }
  return out;
}

}  // namespace

void write_checkpoint(const std::filesystem::path& path, const Simulation& sim,
                      const ProtocolState& protocol) {
  AtomicFile out(path);
  {
    h5::File f = h5::File::create(out);
    h5::Handle root = h5::create_group(f.id(), "/checkpoint");
    h5::write_attribute(root.get(), "format", kFormat);
    h5::write_attribute(root.get(), "creator", std::string("granmem ") + kVersion);

    const Grains& g = sim.grains();
    const hsize_t n = g.size();
    h5::Handle grains = h5::create_group(f.id(), "/checkpoint/grains");
    h5::write(grains.get(), "id", g.id.data(), {n}, "1");
    h5::write(grains.get(), "radius", g.radius.data(), {n}, "m");
    h5::write(grains.get(), "mass", g.mass.data(), {n}, "kg");
    h5::write(grains.get(), "inv_mass", g.inv_mass.data(), {n}, "1/kg");
    h5::write(grains.get(), "inv_inertia", g.inv_inertia.data(), {n}, "1/(kg m^2)");
    h5::write(grains.get(), "position", flat(g.x), {n, 3}, "m");
    h5::write(grains.get(), "velocity", flat(g.v), {n, 3}, "m/s");
    h5::write(grains.get(), "angular_velocity", flat(g.w), {n, 3}, "rad/s");
    h5::write(grains.get(), "force", flat(g.force), {n, 3}, "N");
    h5::write(grains.get(), "torque", flat(g.torque), {n, 3}, "N m");
    std::vector<double> q(4 * n);
    for (std::size_t i = 0; i < n; ++i) {
      q[4 * i] = g.q[i].w();
      q[4 * i + 1] = g.q[i].x();
      q[4 * i + 2] = g.q[i].y();
      q[4 * i + 3] = g.q[i].z();
    }
    h5::write(grains.get(), "orientation", q.data(), {n, 4}, "1");

    const Container& c = sim.container();
    h5::write_table(f.id(), "/checkpoint/container",
                    scalars({{"size_x", c.size.x()},
                             {"size_y", c.size.y()},
                             {"y_wall", c.y_wall},
                             {"y_wall_velocity", c.y_wall_velocity},
                             {"lid_present", c.lid.present ? 1.0 : 0.0},
                             {"lid_mass", c.lid.mass},
                             {"lid_z", c.lid.z},
                             {"lid_v", c.lid.v},
                             {"lid_force", c.lid.force}}));
    h5::write_table(f.id(), "/checkpoint/physics", scalars(physics_values(sim.physics())));
    std::map<std::string, double> loads;
    for (int w = 0; w < kWallCount; ++w) {
      const std::string wall = "wall" + std::to_string(w);
      for (int d = 0; d < 3; ++d)
        loads[wall + "_f" + "xyz"[d]] = sim.wall_loads().force[w][d];
      loads[wall + "_contacts"] = sim.wall_loads().contacts[w];
    }
    h5::write_table(f.id(), "/checkpoint/wall_loads", scalars(loads));
    h5::write_table(f.id(), "/checkpoint/clock",
                    scalars({{"time", sim.time()}, {"steps", double(sim.step_count())}}));

    const std::vector<Simulation::PairRecord> pairs = sim.pair_histories();
    const hsize_t p = pairs.size();
    std::vector<std::int64_t> a(p), b(p);
    std::vector<double> slide(3 * p), roll(3 * p), twist(p);
    for (std::size_t k = 0; k < p; ++k) {
      a[k] = pairs[k].id_a;
      b[k] = pairs[k].id_b;
      for (int d = 0; d < 3; ++d) {
        slide[3 * k + d] = pairs[k].history.slide[d];
        roll[3 * k + d] = pairs[k].history.roll[d];
      }
      twist[k] = pairs[k].history.twist;
    }
    h5::Handle contacts = h5::create_group(f.id(), "/checkpoint/contacts");
    h5::write(contacts.get(), "id_a", a.data(), {p}, "1");
    h5::write(contacts.get(), "id_b", b.data(), {p}, "1");
    h5::write(contacts.get(), "slide", slide.data(), {p, 3}, "m");
    h5::write(contacts.get(), "roll", roll.data(), {p, 3}, "m");
    h5::write(contacts.get(), "twist", twist.data(), {p}, "m");

    const auto& walls = sim.wall_histories();
    std::vector<double> w_slide(n * kWallCount * 3), w_roll(n * kWallCount * 3),
        w_twist(n * kWallCount);
    for (std::size_t i = 0; i < n; ++i) {
      for (int w = 0; w < kWallCount; ++w) {
        const std::size_t k = i * kWallCount + std::size_t(w);
        for (int d = 0; d < 3; ++d) {
          w_slide[3 * k + d] = walls[i][w].slide[d];
          w_roll[3 * k + d] = walls[i][w].roll[d];
        }
        w_twist[k] = walls[i][w].twist;
      }
    }
    h5::Handle wall_contacts = h5::create_group(f.id(), "/checkpoint/wall_contacts");
    const hsize_t wc = kWallCount;
    h5::write(wall_contacts.get(), "slide", w_slide.data(), {n, wc, 3}, "m");
    h5::write(wall_contacts.get(), "roll", w_roll.data(), {n, wc, 3}, "m");
    h5::write(wall_contacts.get(), "twist", w_twist.data(), {n, wc}, "m");

    std::map<std::string, double> progress{{"cycles_done", double(protocol.cycles_done)},
                                           {"step_in_cycle", double(protocol.step_in_cycle)}};
    for (const auto& [name, frames] : protocol.frames_written) {
      progress["frames_" + name] = double(frames);
    }
    for (const auto& [name, value] : protocol.pending)
      progress["pending_" + name] = value;
    h5::write_table(f.id(), "/checkpoint/protocol", scalars(progress));
    h5::Handle settings = h5::create_group(f.id(), "/checkpoint/settings");
    for (const auto& [key, value] : protocol.settings) {
      h5::write_attribute(settings.get(), key, value);
    }
    f.close();
  }
  out.commit();
}

Simulation read_checkpoint(const std::filesystem::path& path, ProtocolState* protocol) {
  const h5::File f = h5::File::open(path);
  const std::string& where = f.name();
  {
    if (!h5::exists(f.id(), "/checkpoint")) throw Error(where + ": not a granmem checkpoint");
    h5::Handle root = h5::open_group(f, "/checkpoint");
    if (h5::read_string_attribute(root.get(), "format").value_or("") != kFormat) {
      throw Error(where + ": not a checkpoint of this granmem version (format '" +
                  h5::read_string_attribute(root.get(), "format").value_or("?") + "')");
    }
  }
  const std::string g = "/checkpoint/grains/";
  const std::vector<std::int64_t> id = h5::read<std::int64_t>(f, g + "id");
  const std::size_t n = id.size();
  Grains grains;
  grains.id = id;
  grains.radius = h5::read<double>(f, g + "radius");
  grains.mass = h5::read<double>(f, g + "mass");
  grains.inv_mass = h5::read<double>(f, g + "inv_mass");
  grains.inv_inertia = h5::read<double>(f, g + "inv_inertia");
  grains.x = vectors(h5::read<double>(f, g + "position"), n, where + " position");
  grains.v = vectors(h5::read<double>(f, g + "velocity"), n, where + " velocity");
  grains.w = vectors(h5::read<double>(f, g + "angular_velocity"), n, where + " angular velocity");
  const std::vector<Eigen::Vector3d> force =
      vectors(h5::read<double>(f, g + "force"), n, where + " " + g + "force");
  const std::vector<Eigen::Vector3d> torque =
      vectors(h5::read<double>(f, g + "torque"), n, where + " " + g + "torque");
  const std::vector<double> q = h5::read<double>(f, g + "orientation");
  if (q.size() != 4 * n || grains.radius.size() != n || grains.mass.size() != n ||
      grains.inv_mass.size() != n || grains.inv_inertia.size() != n) {
    throw Error(where + ": grain datasets of unequal lengths (expected " + std::to_string(n) +
                " grains)");
  }
  for (std::size_t i = 0; i < n; ++i) {
    grains.q.emplace_back(q[4 * i], q[4 * i + 1], q[4 * i + 2], q[4 * i + 3]);
  }
  grains.force = force;
  grains.torque = torque;

  const Table ct = h5::read_table(f, "/checkpoint/container");
  Container c;
  c.size = {scalar(ct, "size_x", where), scalar(ct, "size_y", where)};
  c.y_wall = scalar(ct, "y_wall", where);
  c.y_wall_velocity = scalar(ct, "y_wall_velocity", where);
  c.lid.present = scalar(ct, "lid_present", where) != 0;
  c.lid.mass = scalar(ct, "lid_mass", where);
  c.lid.z = scalar(ct, "lid_z", where);
  c.lid.v = scalar(ct, "lid_v", where);
  const double lid_force = scalar(ct, "lid_force", where);

  const PhysicsOptions physics = physics_from(h5::read_table(f, "/checkpoint/physics"), where);
  const Table clock = h5::read_table(f, "/checkpoint/clock");

  const std::string k = "/checkpoint/contacts/";
  const auto a = h5::read<std::int64_t>(f, k + "id_a"), b = h5::read<std::int64_t>(f, k + "id_b");
  const auto slide = h5::read<double>(f, k + "slide"), roll = h5::read<double>(f, k + "roll"),
             twist = h5::read<double>(f, k + "twist");
  if (b.size() != a.size() || slide.size() != 3 * a.size() || roll.size() != 3 * a.size() ||
      twist.size() != a.size()) {
    throw Error(where + ": contact datasets of unequal lengths");
  }
  std::vector<Simulation::PairRecord> pairs(a.size());
  for (std::size_t p = 0; p < a.size(); ++p) {
    pairs[p].id_a = a[p];
    pairs[p].id_b = b[p];
    pairs[p].history.slide = Eigen::Vector3d(slide[3 * p], slide[3 * p + 1], slide[3 * p + 2]);
    pairs[p].history.roll = Eigen::Vector3d(roll[3 * p], roll[3 * p + 1], roll[3 * p + 2]);
    pairs[p].history.twist = twist[p];
  }
  const std::string w = "/checkpoint/wall_contacts/";
  const auto w_slide = h5::read<double>(f, w + "slide"), w_roll = h5::read<double>(f, w + "roll"),
             w_twist = h5::read<double>(f, w + "twist");
  if (w_twist.size() != n * kWallCount || w_slide.size() != 3 * w_twist.size() ||
      w_roll.size() != 3 * w_twist.size()) {
    throw Error(where + ": wall contact datasets do not match the grains");
  }
  std::vector<std::array<ContactHistory, kWallCount>> walls(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int wall = 0; wall < kWallCount; ++wall) {
      const std::size_t s = i * kWallCount + std::size_t(wall);
      walls[i][wall].slide =
          Eigen::Vector3d(w_slide[3 * s], w_slide[3 * s + 1], w_slide[3 * s + 2]);
      walls[i][wall].roll = Eigen::Vector3d(w_roll[3 * s], w_roll[3 * s + 1], w_roll[3 * s + 2]);
      walls[i][wall].twist = w_twist[s];
    }
  }

  const Table load_table = h5::read_table(f, "/checkpoint/wall_loads");
  WallLoads loads;
  for (int wall = 0; wall < kWallCount; ++wall) {
    const std::string name = "wall" + std::to_string(wall);
    for (int d = 0; d < 3; ++d) {
      loads.force[wall][d] = scalar(load_table, name + "_f" + "xyz"[d], where);
    }
    loads.contacts[wall] = int(scalar(load_table, name + "_contacts", where));
  }
  Simulation sim(std::move(grains), c, physics);
  sim.restore(scalar(clock, "time", where), std::int64_t(scalar(clock, "steps", where)), pairs,
              std::move(walls), loads);
  // The forces of the last step, exactly as they were: the next half-kick uses them.
  sim.grains().force = force;
  sim.grains().torque = torque;
  sim.container().lid.force = lid_force;

  if (protocol) {
    const Table t = h5::read_table(f, "/checkpoint/protocol");
    *protocol = ProtocolState{};
    for (const Column& col : t.columns()) {
      if (col.values.size() != 1)
        throw Error(where + ": protocol value '" + col.name + "' damaged");
      const double v = col.values[0];
      if (col.name == "cycles_done")
        protocol->cycles_done = std::int64_t(v);
      else if (col.name == "step_in_cycle")
        protocol->step_in_cycle = std::int64_t(v);
      else if (col.name.rfind("frames_", 0) == 0)
        protocol->frames_written[col.name.substr(7)] = std::int64_t(v);
      else if (col.name.rfind("pending_", 0) == 0)
        protocol->pending[col.name.substr(8)] = v;
    }
    h5::Handle settings = h5::open_group(f, "/checkpoint/settings");
    for (const std::string& key : h5::attribute_names(settings.get())) {
      protocol->settings[key] = h5::read_string_attribute(settings.get(), key).value_or("");
    }
  }
  return sim;
}

}  // namespace granmem
