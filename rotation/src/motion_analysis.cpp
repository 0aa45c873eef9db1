#include "granmem/rotation/motion_analysis.hpp"

#include <algorithm>
#include <cmath>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/hdf5.hpp"

namespace granmem {
namespace {

constexpr double kDegrees = 180.0 / M_PI;

std::vector<double> in_degrees(std::vector<double> radians) {
  for (double& v : radians)
    v *= kDegrees;
  return radians;
}

void append(std::vector<double>& to, const std::vector<double>& values) {
  to.insert(to.end(), values.begin(), values.end());
}

}  // namespace

MotionAnalysis analyze_motion(const TrajectoryReader& run, const AnalysisOptions& options) {
  const RunHeader& h = run.header();
  const std::string& L = h.length_unit;
  const bool rot = h.has_axis || h.has_orientation;
  const bool full = h.has_orientation;
  if (run.frame_count() < 2) {
    throw Error(run.file_name() + ": needs at least two frames for displacements, has " +
                std::to_string(run.frame_count()));
  }

  MotionAnalysis a;
  a.length_unit = L;
  Table& d = a.displacements;
  Column& frame = d.add("frame", "", true);
  Column& particle = d.add("particle", "", true);
  Column& dx = d.add("dx", L);
  Column& dy = d.add("dy", L);
  Column& dz = d.add("dz", L);
  Column& dr = d.add("dr", L);
  Column& theta_axis = d.add("theta_axis_deg", "deg");
  Column& rot_disp = d.add("rot_disp", L);
  Column* theta_full = full ? &d.add("theta_full_deg", "deg") : nullptr;
  Column* theta_body_x = full ? &d.add("theta_body_x_deg", "deg") : nullptr;
  Column* theta_body_y = full ? &d.add("theta_body_y_deg", "deg") : nullptr;

  Table& p = a.per_frame;
  Column& p_frame = p.add("frame", "", true);
  Column& p_n = p.add("n", "", true);
  Column& p_mean_dr = p.add("mean_dr", L);
  Column& p_median_dr = p.add("median_dr", L);
  Column& p_mean_theta = p.add("mean_theta_axis_deg", "deg");
  Column& p_mean_rot = p.add("mean_rot_disp", L);
  Column& p_median_theta = p.add("median_theta_axis_deg", "deg");
  Column& p_median_rot = p.add("median_rot_disp", L);
  Column& p_n_rot = p.add("n_rot", "", true);
  Column& p_msd = p.add("msd", L.empty() ? "" : L + "^2");
  Column* p_mean_full = full ? &p.add("mean_theta_full_deg", "deg") : nullptr;
  Column* p_median_full = full ? &p.add("median_theta_full_deg", "deg") : nullptr;
  Column& p_drift_x = p.add("drift_x", L);
  Column& p_drift_y = p.add("drift_y", L);
  Column& p_drift_z = p.add("drift_z", L);
  Column& p_prev = p.add("prev_frame", "", true);
  // The structure of frame f (not a change from f-1): from positions, as in a scan.
  Column& p_packing = p.add("packing_fraction", "");
  Column& p_coordination = p.add("coordination", "");

  Frame before = run.read_frame(0);
  for (std::size_t t = 1; t < run.frame_count(); ++t) {
    Frame after = run.read_frame(t);
    const FrameMotion m = grain_motion(h, before, after, options.motion);
    const std::size_t n = m.grain.size();
    const std::vector<double> theta_deg =
        rot ? in_degrees(m.theta_axis) : std::vector<double>(n, std::nan(""));
    const std::vector<double> rot_len = rot ? m.rot_disp : std::vector<double>(n, std::nan(""));
    for (std::size_t k = 0; k < n; ++k) {
      const auto row = static_cast<Eigen::Index>(k);
      frame.values.push_back(double(after.step));
      particle.values.push_back(double(h.id[m.grain[k]]));
      dx.values.push_back(m.displacement(row, 0));
      dy.values.push_back(m.displacement(row, 1));
      dz.values.push_back(m.displacement(row, 2));
    }
    append(dr.values, m.dr);
    append(theta_axis.values, theta_deg);
    append(rot_disp.values, rot_len);
    const std::vector<double> full_deg = in_degrees(m.theta_full);  // empty without orientations
    if (full) {
      append(theta_full->values, full_deg);
      append(theta_body_x->values, in_degrees(m.theta_body_x));
      append(theta_body_y->values, in_degrees(m.theta_body_y));
    }

    const Summary s_dr = summarize(m.dr), s_theta = summarize(theta_deg),
                  s_rot = summarize(rot_len);
    p_frame.values.push_back(double(after.step));
    p_n.values.push_back(double(n));
    p_mean_dr.values.push_back(s_dr.mean);
    p_median_dr.values.push_back(s_dr.median);
    p_mean_theta.values.push_back(s_theta.mean);
    p_mean_rot.values.push_back(s_rot.mean);
    p_median_theta.values.push_back(s_theta.median);
    p_median_rot.values.push_back(s_rot.median);
    p_n_rot.values.push_back(double(s_theta.count));
    p_msd.values.push_back(s_dr.mean_square);
    if (full) {
      const Summary s_full = summarize(full_deg);
      p_mean_full->values.push_back(s_full.mean);
      p_median_full->values.push_back(s_full.median);
    }
    p_drift_x.values.push_back(m.drift.x());
    p_drift_y.values.push_back(m.drift.y());
    p_drift_z.values.push_back(m.drift.z());
    p_prev.values.push_back(double(before.step));
    const PackingStructure structure =
        packing_structure(after.position, h.radius, options.structure);
    p_packing.values.push_back(structure.packing_fraction);
    p_coordination.values.push_back(structure.coordination);
    before = std::move(after);
  }

  // Pdfs pooled over a window of frames.
  const std::vector<std::int64_t>& steps = run.steps();
  a.pdf_frames = options.pdf_frames.value_or(std::make_pair(steps[1], steps.back()));
  const auto [first, last] = a.pdf_frames;
  if (first > last)
    throw Error("--window: first frame " + std::to_string(first) + " is after last frame " +
                std::to_string(last));
  std::vector<std::string> quantities = options.pdf_quantities;
  if (quantities.empty()) {
    quantities.push_back("dr");
    if (rot) quantities.insert(quantities.end(), {"theta_axis_deg", "rot_disp"});
    if (full)
      quantities.insert(quantities.end(),
                        {"theta_full_deg", "theta_body_x_deg", "theta_body_y_deg"});
  }
  std::vector<std::size_t> window;
  for (std::size_t r = 0; r < d.rows(); ++r) {
    if (frame.values[r] >= double(first) && frame.values[r] <= double(last)) window.push_back(r);
  }
  if (window.empty() && !options.pdf_frames) {
    a.notes.push_back("no pdfs: no grain was followed from one frame to the next");
    return a;
  }
  if (window.empty()) {
    throw Error("--window " + std::to_string(first) + ":" + std::to_string(last) +
                ": no displacements in these frames (the run's frames are " +
                std::to_string(steps.front()) + " to " + std::to_string(steps.back()) +
                ", displacements start at frame " + std::to_string(steps[1]) + ")");
  }
  for (const std::string& q : quantities) {
    if (q == "frame" || q == "particle" || !d.has(q)) {
      std::string names;
      for (const Column& c : d.columns()) {
        if (c.name != "frame" && c.name != "particle")
          names += (names.empty() ? "" : ", ") + c.name;
      }
      throw Error("pdf of '" + q + "': not a quantity of this run (it has " + names + ")");
    }
    const Column& c = d[q];
    std::vector<double> values;
    values.reserve(window.size());
    for (std::size_t r : window)
      values.push_back(c.values[r]);
    if (std::none_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); })) {
      const std::string why = "no measured values of " + q + " in frames " + std::to_string(first) +
                              " to " + std::to_string(last);
      // A pdf asked for must be made; a default one is skipped with a note.
      if (!options.pdf_quantities.empty()) throw Error("pdf of '" + q + "': " + why);
      a.notes.push_back("no pdf of " + q + ": " + why);
      continue;
    }
    a.pdfs[q] = probability_density(values, options.density, c.unit);
  }
  return a;
}

