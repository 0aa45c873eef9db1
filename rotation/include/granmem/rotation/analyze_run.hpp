#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/rotation/motion_analysis.hpp"

namespace granmem {

// `granmem analyze` as one call: the run's displacements and rotations between consecutive
// frames, per-frame means and pdfs (analyze_motion), written to a folder
// (write_motion_analysis), and what the user is told.
struct AnalyzeSummary {
  std::string run;  // the store's file name
  MotionAnalysis analysis;
  std::vector<std::filesystem::path> written;
  // What was left out and why, and a run whose rotations cannot be lengths (no radius).
  std::vector<std::string> notes;
  // The run's story at a glance: counts, the unit, a few per-frame rows, the files written.
  std::string Report() const;
};

// Analyses `run` with `options` and writes the tables into `out`, with `parameters` (the
// options used) in analysis.h5. Throws Error for a run with fewer than two frames or bad
// options (analyze_motion), or an output folder that cannot be written.
AnalyzeSummary analyze_run(const TrajectoryReader& run, const AnalysisOptions& options,
                           const std::filesystem::path& out,
                           const std::map<std::string, std::string>& parameters);

}  // namespace granmem
