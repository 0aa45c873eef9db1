#include "granmem/rotation/analyze_run.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace granmem {
namespace {

// A few rows of the per-frame table: the first and last five of a long run.
void per_frame_rows(std::ostream& out, const Table& p, const std::string& unit) {
  const std::size_t rows = p.rows();
  out << std::setw(7) << "frame" << std::setw(8) << "n" << std::setw(14) << "mean_dr"
      << std::setw(14) << "median_dr" << std::setw(14) << "mean_theta"
      << "\n"
      << std::setw(29) << "[" + unit + "]" << std::setw(14) << "[" + unit + "]" << std::setw(14)
      << "[deg]"
      << "\n";
  for (std::size_t r = 0; r < rows; ++r) {
    if (rows > 12 && r == 5) {
      out << std::setw(7) << "..."
          << "\n";
      r = rows - 5;
    }
    out << std::setprecision(5) << std::setw(7) << p["frame"].values[r] << std::setw(8)
        << p["n"].values[r] << std::setw(14) << p["mean_dr"].values[r] << std::setw(14)
        << p["median_dr"].values[r] << std::setw(14) << p["mean_theta_axis_deg"].values[r] << "\n";
  }
}

}  // namespace

std::string AnalyzeSummary::Report() const {
  std::ostringstream out;
  out << run << ": " << analysis.displacements.rows() << " displacements over "
      << analysis.per_frame.rows() << " frame pairs, lengths in " << analysis.length_unit << "\n";
  per_frame_rows(out, analysis.per_frame, analysis.length_unit);
  for (const auto& path : written)
    out << "wrote " << path.string() << "\n";
  return out.str();
}

AnalyzeSummary analyze_run(const TrajectoryReader& run, const AnalysisOptions& options,
                           const std::filesystem::path& out,
                           const std::map<std::string, std::string>& parameters) {
  AnalyzeSummary s;
  s.run = run.file_name();
  s.analysis = analyze_motion(run, options);
  s.written =
      write_motion_analysis(s.analysis, out, {"granmem analyze " + run.file_name()}, parameters);
  s.notes = s.analysis.notes;
  const RunHeader& h = run.header();
  const bool radius_known =
      std::any_of(h.radius.begin(), h.radius.end(), [](double r) { return std::isfinite(r); });
  if ((h.has_axis || h.has_orientation) && !radius_known) {
    s.notes.push_back(run.file_name() +
                      " has no grain radius, so rot_disp is nan (import with --radius)");
  }
  return s;
}

}  // namespace granmem