namespace {

// The pdf tables an earlier analysis left in `dir` that this one did not write (another run,
// other --pdf quantities): left there they would read as part of this one.
void remove_stale_pdfs(const std::filesystem::path& dir,
                       const std::vector<std::filesystem::path>& written) {
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    const bool pdf = name.rfind("pdf_", 0) == 0 && e.path().extension() == ".csv";
    if (pdf && std::find(written.begin(), written.end(), dir / name) == written.end()) {
      std::filesystem::remove(e.path(), ec);
    }
  }
}

}  // namespace

std::vector<std::filesystem::path> write_motion_analysis(
    const MotionAnalysis& analysis, const std::filesystem::path& dir,
    const std::vector<std::string>& comment, const std::map<std::string, std::string>& parameters) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (!std::filesystem::is_directory(dir)) {
    throw Error(dir.string() + ": cannot create the output folder");
  }
  std::vector<AtomicFile> files;
  auto csv = [&](const std::string& name, const Table& table, const std::string& what) {
    files.emplace_back(dir / name);
    std::vector<std::string> lines = comment;
    lines.push_back(what);
    write_csv(table, files.back(), lines);
  };
  const std::string units = "lengths in " + analysis.length_unit + ", angles in degrees";
  csv("displacements.csv", analysis.displacements,
      "displacement of each grain from frame prev to frame; " + units);
  csv("per_frame.csv", analysis.per_frame, "per-frame statistics; " + units);
  const std::string window = "frames " + std::to_string(analysis.pdf_frames.first) + " to " +
                             std::to_string(analysis.pdf_frames.second);
  for (const auto& [q, table] : analysis.pdfs) {
    csv("pdf_" + q + ".csv", table,
        "probability density of " + q + " over " + window + "; " + units +
            "; density = count / (all measured values * bin width)");
  }

  files.emplace_back(dir / "analysis.h5");
  {
    h5::File f = h5::File::create(files.back());
    h5::write_table(f.id(), "/displacements", analysis.displacements);
    h5::write_table(f.id(), "/per_frame", analysis.per_frame);
    for (const auto& [q, table] : analysis.pdfs) {
      h5::write_table(f.id(), "/pdf/" + q, table);
      h5::Handle g = h5::create_group(f.id(), "/pdf/" + q);
      h5::write_attribute(g.get(), "frames", window);
    }
    h5::Handle params = h5::create_group(f.id(), "/parameters/analyze");
    for (const auto& [key, value] : parameters)
      h5::write_attribute(params.get(), key, value);
    f.close();
  }

  std::vector<std::filesystem::path> written;
  for (AtomicFile& file : files) {
    file.commit();
    written.push_back(file.target());
  }
  remove_stale_pdfs(dir, written);
  return written;
}

}  // namespace granmem
