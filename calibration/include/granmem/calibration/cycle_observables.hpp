#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/rotation/grain_motion.hpp"
#include "granmem/rotation/packing_structure.hpp"

namespace granmem {

// The paper's observables of a run, experimental or simulated, computed the same way for
// both: what the friction fit and the comparison read.
struct ObservableOptions {
  // Drift removal, wall exclusion, hole-contact policy (the paper leaves grains locked
  // through their hole out of the rotations).
  MotionOptions motion{false, 0, std::nullopt, HoleContactPolicy::exclude_rotations};
  // Cycles (frame labels) whose end-of-cycle displacements c-1 -> c are pooled, inclusive;
  // the paper pools 10 cycles after 500. Default (0, 0): every cycle of the run.
  std::pair<std::int64_t, std::int64_t> window{0, 0};
  // Grain diameter, m: the unit of every length below, and the lever arm of rotational
  // displacements (angle times d/2, the same for every grain, so that a fitted radius a few
  // percent off does not bias them). 0: twice the run's median grain radius.
  double diameter = 0;
  bool rotations = true;  // rotational displacements (an error if the run has no axes)
  // rad: a scan's error in each hole axis, added to the run's axes before the rotations are
  // measured (a simulation's axes are exact, a scan's are not, and the error adds to every
  // measured rotation): the standard deviation of the axis' tilt in each direction across
  // it. 0: none.
  double axis_noise = 0;
  // m: a scan's locating error along x, y and z, added to every frame's positions (each
  // frame its own draws) before the displacements are measured: how far such an error
  // moves them (calibrate's noise check). Zero: none.
  Eigen::Vector3d position_noise = Eigen::Vector3d::Zero();
};

// Lengths in grain diameters.
struct CycleObservables {
  double diameter = 0;  // m, the length unit below
  std::pair<std::int64_t, std::int64_t> window{0, 0};
  // End-of-cycle translational displacements pooled over the window, one per grain per
  // cycle, with the grain (index into the run) each belongs to: grains are the units of
  // the bootstrap, their cycles being correlated.
  Vectors3 displacement;
  std::vector<double> dr;
  std::vector<std::size_t> dr_grain;
  std::vector<std::int64_t> dr_cycle;  // the cycle c of each (displacement c-1 -> c)
  // Single-axis rotational displacements (angle between the cavity axes times d/2),
  // pooled likewise; empty when not asked for.
  std::vector<double> rot_disp;
  std::vector<std::size_t> rot_grain;
  // Runs with orientations (simulations): the full rotation angle times d/2, pooled
  // likewise, beside the single-axis one (the paper's Fig. 6).
  std::vector<double> full_rot_disp;
  // Every cycle of the run: mean displacement from the previous end-of-cycle frame.
  std::vector<std::int64_t> cycle;
  std::vector<double> mean_dr, mean_rot_disp;  // NaN where no grain was measured
  std::size_t grains = 0;                      // grains in the run
};

// Throws Error (naming the file) for a run without physical lengths (voxels without a
// voxel size), a window the run does not hold, or rotations asked of a run without axes.
CycleObservables cycle_observables(const TrajectoryReader& run, const ObservableOptions& options);

// The displacement field at full compression: every grain's displacement and single-axis
// rotational displacement from the end of cycle c - 1 to full compression in cycle c, and
// its position at full compression (lengths in diameters). `end_of_cycle` is the run,
// `full_compression` the store of its frames at full compression (same grains).
struct DisplacementField {
  std::int64_t cycle = 0;
  Vectors3 position;             // at full compression, in diameters from the run's origin
  std::vector<double> dr;        // in diameters
  std::vector<double> rot_disp;  // in diameters; NaN where not measured
};
DisplacementField full_compression_field(const TrajectoryReader& end_of_cycle,
                                         const TrajectoryReader& full_compression,
                                         std::int64_t cycle, const ObservableOptions& options);

// The steady state of a run over the window of `observed` (cycle_observables of the same
// run): the window means of what carries friction (docs/CALIBRATION.md), measured alike in
// scans and simulations, then the store's own observables where it has them:
//   rot_disp                     single-axis rotational displacement, diameters (axes)
//   bulk_packing_fraction        from positions (packing_structure.hpp)
//   coordination                 from positions
//   height_packing_fraction      from positions: the whole packing's height and the
//                                container's cross-section (the run's box; NaN without)
//   packing_fraction             from the lid height (simulations; the store's)
//   wall_force_full_compression  N (the store's)
//   wall_force_unloaded          N: the store's wall force at each cycle's end, the wall back
//                                at its start (the packing's lateral stress once unloaded)
// and, for a twin placed before the frame before the window (add_height_before_window):
//   height_packing_fraction_before_window   that frame's height_packing_fraction
struct SteadyState {
  std::vector<std::string> names;
  std::vector<double> values;
  // Each one's change across the window (its least-squares slope per cycle times the
  // window's cycles): a steady state's is within the scatter of one packing's value.
  std::vector<double> drift;
  // An experiment's: each value's standard error beyond one packing's scatter, what the twin
  // cannot reproduce of how it was measured (a placed twin's read back at its frame). Empty:
  // none.
  std::vector<double> systematic;
  // The value of `name`, NaN when the run has none.
  double operator[](const std::string& name) const;
  double drift_of(const std::string& name) const;
  double systematic_of(const std::string& name) const;  // 0 where none
};
// What is known of a packing's grains beyond what a scan locates.
struct KnownGrains {
  // m: every grain's radius, for grains known to be alike; the structure is measured at it
  // instead of the store's radii (a scan's located radii are biased by its blur and
  // threshold, and a packing fraction goes as r^3).
  std::optional<double> radius;
  // How many grains the packing holds: a scan that misses some (dim, blurred, at the far
  // side of the beam) would read a looser packing from its height, 1/N per grain missed.
  std::optional<std::size_t> count;
};
// A scan's locating error, given to a simulation's exact positions before the observables
// from positions are measured (as its axes get the scan's axis error): its standard
// deviation along x, y and z, in the run's length unit, and the seed of its draws. Zero: the
// positions as stored.
struct PositionNoise {
  Eigen::Vector3d sigma = Eigen::Vector3d::Zero();
  std::uint64_t seed = 1;
};
SteadyState steady_state(const TrajectoryReader& run, const CycleObservables& observed,
                         const StructureOptions& structure = {}, const KnownGrains& known = {},
                         const PositionNoise& noise = {});

// Cycles, inclusive; (0, 0): every cycle.
using CycleRange = std::pair<std::int64_t, std::int64_t>;

// The same observables cycle by cycle, of which steady_state() takes a window's means: to
// look for where a run has become steady (steady_window.hpp).
struct ObservableSeries {
  struct Entry {
    std::string name;
    std::vector<std::int64_t> cycle;
    std::vector<double> value;  // NaN where not measured
    bool always = false;        // in the window's means even when the window has no value
  };
  std::vector<Entry> entries;
};
ObservableSeries observable_series(const TrajectoryReader& run, const CycleObservables& observed,
                                   const StructureOptions& structure = {},
                                   const KnownGrains& known = {}, CycleRange cycles = {0, 0},
                                   const PositionNoise& noise = {});
SteadyState window_means(const ObservableSeries& series, CycleRange window);
// How far locating noise moves the observables from positions (bulk and height packing
// fractions, coordination): their window means with every position moved by a further
// normal error of `sigma` along x, y and z (the run's length unit), minus as measured. On a
// scan, with sigma its own standard errors, what its noise has already done to them: a
// contact count within a small gap, for one, falls as noise opens touching pairs. No drift.
SteadyState structure_noise_effect(const TrajectoryReader& run, CycleRange window,
                                   const Eigen::Vector3d& sigma,
                                   const StructureOptions& structure = {},
                                   const KnownGrains& known = {}, std::uint64_t seed = 1);
// The index of the run's frame of `cycle`, if it has one.
std::optional<std::size_t> frame_of_cycle(const TrajectoryReader& run, std::int64_t cycle);
// The observables from positions (bulk and height packing fractions, coordination) of the
// run's frame of `cycle`, its positions moved by `noise`: a placed twin's packing read back
// against the experiment's frame it was placed from. Throws Error if the run has no frame of
// that cycle.
SteadyState frame_structure(const TrajectoryReader& run, std::int64_t cycle,
                            const StructureOptions& structure = {}, const KnownGrains& known = {},
                            const PositionNoise& noise = {});
// A twin placed from an earlier frame than the one before the window (the scans'
// preparation) and the experiment share that start, and the packing's chaos grows with the
// cycles from it: its height at the frame before the window carries the compaction so far
// with less of the chaos than the window's mean does (docs/CALIBRATION.md, "The packing's
// height before the window"). Appends that frame's height_packing_fraction to `s` as
// "height_packing_fraction_before_window" (no drift); Error if the run has no such frame.
void add_height_before_window(SteadyState& s, const TrajectoryReader& run, std::int64_t cycle,
                              const KnownGrains& known = {}, const PositionNoise& noise = {});
// The observable from positions a steady-state name reads at another frame
// ("height_packing_fraction" for "height_packing_fraction_before_window"); the name itself
// for the rest.
std::string structure_read_as(const std::string& name);
// What a steady-state observable is, with its unit, for tables and figures ("wall force at
// full compression (N)"); the name itself for one it does not know.
std::string steady_state_label(const std::string& name);

// Twice the median finite grain radius of the run, m (Error if it has none).
double median_diameter(const TrajectoryReader& run);

// Metres per unit of the run's positions; Error for voxels without a voxel size, whose
// lengths are not comparable with anything (slices are often coarser than pixels).
double metres_per_length(const TrajectoryReader& run);

}  // namespace granmem
