#pragma once

#include <CLI/CLI.hpp>
#include <memory>
#include <string>
#include <vector>

#include "granmem/core/atomic_file.hpp"
#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/link_run.hpp"
#include "granmem/tracking/locate.hpp"
#include "granmem/tracking/locate_scan.hpp"

// The two steps of the experimental pipeline as the commands run them: `locate` and
// `link` each run one, `track` both.
namespace granmem::app {

struct LocateArgs {
  std::string diameter, voxel_size, dataset, region, polarity = "dark", beam = "x", axis = "fit";
  double hole_fraction = LocateOptions{}.hole_fraction;
  int passes = LocateOptions{}.passes;
  bool no_illumination = false;
};
void add_locate_options(CLI::App* cmd, LocateArgs& args);
// The library's options from the flags.
ScanLocateOptions scan_locate_options(const LocateArgs& args);
// Reads the stack at `path`, locates its grains (printing a line of what it found) and
// labels them scan `frame`.
Detections locate_scan(const std::string& path, const LocateArgs& args, std::int64_t frame);

struct LinkArgs {
  std::string max_displacement = "auto", report, container, container_size, readings;
  int memory = 2;
  std::int64_t first_cycle = 0;
  bool no_drift = false;
};
void add_link_options(CLI::App* cmd, LinkArgs& args);
LinkRunOptions link_run_options(const LinkArgs& args);
// The files linking writes: the store `out`, its XDMF and the --report.
std::vector<NamedPath> link_outputs(const LinkArgs& args, const std::string& out);
// Links the scans (`names` for messages), writes the trajectory store `out` with `cmd`'s
// options as its parameters, and prints the per-scan summary.
void link_and_write(std::vector<Detections> scans, const std::vector<std::string>& names,
                    const LinkArgs& args, const std::string& out, const CLI::App& cmd);

}  // namespace granmem::app
