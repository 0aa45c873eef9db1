#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "granmem/core/statistics.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/rotation/grain_motion.hpp"
#include "granmem/rotation/packing_structure.hpp"

namespace granmem {

struct AnalysisOptions {
  MotionOptions motion;
  // Quantities (columns of the displacements table) whose pdf is wanted; empty: dr, and
  // theta_axis_deg, rot_disp, theta_full_deg where the run has them.
  std::vector<std::string> pdf_quantities;
  // Frames (labels, inclusive) pooled into the pdfs; default all.
  std::optional<std::pair<std::int64_t, std::int64_t>> pdf_frames;
  DensityOptions density;
  StructureOptions structure;  // the per-frame packing fraction and coordination

  // Throws Error naming the option: the motion's and the pdfs' options
  // (MotionOptions::validate, DensityOptions::validate), a window whose first frame is
  // after its last.
  void validate() const;
};

// The paper's statistics of a run between consecutive frames f-1 -> f.
struct MotionAnalysis {
  // One row per grain per frame f >= 1 seen in f-1 and f: frame, particle, dx, dy, dz, dr,
  // theta_axis_deg, rot_disp (+ theta_full_deg with orientations). `frame` is the label
  // (step) of frame f; lengths are in the run's length unit.
  Table displacements;
  // One row per frame f >= 1: frame, n, mean_dr, median_dr, mean_theta_axis_deg,
  // mean_rot_disp, median_theta_axis_deg, median_rot_disp, n_rot, msd, (mean and median
  // theta_full_deg,) drift_x, drift_y, drift_z, prev_frame, packing_fraction and
  // coordination of frame f (packing_structure.hpp; from positions and radii).
  Table per_frame;
  std::map<std::string, Table> pdfs;  // quantity -> bin_lo, bin_hi, bin_center, count, density
  std::string length_unit;
  std::vector<std::string> notes;  // what was left out and why, for the user
  std::pair<std::int64_t, std::int64_t> pdf_frames{0, 0};
};

// Validates the options, then the run: at least two frames, the pdfs asked for measured.
MotionAnalysis analyze_motion(const TrajectoryReader& run, const AnalysisOptions& options);

// Writes DIR/displacements.csv, DIR/per_frame.csv, DIR/pdf_<quantity>.csv and
// DIR/analysis.h5 (the same tables, with units and `parameters` under /parameters/analyze).
// Every file is written in full under a temporary name first and renamed into place only
// when all are written; pdf_*.csv tables of an earlier analysis in DIR that this one does
// not write are then removed. Returns the paths written.
std::vector<std::filesystem::path> write_motion_analysis(
    const MotionAnalysis& analysis, const std::filesystem::path& dir,
    const std::vector<std::string>& comment, const std::map<std::string, std::string>& parameters);

}  // namespace granmem
