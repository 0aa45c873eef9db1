#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/calibration/friction_fit.hpp"
#include "granmem/calibration/power_law_fit.hpp"
#include "granmem/core/trajectory_store.hpp"

// The comparison of two runs as `compare` and `calibrate` write it.
namespace granmem {

// Observables of `a` and `b` side by side (observables.csv), their KS and Wasserstein-1
// distances (distances.csv) and the figures: pdfs of end-of-cycle displacements (Fig. 2),
// relaxation with power-law fits (Fig. 3), displacement fields at full compression (Fig. 1;
// at the end of the last cycle when the run has no full-compression store beside it), and
// for simulations one-axis against full rotations (Fig. 6). `b`'s displacements get the
// locating noise `sigma` (voxels, `noise_shape`), as the friction fit sees them. The
// relaxation's power laws are fitted with `relaxation` (the steady state fitted, or held
// at the mean of the last cycles as the paper does); not `b`'s where it was placed after
// cycle `b_placed_after` > 0 (a twin placed from the experiment's frame there relaxes from
// it, not from a preparation before cycle 1: said in the notes).
struct Comparison {
  std::vector<std::filesystem::path> written;
  // quantity (dr, rot_disp) -> KS and Wasserstein-1 (grain diameters) distances
  std::map<std::string, std::pair<double, double>> distances;
  std::vector<std::string> notes;  // what could not be made and why (a power law too short)
  // A line per quantity (medians, distances) and per relaxation fit (its exponent).
  std::string Report() const;

 private:
  friend Comparison compare_runs(const TrajectoryReader&, const TrajectoryReader&,
                                 const std::string&, const std::string&, const ObservableOptions&,
                                 const Eigen::Vector3d&, double, const std::filesystem::path&,
                                 const PowerLawOptions&, std::int64_t);
  std::string report_;
};
Comparison compare_runs(const TrajectoryReader& a, const TrajectoryReader& b,
                        const std::string& label_a, const std::string& label_b,
                        const ObservableOptions& observe, const Eigen::Vector3d& noise_shape,
                        double sigma, const std::filesystem::path& dir,
                        const PowerLawOptions& relaxation = {}, std::int64_t b_placed_after = 0);

// The friction fit's figure: the simulated CDF values at three of the experiment's deciles
// against mu_s, the experiment's values beside them.
// `granmem compare` as a library call: the options as the command takes them, lengths in m.
struct CompareOptions {
  std::string label_a = "A", label_b = "B";  // the runs' names in figures
  // The cycles pooled into the distributions; default default_comparison_window().
  std::optional<std::pair<std::int64_t, std::int64_t>> window;
  std::optional<double> diameter;  // the unit of lengths; default twice a's median radius
  double wall_distance = 0;        // grains nearer a container face left out
  bool subtract_drift = true;
  std::size_t steady_points = 0;  // relaxation: 0 fits the steady state (PowerLawOptions)
  std::filesystem::path dir;      // where the tables and figures go

  // Throws Error naming the option: a window whose first cycle is after its last, a
  // diameter that is not a positive length, a wall distance that is not a length >= 0, no
  // output folder.
  void validate() const;
};
// Validates the options, then compares the runs (compare_runs).
Comparison compare(const TrajectoryReader& a, const TrajectoryReader& b, const CompareOptions& o);

// The window `compare` pools by default: both runs' last 10 common cycles.
std::pair<std::int64_t, std::int64_t> default_comparison_window(const TrajectoryReader& a,
                                                                const TrajectoryReader& b);

std::vector<std::filesystem::path> calibration_figures(const std::filesystem::path& dir,
                                                       const FrictionFit& fit,
                                                       const std::vector<double>& mu);

}  // namespace granmem
