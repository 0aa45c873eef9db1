#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <string>

#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem {

struct LocateOptions {
  double diameter = 0;         // grain diameter in voxels along x (the pixel size); required
  bool dark_grains = true;     // bright fluid, dark grains with bright holes
  double hole_fraction = 0.3;  // hole diameter over grain diameter; 0: no hole
  bool correct_illumination = true;
  int beam_axis = 0;  // the laser's path: 0 along x, 1 along y
  // The hole's axis: fitted with the model (with a hole), or, without, the lab's classical
  // estimate (hole_axis.hpp). A fitted axis whose standard error exceeds the limit is not
  // seen (NaN): the hole is blocked or too dim. Its axis_quality is 1 / (1 + error/deg).
  bool fit_axis = true;
  double max_axis_sigma_degrees = 10;
  double min_contrast = 0.4;      // fitted fluid - grain level, normalised; below: rejected
  double radius_tolerance = 0.3;  // fitted radius within (1 +- this) x the nominal
  // Model fits of every grain; from the second on, the neighbours are in the model. Each
  // pass moves a grain less, as its neighbours' fits settle: 4 (at 8 voxels per diameter
  // the RMS error falls ~25 % from 3 to 4).
  int passes = 4;
  // Searches of what the found grains leave unexplained, for grains the candidates missed;
  // each is followed by a pass over the new grains and their neighbours.
  int search_rounds = 4;

  // What locate is doing, a line per stage (illumination, candidates, each pass of fits,
  // the axes), and a flag (a signal handler's, Python's Ctrl-C) that stops it between two
  // stages with Error "locate: stopped ...".
  std::function<void(const std::string&)> log;
  const std::atomic<bool>* stop = nullptr;

  // Throws Error naming the first option out of its range (locate() calls it first).
  void validate() const;
};

struct LocateSummary {
  std::size_t candidates = 0, located = 0, rejected = 0, on_edge = 0;
  // Wall-clock time in total and in each stage: illumination, candidates, model fits.
  double seconds = 0, seconds_illumination = 0, seconds_candidates = 0, seconds_fits = 0;
};

// Every grain of a scan: candidates from the smoothed grain fraction (candidates.hpp), then
// a blurred holed sphere fitted to each grain's voxels with Ceres (grain_fit.hpp): first
// with the voxels nearer another candidate left out, then with the neighbours' fitted
// spheres in the model, since in a dense packing neighbours touch and would otherwise pull
// the fit. Centroids are biased there and lock on the voxel grid; the model fit is not.
// Grains the candidates missed are searched for in what the found ones leave unexplained.
// Last, each hole's axis is refitted on the grain's inner voxels with a blur of its own
// along z (hole_axis.hpp), and grains touching a neighbour through their hole are flagged
// (hole_contacts.hpp); the refits, on the exactly blurred image, also measure how much the
// model fits' radius runs small (the blurred surface's curvature), and the radii are
// corrected by it (grains with holes). Then each centre is fitted once more with its
// neighbours seen through the exactly blurred image at the scan's blur, their grain
// fractions added to its own: the model fits' product of what they leave clear reads the
// rims touching grains share too bright and pulls each centre towards its neighbours
// (docs/BENCHMARKS.md). Works on its own copy of `stack` (normalised,
// illumination.hpp): move a stack in that is not needed after. Positions, radii in the
// stack's unit when it has a voxel size, else in voxels; anisotropic voxels handled
// throughout.
Detections locate(Stack stack, const LocateOptions& options, LocateSummary* summary = nullptr);

// The grain diameter in voxels along x from "12", "12 vox" (or px), or a length ("1.5mm")
// with the stack's voxel size; Error naming `what` (the option) otherwise.
double diameter_in_voxels(const std::string& text, const Stack& stack, const std::string& what);
// What diameter_in_voxels checks before it needs the stack: a positive diameter in voxels
// or with a length unit (Error naming `what`).
void check_diameter(const std::string& text, const std::string& what);

}  // namespace granmem
