#include <omp.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include "commands.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"

namespace granmem::app {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void request_stop(int) {
  g_stop.store(true);
}

// Every option as text, as given or defaulted: it is parsed with its unit below, stored
// in the checkpoint, and read back from it on --resume.
struct SimulateArgs {
  std::map<std::string, std::string> value;  // option name -> text
};

struct OptionSpec {
  const char* name;
  const char* default_value;
  const char* help;
};
// The defaults are the paper's table and protocol.
const OptionSpec kOptions[] = {
    {"grains", "2000", "number of grains"},
    {"cycles", "10", "compression cycles"},
    {"amplitude", "1%", "wall amplitude A: a length (0.15cm) or a fraction of the box (1%)"},
    {"drive", "asymmetric", "asymmetric (0 -> A -> 0) or symmetric (0 -> A/2 -> -A/2 -> 0)"},
    {"wall-motion", "cosine", "cosine (smooth) or linear"},
    {"period", "auto", "cycle period (25ms...), or auto: the inertial number below"},
    {"inertial-number", "1e-3", "quasi-static limit for the automatic period"},
    {"box", "15cm", "side of the square box"},
    {"diameter", "0.5cm", "grain diameter"},
    {"polydispersity", "0", "radii uniform in r(1 +- p)"},
    {"density", "1.18g/cm^3", "grain density"},
    {"lid-mass", "1kg", "mass of the free lid (0: no lid)"},
    {"k-n", "4e6g/s^2", "normal spring constant"},
    {"restitution-n", "0.2", "normal restitution coefficient"},
    {"restitution-t", "0.5", "tangential restitution coefficient"},
    {"kt-over-kn", "0.714285714285714", "tangential over normal spring constant (5/7)"},
    {"mu-s", "0.2", "sliding friction between grains"},
    {"mu-r", "0.01", "rolling friction"},
    {"mu-t", "0.001", "twisting friction"},
    {"beta", "0.5", "shape parameter of rolling and twisting"},
    {"wall-mu-s", "same", "sliding friction on walls and lid (same: as between grains)"},
    {"wall-mu-r", "same", "rolling friction on walls and lid"},
    {"wall-mu-t", "same", "twisting friction on walls and lid"},
    {"dt", "25us", "time step"},
    {"skin", "0.05cm", "neighbour-list skin"},
    {"gravity", "9.81m/s^2", "gravity"},
    {"seed", "1", "seed of the deposition"},
    {"settled-energy", "1e-13J", "kinetic energy per grain below which a packing is settled"},
    {"settling-damping", "5", "drag rate while settling, 1/s"},
    {"full-compression", "false", "also write frames at full compression"},
    {"track", "", "grain ids sampled inside cycles, comma list"},
    {"samples-per-cycle", "0", "in-cycle samples of the tracked grains"},
    {"checkpoint-every", "0", "cycles between checkpoints (0: at the end and on Ctrl-C)"},
    {"checkpoint", "", "checkpoint file (default <out>.checkpoint.h5)"},
    {"out", "run.h5", "end-of-cycle trajectory store"},
};

// What makes the packing and its physics: fixed for a run, and for runs started from it.
const char* const kPackingOptions[] = {"grains",
                                       "box",
                                       "diameter",
                                       "polydispersity",
                                       "density",
                                       "lid-mass",
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

double number(const std::map<std::string, std::string>& v, const std::string& name) {
  const Quantity q = parse_quantity(v.at(name), "--" + name);
  if (!q.unit.empty()) throw Error("--" + name + " '" + v.at(name) + "': expected a plain number");
  return q.value;
}
double si(const std::map<std::string, std::string>& v, const std::string& name, Dimension d,
          const char* default_unit = "") {
  return parse_si(v.at(name), d, default_unit, "--" + name);
}
std::int64_t whole(const std::map<std::string, std::string>& v, const std::string& name) {
  const double x = number(v, name);
  if (x != std::floor(x) || x < 0 || x > 9e15) {
    throw Error("--" + name + " '" + v.at(name) + "': expected a whole number >= 0");
  }
  return std::int64_t(x);
}
bool yes_no(const std::map<std::string, std::string>& v, const std::string& name) {
  const std::string& x = v.at(name);
  if (x == "true" || x == "yes" || x == "on" || x == "1") return true;
  if (x == "false" || x == "no" || x == "off" || x == "0") return false;
  throw Error("--" + name + " '" + x + "': expected true or false");
}

// The files a run writes must be distinct, must not be the checkpoint it starts from, and
// must go to folders that exist: checked before anything is computed.
void check_outputs(const std::vector<std::filesystem::path>& outputs,
                   const std::filesystem::path& source) {
  namespace fs = std::filesystem;
  std::vector<fs::path> seen;
  for (const fs::path& p : outputs) {
    const fs::path folder = p.parent_path().empty() ? fs::path(".") : p.parent_path();
    if (!fs::is_directory(folder)) {
      throw Error(p.string() + ": folder '" + folder.string() + "' does not exist");
    }
    const fs::path full = fs::weakly_canonical(p);
    if (!source.empty() && full == fs::weakly_canonical(source)) {
      throw Error(p.string() + ": is the checkpoint this run starts from; choose another --out");
    }
    for (const fs::path& other : seen) {
      if (full == other)
        throw Error(p.string() + ": written twice by this run (--out, --checkpoint)");
    }
    seen.push_back(full);
  }
}

PhysicsOptions physics_from(const std::map<std::string, std::string>& v) {
  PhysicsOptions p;
  p.contact.k_n = si(v, "k-n", Dimension::stiffness);
  p.contact.restitution_n = number(v, "restitution-n");
  p.contact.restitution_t = number(v, "restitution-t");
  p.contact.k_t_over_k_n = number(v, "kt-over-kn");
  p.contact.mu_s = number(v, "mu-s");
  p.contact.mu_r = number(v, "mu-r");
  p.contact.mu_t = number(v, "mu-t");
  p.contact.beta = number(v, "beta");
  auto wall = [&](const char* name, double grain) {
    return v.at(name) == "same" ? grain : number(v, name);
  };
  p.wall = {wall("wall-mu-s", p.contact.mu_s), wall("wall-mu-r", p.contact.mu_r),
            wall("wall-mu-t", p.contact.mu_t)};
  p.density = si(v, "density", Dimension::density);
  p.gravity = si(v, "gravity", Dimension::acceleration);
  p.dt = si(v, "dt", Dimension::time);
  p.skin = si(v, "skin", Dimension::length);
  return p;
}

std::string duration_text(double seconds) {
  const auto s = std::llround(seconds);
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%lldh%02lldm", s / 3600, (s % 3600) / 60);
  else
    std::snprintf(buf, sizeof buf, "%lldm%02llds", s / 60, s % 60);
  return buf;
}

}  // namespace

void add_simulate(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  auto threads = std::make_shared<int>(0);
  auto resume = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Deposit grains in the box under a lid and compress them cyclically (DEM)");
  std::map<std::string, CLI::Option*> given;
  for (const OptionSpec& o : kOptions) {
    args->value[o.name] = o.default_value;
    given[o.name] = cmd->add_option(std::string("--") + o.name, args->value[o.name], o.help)
                        ->capture_default_str();
  }
  cmd->add_option("--threads", *threads,
                  "OpenMP threads (default: one per 2,500 grains, up to all cores)");
  auto start_from = std::make_shared<std::string>();
  CLI::Option* resume_option =
      cmd->add_option("--resume", *resume, "continue the run of this checkpoint")
          ->check(CLI::ExistingFile);
  cmd->add_option("--start-from", *start_from,
                  "start a new protocol (drive, amplitude, cycles, outputs) from the packing in "
                  "this checkpoint, e.g. a trained state for a memory read-out")
      ->check(CLI::ExistingFile)
      ->excludes(resume_option);

  cmd->callback([args, threads, resume, start_from, given] {
    if (*threads > 0) omp_set_num_threads(*threads);  // deposit's and the cycles' simulations
    std::map<std::string, std::string> v = args->value;
    ProtocolState state;
    std::optional<Simulation> sim;
    if (!resume->empty()) {
      sim.emplace(read_checkpoint(*resume, &state));
      // The run goes on with the settings it started with; more cycles may be asked for.
      for (const auto& [key, value] : state.settings) {
        const bool may_change = key == "cycles" || key == "checkpoint-every";
        const auto option = given.find(key);
        if (option != given.end() && option->second->count() && args->value.at(key) != value) {
          if (!may_change) {
            throw Error("--" + key + " " + args->value.at(key) + ": a resumed run keeps its " +
                        "settings (" + value + "); only --cycles and --checkpoint-every change");
          }
          v[key] = args->value.at(key);
          state.settings[key] = v[key];
        } else {
          v[key] = value;
        }
      }
      std::cerr << "resuming " << *resume << " after cycle " << state.cycles_done
                << (state.step_in_cycle ? " (+" + std::to_string(state.step_in_cycle) + " steps)"
                                        : std::string())
                << "\n";
    }
    if (!start_from->empty()) {
      ProtocolState trained;
      sim.emplace(read_checkpoint(*start_from, &trained));
      if (trained.step_in_cycle != 0) {
        throw Error(*start_from +
                    ": written in the middle of a cycle; a new protocol starts "
                    "between cycles (--resume finishes that run)");
      }
      // The packing and its physics are the checkpoint's; the protocol is new.
      for (const char* name : kPackingOptions) {
        const auto it = trained.settings.find(name);
        if (it == trained.settings.end()) {
          throw Error(*start_from + ": has no setting '" + name +
                      "' (was it written by granmem simulate?)");
        }
        const std::string& theirs = it->second;
        if (given.at(name)->count() && args->value.at(name) != theirs) {
          throw Error(std::string("--") + name + " " + args->value.at(name) +
                      ": with --start-from the packing and its physics are the checkpoint's (" +
                      theirs + ")");
        }
        v[name] = theirs;
      }
      v["start-from"] = *start_from;
      state.settings = v;
      std::cerr << "starting from " << *start_from << " (after cycle " << trained.cycles_done
                << " of its run)\n";
    }
    const PhysicsOptions physics = physics_from(v);
    const double box = si(v, "box", Dimension::length);
    const double radius = 0.5 * si(v, "diameter", Dimension::length);
    if (!(box > 0)) throw Error("--box '" + v.at("box") + "': must be positive");
    if (!(radius > 0)) throw Error("--diameter '" + v.at("diameter") + "': must be positive");
    const double polydispersity = number(v, "polydispersity");
    if (!(polydispersity >= 0 && polydispersity < 1)) {
      throw Error("--polydispersity " + v.at("polydispersity") + ": must be in [0, 1)");
    }
    const std::string out = v.at("out");
    std::string checkpoint = v.at("checkpoint");
    if (checkpoint.empty()) {
      const std::filesystem::path o(out);
      checkpoint = (o.parent_path() / (o.stem().string() + ".checkpoint.h5")).string();
      v["checkpoint"] = checkpoint;
    }

    DepositOptions d;
    d.grains = whole(v, "grains");
    d.radius = radius;
    d.polydispersity = polydispersity;
    d.box_side = box;
    d.lid_mass = si(v, "lid-mass", Dimension::mass);
    d.seed = std::uint64_t(whole(v, "seed"));
    d.settled_energy = si(v, "settled-energy", Dimension::energy);
    d.settling_damping = number(v, "settling-damping");
    physics.validate("simulate", d.radius * (1 - d.polydispersity));
    const double box_y = sim ? sim->container().size.y() : box;
    const double lid_mass =
        sim ? (sim->container().lid.present ? sim->container().lid.mass : 0) : d.lid_mass;

    // Every setting is checked before the packing is made.
    CyclicOptions c;
    c.cycles = whole(v, "cycles");
    const std::string& amplitude = v.at("amplitude");
    c.drive.amplitude =
        !amplitude.empty() && amplitude.back() == '%'
            ? number({{"amplitude", amplitude.substr(0, amplitude.size() - 1)}}, "amplitude") /
                  100 * box_y
            : si(v, "amplitude", Dimension::length);
    c.drive.symmetry = parse_drive_symmetry(v.at("drive"));
    c.drive.shape = parse_drive_shape(v.at("wall-motion"));
    if (v.at("period") == "auto") {
      if (!(number(v, "inertial-number") > 0)) {
        throw Error("--inertial-number " + v.at("inertial-number") + ": must be positive");
      }
      // Under the lid the confining pressure is its weight over the box; the lateral stress
      // just beneath it, about half that, is the smallest in the packing. Without a lid, the
      // weight of one layer of grains.
      const double pressure = lid_mass > 0 ? lid_mass * physics.gravity / (box * box)
                                           : physics.density * 0.6 * physics.gravity * 2 * radius;
      const double speed = quasi_static_wall_speed(number(v, "inertial-number"), box_y, 2 * radius,
                                                   0.5 * pressure, physics.density);
      c.drive.period =
          WallDrive::period_for_speed(c.drive.amplitude, speed, c.drive.symmetry, c.drive.shape);
    } else {
      c.drive.period = si(v, "period", Dimension::time);
    }
    c.out = out;
    c.full_compression_frames = yes_no(v, "full-compression");
    std::stringstream track(v.at("track"));
    for (std::string id; std::getline(track, id, ',');) {
      if (id.empty()) continue;
      const Quantity q = parse_quantity(id, "--track");
      if (!q.unit.empty() || q.value != std::floor(q.value)) {
        throw Error("--track '" + v.at("track") + "': expected grain ids, e.g. 3,17,250");
      }
      c.tracked_grains.push_back(std::int64_t(q.value));
    }
    c.samples_per_cycle = whole(v, "samples-per-cycle");
    if (c.tracked_grains.empty() != (c.samples_per_cycle == 0)) {
      throw Error("--track and --samples-per-cycle go together: which grains, and how often");
    }
    {
      // Tracked grains must exist: a new packing's ids are 0 .. grains - 1.
      std::set<std::int64_t> ids;
      if (sim) ids.insert(sim->grains().id.begin(), sim->grains().id.end());
      for (std::int64_t id : c.tracked_grains) {
        const bool exists = sim ? ids.count(id) > 0 : id >= 0 && id < d.grains;
        if (!exists) throw Error("--track: there is no grain " + std::to_string(id));
      }
      std::set<std::int64_t> once(c.tracked_grains.begin(), c.tracked_grains.end());
      if (once.size() != c.tracked_grains.size()) throw Error("--track: a grain is listed twice");
    }
    c.checkpoint = checkpoint;
    c.checkpoint_every = whole(v, "checkpoint-every");
    c.validate(box_y, physics.dt);
    {
      std::vector<std::filesystem::path> outputs{c.out, c.checkpoint};
      if (c.full_compression_frames) outputs.push_back(full_compression_path(c.out));
      if (c.samples_per_cycle > 0) outputs.push_back(in_cycle_path(c.out));
      check_outputs(outputs, *start_from);
    }

    if (!sim) {
      std::cerr << "depositing " << d.grains << " grains (seed " << d.seed << ")\n";
      DepositSummary s;
      sim.emplace(deposit(d, physics, &s, print_deposit_progress(std::cerr)));
      std::cerr << "settled: packing fraction " << s.packing_fraction << ", lid at "
                << s.lid_height * 100 << " cm, " << s.contacts_per_grain << " contacts per grain\n";
      state.settings = v;
    }
    sim->set_threads(*threads);  // 0: by the number of grains
    for (const auto& [key, value] : v)
      c.parameters["simulate/" + key] = value;
    const double steps_per_cycle = std::round(c.drive.period / physics.dt);
    std::cerr << "cycling: A = " << c.drive.amplitude * 100 << " cm, period " << c.drive.period
              << " s (" << std::int64_t(steps_per_cycle) << " steps, peak wall speed "
              << c.drive.peak_speed() * 100 << " cm/s), " << c.cycles << " cycles\n";

    std::signal(SIGINT, request_stop);  // from here on, Ctrl-C writes a checkpoint
    const CyclicSummary summary = run_cycles(
        *sim, c, state,
        [](const CyclicProgress& p) {
          std::cerr << "cycle " << p.cycle << "/" << p.cycles << "  " << std::scientific
                    << std::setprecision(2) << p.particle_steps_per_second << std::defaultfloat
                    << std::setprecision(6) << " particle-steps/s  "
                    << duration_text(p.seconds_left) << " left\n";
        },
        &g_stop);
    if (summary.interrupted) {
      std::cerr << "stopped after cycle " << summary.cycles_done << ": checkpoint " << checkpoint
                << " (continue with --resume " << checkpoint << ")\n";
      std::signal(SIGINT, SIG_DFL);
      throw CLI::RuntimeError(130);
    }
    std::cout << "simulated " << summary.cycles_done << " cycles of " << sim->grains().size()
              << " grains: " << std::scientific << std::setprecision(3)
              << summary.particle_steps_per_second << std::defaultfloat << " particle-steps/s\n";
    for (const auto& p : summary.written)
      std::cout << "wrote " << p.string() << "\n";
    std::cout << "wrote " << checkpoint << "\n";
  });
}

}  // namespace granmem::app
