#pragma once

#include <array>
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

// A friction fit on steady-state observables, one panel per observable against mu_s (log):
// the twin's runs (one colour per packing), the trend fitted through them, the
// experiment's value as a band (+- one packing's scatter and the experiment's systematic
// error in quadrature), the fitted mu_s and its 95 %
// interval as a shaded band, and the true mu_s of a pseudo-experiment (NaN: unknown).
struct ObservablePanel {
  std::string label;  // the observable, with its unit
  std::vector<double> run_mu_s, run_value;
  std::vector<int> run_packing;  // 0, 1, ...: the colour
  std::vector<double> curve_mu_s, curve;
  double experiment = 0, experiment_error = 0;
};
// What the key calls the runs' points and the experiment's band.
struct ObservableFitKey {
  std::string runs = "twin runs (colour: packing)";
  std::string experiment = "experiment +- packing, systematic";
};
std::vector<std::filesystem::path> plot_observable_fit(const std::filesystem::path& dir,
                                                       const std::string& name,
                                                       const std::vector<ObservablePanel>& panels,
                                                       double mu_s, std::array<double, 2> ci95,
                                                       double true_mu_s, const std::string& title,
                                                       const ObservableFitKey& key = {});

// Fits of one friction made apart (e.g. one per cycle) against what tells them apart (x):
// each with its error bar, the combined fit as a line, its 95 % interval as a shaded
// band, and the true mu_s of a pseudo-experiment (NaN: unknown) dashed.
std::vector<std::filesystem::path> plot_fits_apart(
    const std::filesystem::path& dir, const std::string& name, const std::vector<double>& x,
    const std::vector<double>& mu_s, const std::vector<double>& error, double fit,
    std::array<double, 2> ci95, double true_mu_s, const std::string& x_label,
    const std::string& title);

// A joint fit of two frictions: the twin's design points, the joint 95 % region's
// boundary, the fit and, for a pseudo-experiment, the truth (NaN: unknown), log-log.
std::vector<std::filesystem::path> plot_joint_region(
    const std::filesystem::path& dir, const std::string& name, const std::vector<double>& run_x,
    const std::vector<double>& run_y, const std::vector<std::array<double, 2>>& region,
    std::array<double, 2> fit, std::array<double, 2> truth, const std::string& title);

}  // namespace granmem
