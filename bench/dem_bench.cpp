// granmem's DEM against LAMMPS on the same packing and the same contact law: the granmem
// half of bench/compare_lammps.sh. Lengths on the command line are in cm; data files for
// LAMMPS are in its CGS units (atom_style sphere), everything inside granmem is SI.
//
//   dem_bench insert N L seed out.data        grains as granmem::deposit inserts them
//   dem_bench settle N L seed out.h5 [threads] granmem settles that insertion, lid on top
//   dem_bench export in.h5 out.data           a checkpoint's packing (with its lid)
//   dem_bench time in.h5 nsteps threads [A_cm] the y = 0 wall driven 0 -> A -> 0 (cosine,
//                                              A = 1% of L by default) over nsteps, timed
//   dem_bench contact-check out.data nsteps   a few grains touching each other, the walls
//                                              and the lid: final state after nsteps
//   dem_bench tile in.h5 nx ny out.h5 [threads] nx x ny copies of a settled packing side
//                                              by side under one lid of the same pressure,
//                                              settled again
//
// The lid of `settle` weighs 1 kg per 15 x 15 cm (the paper's pressure; 1 kg at L = 15).
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/lammps_data.hpp"
#include "granmem/sim/quasi_static.hpp"
#include "granmem/sim/simulation.hpp"
#include "granmem/sim/spatial_order.hpp"
#include "granmem/sim/wall_drive.hpp"

namespace {

using granmem::Container;
using granmem::Grains;
using granmem::Simulation;

constexpr double kCm = 0.01;  // m per cm
constexpr double kPaperBox = 0.15;

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB on Linux
}

long to_count(const std::string& text, const char* what) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || v < 0) {
    throw granmem::Error(std::string(what) + " '" + text + "': expected a whole number >= 0");
  }
  return v;
}
double to_number(const std::string& text, const char* what) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !std::isfinite(v)) {
    throw granmem::Error(std::string(what) + " '" + text + "': expected a number");
  }
  return v;
}

// The deposition of N grains in an L x L box with the paper's physics and lid pressure.
granmem::DepositOptions deposit_options(long grains, double box_cm, long seed) {
  granmem::DepositOptions d;
  d.grains = grains;
  d.box_side = box_cm * kCm;
  d.seed = std::uint64_t(seed);
  d.lid_mass = granmem::lid_mass_for_pressure(
      granmem::kPaperLidPressure, granmem::PhysicsOptions{}.gravity, d.box_side, d.box_side);
  return d;
}

// The packing as LAMMPS reads it (sim/lammps/common.lmp): atom_style sphere, the lid a
// type-2 point particle.
void write_lammps_data(const std::filesystem::path& path, const Grains& g, const Container& c,
                       double density, const std::string& comment) {
  granmem::LammpsDataOptions o;
  o.density = density;
  o.comment = "dem_bench: " + comment;
  granmem::write_lammps_data(path, g, c, o);
}

int insert(const std::vector<std::string>& a) {
  if (a.size() != 4) throw granmem::Error("usage: dem_bench insert N L_cm seed out.data");
  const granmem::DepositOptions d =
      deposit_options(to_count(a[0], "N"), to_number(a[1], "L"), to_count(a[2], "seed"));
  const granmem::PhysicsOptions physics;
  const Grains g = granmem::insert_grains(d, physics);
  Container box;
  box.size = {d.box_side, d.box_side};
  write_lammps_data(a[3], g, box, physics.density,
                    "inserted, N=" + a[0] + " L=" + a[1] + "cm seed=" + a[2]);
  std::cout << "granmem insert: N=" << g.size() << " L_cm=" << a[1] << " seed=" << a[2]
            << " lid_mass_g=" << d.lid_mass * 1e3 << " wrote " << a[3] << "\n";
  return 0;
}

int settle(const std::vector<std::string>& a) {
  if (a.size() != 4 && a.size() != 5) {
    throw granmem::Error("usage: dem_bench settle N L_cm seed out.h5 [threads]");
  }
  if (a.size() == 5) omp_set_num_threads(int(to_count(a[4], "threads")));
  const granmem::DepositOptions d =
      deposit_options(to_count(a[0], "N"), to_number(a[1], "L"), to_count(a[2], "seed"));
  const granmem::PhysicsOptions physics;
  granmem::DepositSummary s;
  const auto start = Clock::now();
  Simulation sim = granmem::deposit(d, physics, &s, granmem::print_deposit_progress(std::cerr));
  const double wall = seconds_since(start);
  granmem::write_checkpoint(a[3], sim, granmem::ProtocolState{});
  std::cout << "granmem settle: N=" << sim.grains().size() << " L_cm=" << a[1] << " seed=" << a[2]
            << " lid_mass_g=" << d.lid_mass * 1e3 << " packing_fraction=" << s.packing_fraction
            << " lid_height_cm=" << s.lid_height / kCm
            << " contacts_per_grain=" << s.contacts_per_grain
            << " settling_time_s=" << s.settling_time << " steps=" << sim.step_count()
            << " threads=" << omp_get_max_threads() << " wall_s=" << wall << " wrote " << a[3]
            << "\n";
  return 0;
}

