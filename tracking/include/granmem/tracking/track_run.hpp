#pragma once

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "granmem/tracking/link_run.hpp"
#include "granmem/tracking/locate_scan.hpp"

namespace granmem {

// `granmem track` as one call: every scan located (locate_scan; scan k is frame k), its
// detections kept if asked, the scans linked (link_run) and the run written
// (write_link_run).
struct TrackRunOptions {
  std::vector<std::filesystem::path> scans;  // in scan order
  ScanLocateOptions locate;                  // its frame is set per scan
  std::filesystem::path detections;          // folder for each scan's detections; empty: none
  LinkRunOptions link;
  std::filesystem::path out, report;  // the trajectory store; the unlinked table (optional)
  std::map<std::string, std::string> parameters;  // added to the run's
  std::function<void(const std::string&)> log;    // each scan's line as it is located

  // Throws Error before any scan is located: the link's options (LinkRunOptions), no scan
  // or one that is not there, the locate options (ScanLocateOptions), no --out.
  void validate() const;
};

struct TrackSummary {
  std::vector<LocateSummary> scans;
  LinkRun linked;
  std::vector<std::filesystem::path> written;
  // The link's per-scan table and the files written.
  std::string Report() const;
};

// The file a scan's detections are kept in within `folder`: the scan's name + .h5.
std::filesystem::path detections_path(const std::filesystem::path& folder,
                                      const std::filesystem::path& scan);

// Validates the options (nothing is made before), then throws as locate_scan, link_run and
// write_link_run.
TrackSummary track_run(const TrackRunOptions& options);

}  // namespace granmem
