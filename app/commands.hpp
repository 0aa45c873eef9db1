#pragma once

#include <CLI/CLI.hpp>
#include <map>
#include <string>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/rotation/motion_analysis.hpp"

// The `granmem` subcommands. Each registers its options on `app`; its callback maps them
// onto a library options struct, calls the library and prints the summary.
namespace granmem::app {

void add_import(CLI::App& app);
void add_info(CLI::App& app);
void add_analyze(CLI::App& app);
void add_export(CLI::App& app);
// Returns its settings, which `calibrate` reads for the simulated twin.
struct SimulateSettings;
SimulateSettings add_simulate(CLI::App& app);
void add_calibrate(CLI::App& app, const SimulateSettings& twin);
void add_compare(CLI::App& app);
void add_readout(CLI::App& app);
void add_locate(CLI::App& app);
void add_track(CLI::App& app);
void add_render(CLI::App& app);
void add_link(CLI::App& app);

// `granmem analyze`'s work once its options are read: analyses `run`, writes the tables to
// `out` with `used` as their parameters, prints the notes and the per-frame summary.
void analyze_and_report(const TrajectoryReader& run, const AnalysisOptions& options,
                        const std::string& out, const std::map<std::string, std::string>& used);

// The packing's drift (its mean displacement, frame by frame), one pair of flags in every
// command that has it: --subtract-drift removes it, --keep-drift keeps it; `subtract`
// holds the command's default when called.
void add_drift_flags(CLI::App* command, bool& subtract);

// --readings FILE.csv, the apparatus' readings beside the scans or tracks (import, link,
// track: core/apparatus_readings.hpp).
void add_readings_option(CLI::App* command, std::string& readings);

// The options of a subcommand as actually used (given or default), "<command>/<option>"
// -> value, for the output's /parameters.
std::map<std::string, std::string> used_options(const CLI::App& command);

}  // namespace granmem::app
