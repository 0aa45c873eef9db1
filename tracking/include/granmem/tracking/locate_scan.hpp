#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/locate.hpp"
#include "granmem/tracking/stack.hpp"

// `granmem locate` (and the first step of `granmem track`) as a library call: a scan read
// from its file (or a region of it) and its grains located.
namespace granmem {

struct ScanLocateOptions {
  StackReadOptions read;   // dataset, region, a voxel size replacing the file's
  std::string diameter;    // "12", "12vox" (voxels along x) or a length ("1.5mm")
  LocateOptions locate;    // its diameter is set from `diameter` and the stack
  std::int64_t frame = 0;  // the scan's index, in the detections' frame column

  // Throws Error naming the option: a diameter that is not positive voxels or a length,
  // a locate setting out of its range (LocateOptions::validate). A length is turned into
  // voxels, and checked against the stack's voxel size, as each stack is read.
  void validate() const;
};

struct LocatedScan {
  Detections detections;  // positions in the whole stack's frame (a region's shifted back)
  LocateSummary summary;
  std::int64_t voxels = 0;
  // A line of what was found, how fast, in which unit.
  std::string Report() const;
};

// Validates the options, reads the scan and locates its grains.
LocatedScan locate_scan(const std::filesystem::path& path, const ScanLocateOptions& options);

}  // namespace granmem
