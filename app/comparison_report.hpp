#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/calibration/friction_fit.hpp"
#include "granmem/calibration/power_law_fit.hpp"
#include "granmem/core/trajectory_store.hpp"

// The comparison of two runs as `compare` and `calibrate` write it.
namespace granmem::app {

// Observables of `a` and `b` side by side (observables.csv), their KS and Wasserstein-1
// distances (distances.csv) and the figures: pdfs of end-of-cycle displacements (Fig. 2),
// relaxation with power-law fits (Fig. 3), displacement fields at full compression (Fig. 1;
// at the end of the last cycle when the run has no full-compression store beside it), and
// for simulations one-axis against full rotations (Fig. 6). `b`'s displacements get the
// locating noise `sigma` (voxels, `noise_shape`), as the friction fit sees them. The
// relaxation's power laws are fitted with `relaxation` (the steady state fitted, or held
// at the mean of the last cycles as the paper does). Prints a line per quantity.
struct Comparison {
  std::vector<std::filesystem::path> written;
  // quantity (dr, rot_disp) -> KS and Wasserstein-1 (grain diameters) distances
  std::map<std::string, std::pair<double, double>> distances;
};
Comparison compare_runs(const TrajectoryReader& a, const TrajectoryReader& b,
                        const std::string& label_a, const std::string& label_b,
                        const ObservableOptions& observe, const Eigen::Vector3d& noise_shape,
                        double sigma, const std::filesystem::path& dir,
                        const PowerLawOptions& relaxation = {});

// The friction fit's figure: the simulated CDF values at three of the experiment's deciles
// against mu_s, the experiment's values beside them.
std::vector<std::filesystem::path> calibration_figures(const std::filesystem::path& dir,
                                                       const FrictionFit& fit,
                                                       const std::vector<double>& mu);

}  // namespace granmem::app