int export_data(const std::vector<std::string>& a) {
  if (a.size() != 2) throw granmem::Error("usage: dem_bench export in.h5 out.data");
  const Simulation sim = granmem::read_checkpoint(a[0]);
  write_lammps_data(a[1], sim.grains(), sim.container(), sim.physics().density,
                    "settled packing of " + a[0]);
  std::cout << "granmem export: N=" << sim.grains().size()
            << " packing_fraction=" << granmem::packing_fraction(sim)
            << " lid_height_cm=" << granmem::packing_height(sim) / kCm << " wrote " << a[1] << "\n";
  return 0;
}

// nx x ny copies of a packing side by side in one box (x and y sides nx and ny times as
// long), under one lid at the same height and pressure, settled as deposit() settles (the
// copies meet where their walls were, with gaps to close): a large settled packing at the
// cost of a short settling.
int tile(const std::vector<std::string>& a) {
  if (a.size() != 4 && a.size() != 5) {
    throw granmem::Error("usage: dem_bench tile in.h5 nx ny out.h5 [threads]");
  }
  if (a.size() == 5) omp_set_num_threads(int(to_count(a[4], "threads")));
  const long nx = to_count(a[1], "nx"), ny = to_count(a[2], "ny");
  if (nx < 1 || ny < 1) throw granmem::Error("nx and ny must be >= 1");
  const Simulation one = granmem::read_checkpoint(a[0]);
  const Grains& g = one.grains();
  Container box = one.container();
  const Eigen::Vector2d side = box.size;
  box.size = {side.x() * double(nx), side.y() * double(ny)};
  box.lid.mass *= double(nx * ny);
  const std::int64_t id_span = *std::max_element(g.id.begin(), g.id.end()) + 1;
  Grains all;
  for (long cx = 0; cx < nx; ++cx) {
    for (long cy = 0; cy < ny; ++cy) {
      const Eigen::Vector3d shift(side.x() * double(cx), side.y() * double(cy), 0);
      const std::int64_t copy = cx * ny + cy;
      for (std::size_t i = 0; i < g.size(); ++i) {
        all.add(g.id[i] + copy * id_span, g.x[i] + shift, g.radius[i], one.physics().density);
        all.v.back() = g.v[i];
        all.w.back() = g.w[i];
        all.q.back() = g.q[i];
      }
    }
  }
  // In spatial order: the copies' ids would otherwise put neighbours across a seam far apart.
  Simulation sim = granmem::in_spatial_order(Simulation(std::move(all), box, one.physics()));
  const auto start = Clock::now();
  const double settling = granmem::settle(sim, granmem::DepositOptions{}, "tiled",
                                          granmem::print_deposit_progress(std::cerr));
  granmem::write_checkpoint(a[3], sim, granmem::ProtocolState{});
  std::cout << "granmem tile: N=" << sim.grains().size() << " box_cm=" << box.size.x() / kCm << "x"
            << box.size.y() / kCm << " lid_mass_g=" << box.lid.mass * 1e3
            << " packing_fraction=" << granmem::packing_fraction(sim)
            << " lid_height_cm=" << granmem::packing_height(sim) / kCm
            << " settling_time_s=" << settling << " wall_s=" << seconds_since(start) << " wrote "
            << a[3] << "\n";
  return 0;
}

// Steps per cycle of the paper's protocol as `granmem simulate` sets it by default
// (--period auto: a cosine drive of A = 1 % of the 15 cm box at the default inertial number
// under the paper's lid pressure), with this packing's grains and time step.
double paper_steps_per_cycle(const Simulation& sim) {
  const auto& p = sim.physics();
  const double diameter = 2 * sim.grains().radius.at(0);
  granmem::WallDrive drive;
  drive.amplitude = 0.01 * kPaperBox;
  const double stress =
      granmem::confining_stress(granmem::kPaperLidPressure, p.density, p.gravity, diameter);
  return std::round(granmem::quasi_static_period(granmem::kQuasiStaticInertialNumber, drive,
                                                 kPaperBox, diameter, stress, p.density) /
                    p.dt);
}

