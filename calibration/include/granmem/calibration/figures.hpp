#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "granmem/calibration/power_law_fit.hpp"

namespace granmem {

// The comparison's figures, drawn by gnuplot (Debian's gnuplot-nox): each figure's data
// (`<name>.dat`) and script (`<name>.gp`) are written beside its PNG and SVG, so that a
// user can restyle it and draw it again with `gnuplot <name>.gp`. Throws Error when
// gnuplot is missing or fails. Every function returns the files written.

struct Sample {
  std::string label;
  std::vector<double> values;  // NaN and values <= 0 are left out of log-binned pdfs
};

// Probability densities of the samples in common logarithmic bins, on log-log axes (the
// paper's Fig. 2 and 6).
std::vector<std::filesystem::path> plot_log_pdfs(const std::filesystem::path& dir,
                                                 const std::string& name,
                                                 const std::vector<Sample>& samples,
                                                 const std::string& x_label,
                                                 const std::string& title, int bins = 25);

struct Relaxation {
  std::string label;
  std::vector<double> cycle, mean;  // mean displacement per cycle
  PowerLawFit fit;
};
// Mean displacement per cycle minus the fitted steady state against the cycle, log-log,
// with the fitted power laws (the paper's Fig. 3).
std::vector<std::filesystem::path> plot_relaxation(const std::filesystem::path& dir,
                                                   const std::string& name,
                                                   const std::vector<Relaxation>& runs,
                                                   const std::string& y_label,
                                                   const std::string& title);

// Grains at (y, z) coloured by a magnitude (the paper's Fig. 1): one panel per field,
// side by side, on one colour scale.
struct Field {
  std::string title;
  std::vector<double> y, z, value;
};
std::vector<std::filesystem::path> plot_fields(const std::filesystem::path& dir,
                                               const std::string& name,
                                               const std::vector<Field>& panels,
                                               const std::string& axis_label,
                                               const std::string& value_label);

// Lines y(x) with optional error bars and log x (the calibration curves).
struct Curve {
  std::string label;
  std::vector<double> x, y, error;  // error empty: no bars
  bool points = true;               // points, or a line
};
std::vector<std::filesystem::path> plot_curves(
    const std::filesystem::path& dir, const std::string& name, const std::vector<Curve>& curves,
    const std::string& x_label, const std::string& y_label, const std::string& title, bool log_x);

}  // namespace granmem
