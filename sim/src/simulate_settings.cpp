#include "granmem/sim/simulate_settings.hpp"

#include <cmath>
#include <cstdio>
#include <iterator>
#include <sstream>

#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"
#include "granmem/sim/quasi_static.hpp"

namespace granmem {

namespace {
constexpr const char* kPaperLidPressureText = "436Pa";  // kPaperLidPressure, as given
}  // namespace

const OptionSpec kSimulateOptions[] = {
    {"grains", nullptr, "number of grains"},
    {"cycles", "10", "compression cycles"},
    {"amplitude", "1%", "wall amplitude A: a length (0.15cm) or a fraction of the box (1%)"},
    {"drive", "asymmetric", "asymmetric (0 -> A -> 0) or symmetric (0 -> A/2 -> -A/2 -> 0)"},
    {"wall-motion", "cosine", "cosine (smooth) or linear"},
    {"period", "auto", "cycle period (25ms...), or auto: the inertial number below"},
    {"inertial-number", kQuasiStaticInertialNumberText,
     "quasi-static limit for the automatic period"},
    {"box", nullptr, "side of the square box"},
    {"diameter", nullptr, "grain diameter"},
    {"polydispersity", nullptr, "radii uniform in r(1 +- p)"},
    {"density", nullptr, "grain density"},
    {"lid-pressure", kPaperLidPressureText,
     "pressure of the free lid on the packing (436Pa: the paper's 1 kg on 15 x 15 cm; 0: no "
     "lid)"},
    {"lid-mass", "auto", "mass of the free lid (auto: from --lid-pressure; 0: no lid)"},
    {"k-n", nullptr, "normal spring constant"},
    {"restitution-n", nullptr, "normal restitution coefficient"},
    {"restitution-t", nullptr, "tangential restitution coefficient"},
    {"kt-over-kn", nullptr, "tangential over normal spring constant (5/7)"},
    {"mu-s", nullptr, "sliding friction between grains"},
    {"mu-r", nullptr, "rolling friction"},
    {"mu-t", nullptr, "twisting friction"},
    {"beta", nullptr, "shape parameter of rolling and twisting"},
    {"wall-mu-s", "same", "sliding friction on walls and lid (same: as between grains)"},
    {"wall-mu-r", "same", "rolling friction on walls and lid"},
    {"wall-mu-t", "same", "twisting friction on walls and lid"},
    {"dt", nullptr, "time step"},
    {"skin", nullptr, "neighbour-list skin"},
    {"gravity", nullptr, "gravity"},
    {"seed", nullptr, "seed of the deposition"},
    {"settled-energy", nullptr, "kinetic energy per grain below which a packing is settled"},
    {"settling-damping", nullptr, "drag rate while settling, 1/s"},
    {"full-compression", "false", "also write frames at full compression"},
    {"track", "", "grain ids sampled inside cycles, comma list"},
    {"samples-per-cycle", "0", "in-cycle samples of the tracked grains"},
    {"checkpoint-every", "0", "cycles between checkpoints (0: at the end and on Ctrl-C)"},
    {"keep-states", "",
     "cycles after which the full state is kept (<out>_state_cycle<N>.h5), comma list: "
     "trained states for granmem readout"},
    {"checkpoint", "", "checkpoint file (default <out>.checkpoint.h5)"},
    {"out", "run.h5", "end-of-cycle trajectory store"},
    {"engine", "granmem",
     "what runs the cycles: granmem (the embedded DEM) or lammps (LAMMPS under mpirun, files "
     "in <out>.lammps/; equal grains, end-of-cycle frames, cavity axes only)"},
    {"ranks", "1", "--engine lammps: MPI ranks (mpirun -np)"},
    {"lammps", "lmp", "--engine lammps: the LAMMPS executable"},
};
const std::size_t kSimulateOptionCount = std::size(kSimulateOptions);

const char* const kPackingOptions[] = {"grains",
                                       "box",
                                       "diameter",
                                       "polydispersity",
                                       "density",
                                       "lid-mass",
                                       "lid-pressure",
                                       "k-n",
                                       "restitution-n",
                                       "restitution-t",
                                       "kt-over-kn",
                                       "mu-s",
                                       "mu-r",
                                       "mu-t",
                                       "beta",
                                       "wall-mu-s",
                                       "wall-mu-r",
                                       "wall-mu-t",
                                       "dt",
                                       "skin",
                                       "gravity",
                                       "seed",
                                       "settled-energy",
                                       "settling-damping"};
const std::size_t kPackingOptionCount = std::size(kPackingOptions);

namespace {

// A number as the settings write it: 15 significant digits, so that a default scaled into
// the unit shown (25e-6 s as 25us) reads as typed.
std::string number_text(double value, const char* unit = "") {
  char text[40];
  std::snprintf(text, sizeof text, "%.15g%s", value, unit);
  return text;
}

// The defaults the library's structs hold (PhysicsOptions, ContactParameters,
// DepositOptions: the paper's table), in the units the help shows them in.
RunSettings library_defaults() {
  const PhysicsOptions p;
  const ContactParameters& c = p.contact;
  const DepositOptions d;
  return {{"grains", number_text(double(d.grains))},
          {"box", number_text(d.box_side * 100, "cm")},
          {"diameter", number_text(2 * d.radius * 100, "cm")},
          {"polydispersity", number_text(d.polydispersity)},
          {"density", number_text(p.density / 1000, "g/cm^3")},
          {"k-n", number_text(c.k_n * 1000, "g/s^2")},
          {"restitution-n", number_text(c.restitution_n)},
          {"restitution-t", number_text(c.restitution_t)},
          {"kt-over-kn", number_text(c.k_t_over_k_n)},
          {"mu-s", number_text(c.mu_s)},
          {"mu-r", number_text(c.mu_r)},
          {"mu-t", number_text(c.mu_t)},
          {"beta", number_text(c.beta)},
          {"dt", number_text(p.dt * 1e6, "us")},
          {"skin", number_text(p.skin * 100, "cm")},
          {"gravity", number_text(p.gravity, "m/s^2")},
          {"seed", number_text(double(d.seed))},
          {"settled-energy", number_text(d.settled_energy, "J")},
          {"settling-damping", number_text(d.settling_damping)}};
}

}  // namespace

RunSettings default_simulate_settings() {
  RunSettings v = library_defaults();
  for (const OptionSpec& o : kSimulateOptions) {
    if (o.default_value) v[o.name] = o.default_value;
  }
  return v;
}

double setting_number(const RunSettings& v, const std::string& name) {
  const Quantity q = parse_quantity(v.at(name), "--" + name);
  if (!q.unit.empty()) throw Error("--" + name + " '" + v.at(name) + "': expected a plain number");
  return q.value;
}
double setting_si(const RunSettings& v, const std::string& name, Dimension d,
                  const char* default_unit) {
  return parse_si(v.at(name), d, default_unit, "--" + name);
}
std::int64_t setting_whole(const RunSettings& v, const std::string& name) {
  const double x = setting_number(v, name);
  if (x != std::floor(x) || x < 0 || x > 9e15) {
    throw Error("--" + name + " '" + v.at(name) + "': expected a whole number >= 0");
  }
  return std::int64_t(x);
}
bool setting_yes_no(const RunSettings& v, const std::string& name) {
  const std::string& x = v.at(name);
  if (x == "true" || x == "yes" || x == "on" || x == "1") return true;
  if (x == "false" || x == "no" || x == "off" || x == "0") return false;
  throw Error("--" + name + " '" + x + "': expected true or false");
}

PhysicsOptions physics_from(const RunSettings& v) {
  PhysicsOptions p;
  p.contact.k_n = setting_si(v, "k-n", Dimension::stiffness);
  p.contact.restitution_n = setting_number(v, "restitution-n");
  p.contact.restitution_t = setting_number(v, "restitution-t");
  p.contact.k_t_over_k_n = setting_number(v, "kt-over-kn");
  p.contact.mu_s = setting_number(v, "mu-s");
  p.contact.mu_r = setting_number(v, "mu-r");
  p.contact.mu_t = setting_number(v, "mu-t");
  p.contact.beta = setting_number(v, "beta");
  auto wall = [&](const char* name, double grain) {
    return v.at(name) == "same" ? grain : setting_number(v, name);
  };
  p.wall = {wall("wall-mu-s", p.contact.mu_s), wall("wall-mu-r", p.contact.mu_r),
            wall("wall-mu-t", p.contact.mu_t)};
  p.density = setting_si(v, "density", Dimension::density);
  p.gravity = setting_si(v, "gravity", Dimension::acceleration);
  p.dt = setting_si(v, "dt", Dimension::time);
  p.skin = setting_si(v, "skin", Dimension::length);
  return p;
}

double lid_mass_from(const RunSettings& v, double box, double gravity) {
  if (v.at("lid-mass") != "auto") {
    if (v.at("lid-pressure") != kPaperLidPressureText) {
      throw Error("--lid-mass " + v.at("lid-mass") + " and --lid-pressure " + v.at("lid-pressure") +
                  ": give the lid's mass or its pressure, not both");
    }
    return setting_si(v, "lid-mass", Dimension::mass);
  }
  const double pressure = setting_si(v, "lid-pressure", Dimension::pressure);
  if (!(pressure >= 0)) {
    throw Error("--lid-pressure '" + v.at("lid-pressure") + "': must be zero or positive");
  }
  return lid_mass_for_pressure(pressure, gravity, box, box);
}

DepositOptions deposit_from(const RunSettings& v) {
  DepositOptions d;
  d.grains = setting_whole(v, "grains");
  d.radius = 0.5 * setting_si(v, "diameter", Dimension::length);
  d.polydispersity = setting_number(v, "polydispersity");
  d.box_side = setting_si(v, "box", Dimension::length);
  d.lid_mass = lid_mass_from(v, d.box_side, setting_si(v, "gravity", Dimension::acceleration));
  d.seed = std::uint64_t(setting_whole(v, "seed"));
  d.settled_energy = setting_si(v, "settled-energy", Dimension::energy);
  d.settling_damping = setting_number(v, "settling-damping");
  if (!(d.box_side > 0)) throw Error("--box '" + v.at("box") + "': must be positive");
  if (!(d.radius > 0)) throw Error("--diameter '" + v.at("diameter") + "': must be positive");
  if (!(d.polydispersity >= 0 && d.polydispersity < 1)) {
    throw Error("--polydispersity " + v.at("polydispersity") + ": must be in [0, 1)");
  }
  return d;
}

WallDrive drive_from(const RunSettings& v, const PhysicsOptions& physics, double box, double box_y,
                     double lid_mass, double radius) {
  WallDrive d;
  d.amplitude = parse_amplitude(v.at("amplitude"), box_y, "--amplitude");
  d.symmetry = parse_drive_symmetry(v.at("drive"));
  d.shape = parse_drive_shape(v.at("wall-motion"));
  if (v.at("period") == "auto") {
    if (!(d.amplitude > 0)) {
      throw Error("--amplitude " + v.at("amplitude") +
                  ": a still wall has no quasi-static period; give --period");
    }
    if (!(setting_number(v, "inertial-number") > 0)) {
      throw Error("--inertial-number " + v.at("inertial-number") + ": must be positive");
    }
    const double stress = confining_stress(lid_pressure(lid_mass, physics.gravity, box, box),
                                           physics.density, physics.gravity, 2 * radius);
    d.period = quasi_static_period(setting_number(v, "inertial-number"), d, box_y, 2 * radius,
                                   stress, physics.density);
  } else {
    d.period = setting_si(v, "period", Dimension::time);
  }
  return d;
}

std::vector<std::int64_t> whole_list(const RunSettings& v, const std::string& name,
                                     const char* example) {
  std::vector<std::int64_t> out;
  std::stringstream list(v.at(name));
  for (std::string item; std::getline(list, item, ',');) {
    if (item.empty()) continue;
    const Quantity q = parse_quantity(item, "--" + name);
    if (!q.unit.empty() || q.value != std::floor(q.value)) {
      throw Error("--" + name + " '" + v.at(name) + "': expected whole numbers, e.g. " + example);
    }
    out.push_back(std::int64_t(q.value));
  }
  return out;
}

bool wall_friction_follows(const RunSettings& v) {
  return v.at("wall-mu-s") == "same";
}

}  // namespace granmem
