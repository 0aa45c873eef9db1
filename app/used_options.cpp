#include "commands.hpp"

namespace granmem::app {

std::map<std::string, std::string> used_options(const CLI::App& command) {
  std::map<std::string, std::string> used;
  for (const CLI::Option* opt : command.get_options()) {
    const std::string name =
        opt->get_lnames().empty() ? opt->get_name() : opt->get_lnames().front();
    if (name == "help" || name.empty()) continue;
    std::string value;
    if (opt->count() > 0) {
      for (const std::string& r : opt->results())
        value += (value.empty() ? "" : ",") + r;
    } else {
      value = opt->get_default_str();
    }
    used[command.get_name() + "/" + name] = value;
  }
  return used;
}

void add_drift_flags(CLI::App* command, bool& subtract) {
  command->add_flag("--subtract-drift,!--keep-drift", subtract,
                    std::string("remove the packing's mean displacement, frame by frame, or keep "
                                "it (default: ") +
                        (subtract ? "subtracted" : "kept") + ")");
}

void add_readings_option(CLI::App* command, std::string& readings) {
  command->add_option("--readings", readings,
                      "CSV of the apparatus' readings, cycle by cycle: columns cycle and "
                      "wall_force_full_compression and/or wall_force_unloaded (N, the "
                      "packing's force on the driven wall), stored with the tracks for "
                      "calibrate");
}

}  // namespace granmem::app
