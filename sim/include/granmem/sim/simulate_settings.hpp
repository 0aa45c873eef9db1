#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "granmem/core/units.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/run_settings.hpp"
#include "granmem/sim/simulation.hpp"
#include "granmem/sim/wall_drive.hpp"

// The settings of a simulated run as text with units (RunSettings: the command line's, a
// config's [simulate], Python's keywords), and what they mean for the DEM: shared by
// `simulate`, by `calibrate`'s twin (runs of `simulate` at several frictions) and by Python.
namespace granmem {

struct OptionSpec {
  const char* name;
  const char* default_value;  // nullptr: the library's struct holds it (PhysicsOptions...)
  const char* help;
};
// The defaults are the paper's table and protocol; default_simulate_settings() has them
// all, those of the physics and the deposit taken from PhysicsOptions and DepositOptions
// (one place for each default).
extern const OptionSpec kSimulateOptions[];
extern const std::size_t kSimulateOptionCount;
// What makes the packing and its physics: fixed for a run, and for runs started from it.
extern const char* const kPackingOptions[];
extern const std::size_t kPackingOptionCount;
// Every option at its default (the settings' text, e.g. "15cm" for DepositOptions'
// 0.15 m box).
RunSettings default_simulate_settings();

// A setting read as a plain number, a quantity in SI (a bare number in `default_unit`), a
// whole number >= 0, or a yes/no; Error naming the option (--name) otherwise.
double setting_number(const RunSettings& v, const std::string& name);
double setting_si(const RunSettings& v, const std::string& name, Dimension d,
                  const char* default_unit = "");
std::int64_t setting_whole(const RunSettings& v, const std::string& name);
bool setting_yes_no(const RunSettings& v, const std::string& name);

PhysicsOptions physics_from(const RunSettings& v);
// The lid's mass: --lid-mass, or (auto) the mass that presses with --lid-pressure on a
// square box of side `box`. A --lid-mass beside a --lid-pressure other than the default is
// refused (the settings are text: the default pressure given explicitly is not told apart).
double lid_mass_from(const RunSettings& v, double box, double gravity);
// The deposition (grains, box, lid, seed, settling); checks the sizes.
DepositOptions deposit_from(const RunSettings& v);
// The wall's drive in a box of depth `box_y` along y and side `box` (the lid's pressure);
// `period auto` is the quasi-static limit of the inertial number.
WallDrive drive_from(const RunSettings& v, const PhysicsOptions& physics, double box, double box_y,
                     double lid_mass, double radius);
// A comma list of whole numbers (grain ids, cycles); `example` shows one in the error.
std::vector<std::int64_t> whole_list(const RunSettings& v, const std::string& name,
                                     const char* example);
// Walls' friction follows the grains' ("same").
bool wall_friction_follows(const RunSettings& v);

}  // namespace granmem
