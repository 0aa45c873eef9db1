#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "granmem/sim/simulate_settings.hpp"

// `simulate`'s options on the command line (text with units, sim/simulate_settings.hpp),
// shared by `simulate` and by `calibrate`, whose simulated twin is a run of `simulate` at
// several frictions.
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

}  // namespace granmem::app
