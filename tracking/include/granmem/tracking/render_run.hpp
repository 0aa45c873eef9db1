#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

#include "granmem/tracking/render.hpp"

namespace granmem {

// `granmem render` as one call: one frame of a trajectory store drawn as a laser-sheet scan
// (render_scan), written as a multi-page TIFF, and its truth as CSV. A run with a container
// (its box) is drawn in one frame for all its frames, the stack's first voxel `margin`
// voxels below the container's lower corner, as a lab's scanner stays put; without, each
// frame's stack is centred on its grains.
struct RenderRunOptions {
  std::filesystem::path run;
  std::int64_t frame = 0;  // the frame's label (its step: cycle or scan)
  std::filesystem::path out;
  std::filesystem::path truth;  // empty: no truth table
  // How to draw (its length_unit and frame are set from the run and `frame`).
  RenderOptions render;
  // The voxel size "X[,Y,Z]<unit>" (--voxel-size), converted to the run's length unit;
  // empty: render.voxel_size, or from diameter_px and the run's median radius (every frame
  // alike).
  std::string voxel_size;
  // The options as the user gave them, in the truth table's comment lines.
  std::map<std::string, std::string> parameters;

  // Throws Error naming the option: no run or --out, a --voxel-size that is not positive
  // sizes, a drawing option out of its range (RenderOptions::validate).
  void validate() const;
};

struct RenderSummary {
  std::filesystem::path run, out, truth;
  std::int64_t frame = 0;
  std::size_t grains = 0;
  std::int64_t nx = 0, ny = 0, nz = 0;
  Eigen::Vector3d voxel_size = Eigen::Vector3d::Zero();
  std::string length_unit;
  int bits = 8;
  bool artefacts = true;
  std::string Report() const;  // what the command line prints
};

// Validates the options, finds the frame (Error naming the frames the run has), draws it and writes
// the scan and the truth: the truth goes to a temporary first and into place only once the scan is
// written, so that both stay as they were if anything fails.
RenderSummary render_run(const RenderRunOptions& options);

}  // namespace granmem
