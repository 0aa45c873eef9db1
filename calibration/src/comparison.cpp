#include "granmem/calibration/comparison.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "granmem/calibration/distribution_distance.hpp"
#include "granmem/calibration/figures.hpp"
#include "granmem/calibration/power_law_fit.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/table.hpp"
#include "granmem/sim/cyclic_protocol.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;

// The displacement field at full compression of the window's last cycle, from the store
// of full-compression frames beside the run; without one, from the end of that cycle.
DisplacementField field_of(const TrajectoryReader& run, const ObservableOptions& o,
                           std::string* what) {
  const fs::path full = full_compression_path(run.file_name());
  const std::int64_t cycle = o.window.second;
  if (fs::exists(full)) {
    *what = "full compression, cycle " + std::to_string(cycle);
    return full_compression_field(run, TrajectoryReader(full), cycle, o);
  }
  *what = "end of cycle " + std::to_string(cycle);
  return full_compression_field(run, run, cycle, o);
}

// The relaxation's power law, or nothing (with a note) when the run is too short for it.
bool relaxation_of(const std::string& label, const std::vector<std::int64_t>& cycle,
                   const std::vector<double>& mean, const PowerLawOptions& options,
                   std::vector<Relaxation>* out, std::vector<std::string>* notes) {
  Relaxation r;
  r.label = label;
  for (std::size_t k = 0; k < cycle.size(); ++k) {
    r.cycle.push_back(double(cycle[k]));
    r.mean.push_back(mean[k]);
  }
  try {
    r.fit = fit_power_law(r.cycle, r.mean, {}, options);
  } catch (const Error& e) {
    notes->push_back("no power law for " + label + ": " + e.what());
    return false;
  }
  out->push_back(std::move(r));
  return true;
}

}  // namespace

