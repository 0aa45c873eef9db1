#pragma once

#include <map>

#include <filesystem>

#include <optional>
#include <string>
#include <vector>

#include "granmem/core/table.hpp"
#include "granmem/core/trajectories.hpp"
#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/link.hpp"

// `granmem link` (and the second step of `granmem track`) as a library call: the scans'
// detections linked into a run in the container's frame, with what could not be linked.
namespace granmem {

struct LinkRunOptions {
  // In the detections' unit ("0.4"), or with a unit ("0.4mm"); "auto": 0.7 median diameter.
  std::string max_displacement = "auto";
  int memory = LinkOptions{}.memory;
  bool collective_motion = true;  // the drift, uniform deformation and local field
  // The container in the scans' frame, "xmin,ymin,zmin,xmax,ymax,zmax<unit>", or its edges
  // "LX,LY,LZ<unit>" (its position found from the packing's extent in the first scan):
  // positions are then stored in its frame and it is the run's box. Empty: neither.
  std::string container, container_size;
  // The cycle at whose end the first scan was taken, when the scans do not say theirs: the
  // scans are then frames first_cycle, first_cycle + 1, ... (e.g. the last 10 of 500).
  std::int64_t first_cycle = 0;
  // The apparatus' readings beside the scans (a load cell's force on the driven wall, cycle
  // by cycle: core/apparatus_readings.hpp), stored as the run's observables. Empty: none.
  std::filesystem::path readings;
  // A line per scan as it is linked, and a flag that stops between two (LinkOptions).
  std::function<void(const std::string&)> log;
  const std::atomic<bool>* stop = nullptr;

  // Checks what can be checked before any scan is read (Error naming the option).
  void validate() const;
};

struct LinkRun {
  Trajectories run;
  LinkSummary summary;
  std::vector<Detections> scans;       // as linked (frames numbered)
  std::optional<Box> found_container;  // from container_size
  // The scans' point the run's positions are measured from: the container's lower corner
  // (zero without a container).
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  std::vector<std::string> notes;  // scans renumbered, the container found
  // The per-scan table the command line prints.
  std::string Report() const;
};

// Links `scans` (`names` name them in messages; in scan order). Scans that all say one
// frame (each located alone) are numbered 0, 1, ... in the order given; all must share a
// length unit.
LinkRun link_run(std::vector<Detections> scans, const std::vector<std::string>& names,
                 const LinkRunOptions& options);

// What could not be linked, one row per event: a track seen in the scan before and not
// found in this one (lost = 1, at its last position, detection -1), or a detection of this
// scan starting a new track (lost = 0). Columns frame, particle, detection, lost, x, y, z,
// positions in the run's frame.
Table unlinked_table(const LinkRun& linked);

// Writes the linked run as a trajectory store `out` (with its XDMF sidecar; `parameters`
// added to the run's) and, if `report` is not empty, the unlinked table as CSV: all under
// temporary names, renamed into place together at the end. Returns the files written.
std::vector<std::filesystem::path> write_link_run(
    const LinkRun& linked, const std::filesystem::path& out, const std::filesystem::path& report,
    const std::map<std::string, std::string>& parameters);

}  // namespace granmem
