#include <iostream>

#include "commands.hpp"
#include "granmem/core/run_info.hpp"

namespace granmem::app {

void add_info(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  CLI::App* cmd = app.add_subcommand("info", "Print what a trajectory store holds");
  cmd->add_option("file", *path, "trajectory store (.h5)")->required()->check(CLI::ExistingFile);
  cmd->callback([path] { std::cout << run_info(*path); });
}

}  // namespace granmem::app