Comparison compare_runs(const TrajectoryReader& a, const TrajectoryReader& b,
                        const std::string& label_a, const std::string& label_b,
                        const ObservableOptions& observe, const Eigen::Vector3d& noise_shape,
                        double sigma, const fs::path& dir, const PowerLawOptions& relaxation,
                        std::int64_t b_placed_after) {
  ObservableOptions oa = observe, ob = observe;
  oa.rotations = a.header().has_axis || a.header().has_orientation;
  ob.rotations = b.header().has_axis || b.header().has_orientation;
  if (!a.header().box) oa.motion.wall_distance = 0;
  if (!b.header().box) ob.motion.wall_distance = 0;
  const CycleObservables x = cycle_observables(a, oa);
  CycleObservables y = cycle_observables(b, ob);
  y.dr = noisy_dr(y, noise_shape, sigma, 8);
  fs::create_directories(dir);

  // Distances and summaries, quantity by quantity.
  Table t;
  Column& quantity = t.add("quantity");
  Column& na = t.add("n_a", "", true);
  Column& nb = t.add("n_b", "", true);
  Column& mean_a = t.add("mean_a", "d");
  Column& mean_b = t.add("mean_b", "d");
  Column& median_a = t.add("median_a", "d");
  Column& median_b = t.add("median_b", "d");
  Column& ks = t.add("ks");
  Column& ks_p = t.add("ks_p");
  Column& w1 = t.add("wasserstein1", "d");
  std::vector<std::string> names;
  Comparison result;
  std::ostringstream report;
  auto compare = [&](const std::string& name, const std::vector<double>& u,
                     const std::vector<double>& v) {
    if (u.empty() || v.empty()) return;
    const Summary su = summarize(u), sv = summarize(v);
    const double d = ks_distance(u, v);
    names.push_back(name);
    quantity.values.push_back(double(names.size()));
    na.values.push_back(double(su.count));
    nb.values.push_back(double(sv.count));
    mean_a.values.push_back(su.mean);
    mean_b.values.push_back(sv.mean);
    median_a.values.push_back(su.median);
    median_b.values.push_back(sv.median);
    ks.values.push_back(d);
    ks_p.values.push_back(ks_p_value(d, su.count, sv.count));
    w1.values.push_back(wasserstein1_distance(u, v));
    result.distances[name] = {d, w1.values.back()};
    report << std::setprecision(3) << std::setw(10) << name << ": median " << su.median << " vs "
           << sv.median << " d, KS " << d << ", Wasserstein-1 " << w1.values.back() << " d\n";
  };
  compare("dr", x.dr, y.dr);
  compare("rot_disp", x.rot_disp, y.rot_disp);
  std::string legend = "quantity: ";
  for (std::size_t k = 0; k < names.size(); ++k)
    legend += (k ? ", " : "") + std::to_string(k + 1) + " = " + names[k];
  write_csv(
      t, dir / "distances.csv",
      {"a: " + label_a + " (" + a.file_name() + "), b: " + label_b + " (" + b.file_name() + ")",
       "end-of-cycle displacements over cycles " + std::to_string(observe.window.first) + "-" +
           std::to_string(observe.window.second) + ", lengths in grain diameters",
       legend});
  std::vector<fs::path>& written = result.written;
  written.push_back(dir / "distances.csv");
  auto add = [&](const std::vector<fs::path>& files) {
    written.insert(written.end(), files.begin(), files.end());
  };

  // Fig. 2: pdfs of the end-of-cycle displacements.
  std::vector<Sample> pdfs{{label_a + ", translation", x.dr}, {label_b + ", translation", y.dr}};
  if (!x.rot_disp.empty()) pdfs.push_back({label_a + ", rotation", x.rot_disp});
  if (!y.rot_disp.empty()) pdfs.push_back({label_b + ", rotation", y.rot_disp});
  add(plot_log_pdfs(dir, "pdf_displacement", pdfs, "displacement after a cycle [grain diameter]",
                    "End-of-cycle displacements, cycles " + std::to_string(observe.window.first) +
                        "-" + std::to_string(observe.window.second)));

  // Fig. 3: relaxation towards the steady state, from the preparation before cycle 1.
  std::vector<Relaxation> trans, rot;
  const bool b_relaxes = b_placed_after <= 0;
  if (!b_relaxes) {
    result.notes.push_back("no power law for " + label_b + ": placed after cycle " +
                           std::to_string(b_placed_after) +
                           ", it relaxes from there, not from a preparation before cycle 1");
  }
  relaxation_of(label_a, x.cycle, x.mean_dr, relaxation, &trans, &result.notes);
  if (b_relaxes) relaxation_of(label_b, y.cycle, y.mean_dr, relaxation, &trans, &result.notes);
  if (!trans.empty()) {
    add(plot_relaxation(dir, "relaxation_translation", trans,
                        "mean displacement per cycle - steady state [d]",
                        "Translations: relaxation to the steady state"));
  }
  if (oa.rotations)
    relaxation_of(label_a, x.cycle, x.mean_rot_disp, relaxation, &rot, &result.notes);
  if (ob.rotations && b_relaxes)
    relaxation_of(label_b, y.cycle, y.mean_rot_disp, relaxation, &rot, &result.notes);
  if (!rot.empty()) {
    add(plot_relaxation(dir, "relaxation_rotation", rot,
                        "mean rotational displacement per cycle - steady state [d]",
                        "Rotations: relaxation to the steady state"));
  }
  for (const auto* set : {&trans, &rot}) {
    for (const Relaxation& r : *set) {
      report << "  relaxation of " << (set == &rot ? "the rotations of " : "") << r.label
             << ": exponent " << r.fit.exponent << " [" << r.fit.exponent_ci95[0] << ", "
             << r.fit.exponent_ci95[1] << "]\n";
    }
  }

  // Fig. 1: displacement fields, y-z projection.
  std::vector<Field> translation, rotation;
  for (const auto& [run, o, label] : {std::tuple{&a, &oa, label_a}, std::tuple{&b, &ob, label_b}}) {
    std::string what;
    const DisplacementField f = field_of(*run, *o, &what);
    Field t{label + " (" + what + ")", {}, {}, f.dr};
    for (Eigen::Index i = 0; i < f.position.rows(); ++i) {
      t.y.push_back(f.position(i, 1));
      t.z.push_back(f.position(i, 2));
    }
    translation.push_back(t);
    if (o->rotations) rotation.push_back({t.title, t.y, t.z, f.rot_disp});
  }
  add(plot_fields(dir, "field_translation", translation, "[d]", "displacement [d]"));
  if (!rotation.empty()) {
    add(plot_fields(dir, "field_rotation", rotation, "[d]", "rotational displacement [d]"));
  }

  // Fig. 6: one-axis against full rotations, for the runs that have both.
  std::vector<Sample> rotations;
  for (const auto& [o, label] :
       {std::pair{&x, label_a}, std::pair{static_cast<const CycleObservables*>(&y), label_b}}) {
    if (o->full_rot_disp.empty()) continue;
    rotations.push_back({label + ", one axis", o->rot_disp});
    rotations.push_back({label + ", full rotation", o->full_rot_disp});
  }
  if (!rotations.empty()) {
    add(plot_log_pdfs(dir, "pdf_rotation_axes", rotations,
                      "rotational displacement after a cycle [grain diameter]",
                      "Single-axis and full rotations"));
  }
  result.report_ = report.str();
  return result;
}

