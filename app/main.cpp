#include <exception>
#include <iostream>
#include <string>

#include "commands.hpp"
#include "git_commit.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/version.hpp"
#include "simulation_settings.hpp"

namespace {

// CLI11 says "INI was not able to parse X" for every config line it could not use: a
// section header without its ']', a line without '=', or an option no command has.
std::string config_error(const std::string& what) {
  const std::string prefix = "INI was not able to parse ";
  if (what.rfind(prefix, 0) != 0) return what;
  std::string line = what.substr(prefix.size());
  if (!line.empty() && line.front() == '[') {
    return "--config: '" + line + "' is not a [command] header (no closing ']')";
  }
  const std::size_t space = line.find(' ');
  if (space != std::string::npos) {
    const std::size_t dot = line.rfind('.', space);  // CLI11 writes section.key
    const std::string section = dot == std::string::npos ? "" : line.substr(0, dot);
    const std::string text = line.substr(dot == std::string::npos ? 0 : dot + 1);
    return "--config: '" + text + "'" + (section.empty() ? "" : " in [" + section + "]") +
           " is not 'option = value'";
  }
  return "--config: no option " + line + " ([command] option)";
}

// Options whose value is a comma list take a TOML array too: `mu-s = [0.05, 0.2]` in the
// config is `--mu-s 0.05,0.2` (CLI11 splits both at commas and joins the items again).
void accept_toml_arrays(CLI::App& app) {
  for (const char* name :
       {"--mu-s", "--mu-r", "--amplitudes", "--pdf", "--only", "--voxel-size", "--container",
        "--container-size", "--region", "--columns", "--noise", "--streaks"}) {
    for (CLI::App* command : app.get_subcommands({})) {
      if (CLI::Option* o = command->get_option_no_throw(name)) {
        o->delimiter(',')->multi_option_policy(CLI::MultiOptionPolicy::Join);
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"granmem: tracked grains and DEM runs of cyclically compressed packings"};
  app.set_version_flag("--version", std::string("granmem ") + granmem::kVersion + " (commit " +
                                        granmem::kGitCommit + ")");
  app.set_config("--config", "", "TOML file of options, one [section] per command");
  app.add_option("--author",
                 "who made the files: recorded in every store written "
                 "(H5MD /h5md/author; default the login name)")
      ->each([](const std::string& name) { granmem::set_default_author(name); });
  app.require_subcommand(1);
  app.fallthrough();                                        // --config may follow the command name
  app.allow_config_extras(CLI::config_extras_mode::error);  // a mistyped key is an error
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return "granmem: error: " + config_error(e.what()) + " (see granmem --help)\n";
  });
  granmem::app::add_import(app);
  granmem::app::add_info(app);
  granmem::app::add_analyze(app);
  granmem::app::add_export(app);
  const granmem::app::SimulateSettings twin = granmem::app::add_simulate(app);
  granmem::app::add_calibrate(app, twin);
  granmem::app::add_readout(app);
  granmem::app::add_compare(app);
  granmem::app::add_locate(app);
  granmem::app::add_track(app);
  granmem::app::add_render(app);
  granmem::app::add_link(app);
  accept_toml_arrays(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0, an interrupted run (a CLI::RuntimeError, which prints
    // nothing) with its own code, a usage error 2 as Unix tools do.
    const int code = app.exit(e);
    const bool usage_error = code != 0 && dynamic_cast<const CLI::RuntimeError*>(&e) == nullptr;
    return usage_error ? 2 : code;
  } catch (const std::exception& e) {
    std::cerr << "granmem: error: " << granmem::one_printable_line(e.what()) << "\n";
    return 1;
  }
  return 0;
}
