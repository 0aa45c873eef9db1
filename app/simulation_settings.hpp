#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "granmem/core/units.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/simulation.hpp"
#include "granmem/sim/wall_drive.hpp"

// The settings of a simulated run as `granmem simulate` takes them (text with units), and
// what they mean for the library: shared by `simulate` and by `calibrate`, whose simulated
// twin is a run of `simulate` at several frictions.
namespace granmem::app {

// Every option as text, as given or defaulted: it is parsed with its unit, stored in the
// checkpoint, and read back from it on --resume.
struct SimulateArgs {
  std::map<std::string, std::string> value;  // option name -> text
};

// `simulate`'s settings as the command line or the config's [simulate] section gave them:
// read by `calibrate` for its twin.
struct SimulateSettings {
  std::shared_ptr<SimulateArgs> args;
  std::map<std::string, CLI::Option*> given;
};

struct OptionSpec {
  const char* name;
  const char* default_value;
  const char* help;
};
// The defaults are the paper's table and protocol.
extern const OptionSpec kSimulateOptions[];
extern const std::size_t kSimulateOptionCount;
// What makes the packing and its physics: fixed for a run, and for runs started from it.
extern const char* const kPackingOptions[];
extern const std::size_t kPackingOptionCount;

double number(const std::map<std::string, std::string>& v, const std::string& name);
double si(const std::map<std::string, std::string>& v, const std::string& name, Dimension d,
          const char* default_unit = "");
std::int64_t whole(const std::map<std::string, std::string>& v, const std::string& name);
bool yes_no(const std::map<std::string, std::string>& v, const std::string& name);

PhysicsOptions physics_from(const std::map<std::string, std::string>& v);
// The lid's mass: --lid-mass, or (auto) the mass that presses with --lid-pressure on a
// square box of side `box`. A --lid-mass beside a --lid-pressure other than the default is
// refused (the settings are text: the default pressure given explicitly is not told apart).
double lid_mass_from(const std::map<std::string, std::string>& v, double box, double gravity);
// The deposition (grains, box, lid, seed, settling); checks the sizes.
DepositOptions deposit_from(const std::map<std::string, std::string>& v);
// The wall's drive in a box of depth `box_y` along y and side `box` (the lid's pressure);
// `period auto` is the quasi-static limit of the inertial number.
WallDrive drive_from(const std::map<std::string, std::string>& v, const PhysicsOptions& physics,
                     double box, double box_y, double lid_mass, double radius);
// A comma list of whole numbers (grain ids, cycles); `example` shows one in the error.
std::vector<std::int64_t> whole_list(const std::map<std::string, std::string>& v,
                                     const std::string& name, const char* example);
// Walls' friction follows the grains' ("same").
bool wall_friction_follows(const std::map<std::string, std::string>& v);

}  // namespace granmem::app