std::string Comparison::Report() const {
  return report_;
}

void CompareOptions::validate() const {
  if (window && window->first > window->second) {
    throw Error("window " + std::to_string(window->first) + ":" + std::to_string(window->second) +
                ": the first cycle is after the last");
  }
  if (diameter && !(*diameter > 0 && std::isfinite(*diameter))) {
    throw Error("--diameter: expected a positive length");
  }
  MotionOptions motion;
  motion.wall_distance = wall_distance;
  motion.validate();
  if (dir.empty()) throw Error("compare: no output folder (--out)");
}

Comparison compare(const TrajectoryReader& a, const TrajectoryReader& b, const CompareOptions& o) {
  o.validate();
  ObservableOptions observe;
  observe.motion.subtract_drift = o.subtract_drift;
  observe.motion.wall_distance = o.wall_distance;
  observe.diameter = o.diameter ? *o.diameter : median_diameter(a);
  observe.window = o.window ? *o.window : default_comparison_window(a, b);
  PowerLawOptions relaxation;
  relaxation.steady_points = o.steady_points;
  return compare_runs(a, b, o.label_a, o.label_b, observe, Eigen::Vector3d::Ones(), 0.0, o.dir,
                      relaxation);
}

std::pair<std::int64_t, std::int64_t> default_comparison_window(const TrajectoryReader& a,
                                                                const TrajectoryReader& b) {
  const std::int64_t last = std::min(a.steps().back(), b.steps().back());
  const std::int64_t first = std::max(a.steps().front(), b.steps().front()) + 1;
  return {std::max(first, last - 9), last};
}

std::vector<fs::path> calibration_figures(const fs::path& dir, const FrictionFit& fit,
                                          const std::vector<double>& mu) {
  std::vector<Curve> curves;
  const double lo = *std::min_element(mu.begin(), mu.end()),
               hi = *std::max_element(mu.begin(), mu.end());
  for (std::size_t j : {std::size_t(1), std::size_t(4), std::size_t(7)}) {
    if (j >= fit.thresholds.size()) continue;
    char label[96];
    // Per-cycle summaries: these are the first cycle's.
    const std::string cycle = fit.threshold_cycle.empty() || fit.threshold_cycle[j] == 0
                                  ? ""
                                  : ", cycle " + std::to_string(fit.threshold_cycle[j]);
    std::snprintf(label, sizeof label, "DEM, P(dr < %.3g d%s)", fit.thresholds[j], cycle.c_str());
    Curve runs{label, mu, {}, {}, true};
    for (std::size_t k = 0; k < mu.size(); ++k)
      runs.y.push_back(fit.run_cdf[k][j]);
    curves.push_back(runs);
    std::snprintf(label, sizeof label, "experiment, P(dr < %.3g d%s)", fit.thresholds[j],
                  cycle.c_str());
    curves.push_back({label,
                      {lo, fit.mu_s, hi},
                      {fit.experiment_cdf[j], fit.experiment_cdf[j], fit.experiment_cdf[j]},
                      {0, fit.experiment_error[j], 0},
                      false});
  }
  char title[160];
  std::snprintf(title, sizeof title, "Friction fit: mu_s = %.3g [%.3g, %.3g] (95%%)", fit.mu_s,
                fit.mu_s_ci95[0], fit.mu_s_ci95[1]);
  return plot_curves(dir, "calibration", curves, "mu_s", "CDF of the end-of-cycle displacement",
                     title, true);
}

}  // namespace granmem