int time_run(const std::vector<std::string>& a) {
  if (a.size() != 3 && a.size() != 4) {
    throw granmem::Error("usage: dem_bench time in.h5 nsteps threads [A_cm]");
  }
  const long steps = to_count(a[1], "nsteps");
  const int threads = int(to_count(a[2], "threads"));
  if (steps < 1 || threads < 1) throw granmem::Error("nsteps and threads must be >= 1");
  omp_set_num_threads(threads);
  Simulation sim = granmem::read_checkpoint(a[0]);
  sim.set_threads(threads);  // by default a Simulation takes one thread per 2,500 grains
  const double lid_before = granmem::packing_height(sim);
  granmem::WallDrive drive;
  drive.amplitude = a.size() == 4 ? to_number(a[3], "A") * kCm : 0.01 * sim.container().size.y();
  drive.period = double(steps) * sim.physics().dt;
  const double t0 = sim.time();
  sim.set_wall_motion(
      [drive, t0](double t) { return drive.at(std::clamp(t - t0, 0.0, drive.period)); });
  const std::int64_t builds_before = sim.neighbor_builds();
  const auto start = Clock::now();
  sim.run(steps);
  const double wall = seconds_since(start);
  const double n = double(sim.grains().size());
  double y_min = 1e300;
  for (const auto& x : sim.grains().x)
    y_min = std::min(y_min, x.y());
  std::cout << "granmem time: N=" << sim.grains().size() << " threads=" << sim.threads()
            << " steps=" << steps << " wall_s=" << wall
            << " particle_steps_per_s=" << n * double(steps) / wall
            << " peak_rss_mb=" << peak_rss_mb() << " A_cm=" << drive.amplitude / kCm
            << " lid_cm_before=" << lid_before / kCm
            << " lid_cm_after=" << granmem::packing_height(sim) / kCm
            << " ke_per_grain_erg=" << sim.kinetic_energy() / n * 1e7
            << " min_grain_y_cm=" << y_min / kCm
            << " contacts_per_grain=" << 2.0 * double(sim.contact_count()) / n
            << " neighbor_builds=" << sim.neighbor_builds() - builds_before
            << " steps_per_cycle_paper=" << paper_steps_per_cycle(sim) << "\n";
  return 0;
}

// Four grains on the floor of a 3 x 3 cm box under a 2 g lid, sliding, rolling and
// spinning against the floor, a side wall, each other and the lid: every mode of the law
// between grains and against walls is exercised. Prints the state after nsteps (CGS).
int contact_check(const std::vector<std::string>& a) {
  if (a.size() != 2) throw granmem::Error("usage: dem_bench contact-check out.data nsteps");
  const long steps = to_count(a[1], "nsteps");
  const granmem::PhysicsOptions physics;
  const double r = 0.0025, z = r - 1.4e-6;  // about at rest on the floor under the lid
  Grains g;
  g.add(0, {0.010, 0.015, z}, r, physics.density);
  g.add(1, {r - 5e-6, 0.010, z}, r, physics.density);
  g.add(2, {0.020, 0.020, z}, r, physics.density);
  g.add(3, {0.020, 0.020 + 2 * r - 5e-6, z}, r, physics.density);
  g.v[0] = {0.05, 0, 0};
  g.w[0] = {0, 20, 10};
  g.v[1] = {0, 0.03, 0};
  g.w[1] = {15, -5, 8};
  g.v[2] = {0, 0.05, 0};
  g.w[2] = {10, 0, -30};
  g.w[3] = {0, -10, 20};
  Container c;
  c.size = {0.03, 0.03};
  c.lid.present = true;
  c.lid.mass = 0.002;
  c.lid.z = z + r - 1.2e-6;
  write_lammps_data(a[0], g, c, physics.density, "contact check");
  Simulation sim(std::move(g), c, physics);
  sim.run(steps);
  const Grains& s = sim.grains();
  std::cout << std::setprecision(10);
  for (std::size_t i = 0; i < s.size(); ++i) {
    const Eigen::Vector3d x = s.x[i] / kCm, v = s.v[i] / kCm;
    std::cout << "grain " << s.id[i] + 1 << " " << x.x() << " " << x.y() << " " << x.z() << " "
              << v.x() << " " << v.y() << " " << v.z() << " " << s.w[i].x() << " " << s.w[i].y()
              << " " << s.w[i].z() << "\n";
  }
  std::cout << "lid " << sim.container().lid.z / kCm << " " << sim.container().lid.v / kCm << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + std::min(argc, 2), argv + argc);
  const std::string mode = argc > 1 ? argv[1] : "";
  try {
    if (mode == "insert") return insert(args);
    if (mode == "settle") return settle(args);
    if (mode == "export") return export_data(args);
    if (mode == "time") return time_run(args);
    if (mode == "contact-check") return contact_check(args);
    if (mode == "tile") return tile(args);
    std::cerr << "usage: dem_bench insert|settle|export|time|contact-check|tile ... (see the "
                 "source's first lines)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "dem_bench " << mode << ": " << e.what() << "\n";
    return 1;
  }
}
