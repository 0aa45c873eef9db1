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

void check_window(std::int64_t first, std::int64_t last) {
  if (first > last)
    throw Error("--window: first frame " + std::to_string(first) + " is after last frame " +
                std::to_string(last));
}

// A frame pair's motion as the tables hold it: angles in degrees; the single-axis rotation
// NaN where the run has neither axes nor orientations, the full one empty without the latter.
struct TabledMotion {
  const FrameMotion& m;
  std::vector<double> theta_deg, rot_len, full_deg;
};

TabledMotion tabled(const FrameMotion& m, bool rot) {
  const std::size_t n = m.grain.size();
  return {m, rot ? in_degrees(m.theta_axis) : std::vector<double>(n, std::nan("")),
          rot ? m.rot_disp : std::vector<double>(n, std::nan("")), in_degrees(m.theta_full)};
}

// The displacements table's columns: a row per grain followed from frame f-1 to frame f.
class DisplacementColumns {
 public:
  DisplacementColumns(Table& d, const std::string& L, bool full)
      : frame_(d.add("frame", "", true)),
        particle_(d.add("particle", "", true)),
        dx_(d.add("dx", L)),
        dy_(d.add("dy", L)),
        dz_(d.add("dz", L)),
        dr_(d.add("dr", L)),
        theta_axis_(d.add("theta_axis_deg", "deg")),
        rot_disp_(d.add("rot_disp", L)),
        theta_full_(full ? &d.add("theta_full_deg", "deg") : nullptr),
        theta_body_x_(full ? &d.add("theta_body_x_deg", "deg") : nullptr),
        theta_body_y_(full ? &d.add("theta_body_y_deg", "deg") : nullptr) {}

  void add(const RunHeader& h, std::int64_t step, const TabledMotion& t) {
    const FrameMotion& m = t.m;
    for (std::size_t k = 0; k < m.grain.size(); ++k) {
      const auto row = static_cast<Eigen::Index>(k);
      frame_.values.push_back(double(step));
      particle_.values.push_back(double(h.id[m.grain[k]]));
      dx_.values.push_back(m.displacement(row, 0));
      dy_.values.push_back(m.displacement(row, 1));
      dz_.values.push_back(m.displacement(row, 2));
    }
    append(dr_.values, m.dr);
    append(theta_axis_.values, t.theta_deg);
    append(rot_disp_.values, t.rot_len);
    if (theta_full_) {
      append(theta_full_->values, t.full_deg);
      append(theta_body_x_->values, in_degrees(m.theta_body_x));
      append(theta_body_y_->values, in_degrees(m.theta_body_y));
    }
  }

 private:
  Column &frame_, &particle_, &dx_, &dy_, &dz_, &dr_, &theta_axis_, &rot_disp_;
  Column *theta_full_, *theta_body_x_, *theta_body_y_;
};

// The per-frame table's columns: a row per frame pair f-1 -> f, with the structure of f.
class PerFrameColumns {
 public:
  PerFrameColumns(Table& p, const std::string& L, bool full)
      : frame_(p.add("frame", "", true)),
        n_(p.add("n", "", true)),
        mean_dr_(p.add("mean_dr", L)),
        median_dr_(p.add("median_dr", L)),
        mean_theta_(p.add("mean_theta_axis_deg", "deg")),
        mean_rot_(p.add("mean_rot_disp", L)),
        median_theta_(p.add("median_theta_axis_deg", "deg")),
        median_rot_(p.add("median_rot_disp", L)),
        n_rot_(p.add("n_rot", "", true)),
        msd_(p.add("msd", L.empty() ? "" : L + "^2")),
        mean_full_(full ? &p.add("mean_theta_full_deg", "deg") : nullptr),
        median_full_(full ? &p.add("median_theta_full_deg", "deg") : nullptr),
        drift_x_(p.add("drift_x", L)),
        drift_y_(p.add("drift_y", L)),
        drift_z_(p.add("drift_z", L)),
        prev_(p.add("prev_frame", "", true)),
        // The structure of frame f (not a change from f-1): from positions, as in a scan.
        packing_(p.add("packing_fraction", "")),
        coordination_(p.add("coordination", "")) {}

  void add(std::int64_t step, std::int64_t prev_step, const TabledMotion& t,
           const PackingStructure& structure) {
    const FrameMotion& m = t.m;
    const Summary s_dr = summarize(m.dr), s_theta = summarize(t.theta_deg),
                  s_rot = summarize(t.rot_len);
    frame_.values.push_back(double(step));
    n_.values.push_back(double(m.grain.size()));
    mean_dr_.values.push_back(s_dr.mean);
    median_dr_.values.push_back(s_dr.median);
    mean_theta_.values.push_back(s_theta.mean);
    mean_rot_.values.push_back(s_rot.mean);
    median_theta_.values.push_back(s_theta.median);
    median_rot_.values.push_back(s_rot.median);
    n_rot_.values.push_back(double(s_theta.count));
    msd_.values.push_back(s_dr.mean_square);
    if (mean_full_) {
      const Summary s_full = summarize(t.full_deg);
      mean_full_->values.push_back(s_full.mean);
      median_full_->values.push_back(s_full.median);
    }
    drift_x_.values.push_back(m.drift.x());
    drift_y_.values.push_back(m.drift.y());
    drift_z_.values.push_back(m.drift.z());
    prev_.values.push_back(double(prev_step));
    packing_.values.push_back(structure.packing_fraction);
    coordination_.values.push_back(structure.coordination);
  }

 private:
  Column &frame_, &n_, &mean_dr_, &median_dr_, &mean_theta_, &mean_rot_, &median_theta_,
      &median_rot_, &n_rot_, &msd_;
  Column *mean_full_, *median_full_;
  Column &drift_x_, &drift_y_, &drift_z_, &prev_, &packing_, &coordination_;
};

// The displacements and per-frame tables, frame pair by frame pair.
void tabulate_motion(const TrajectoryReader& run, const AnalysisOptions& options,
                     MotionAnalysis& a) {
  const RunHeader& h = run.header();
  const bool rot = h.has_axis || h.has_orientation;
  DisplacementColumns displacements(a.displacements, h.length_unit, h.has_orientation);
  PerFrameColumns per_frame(a.per_frame, h.length_unit, h.has_orientation);
  Frame before = run.read_frame(0);
  for (std::size_t t = 1; t < run.frame_count(); ++t) {
    Frame after = run.read_frame(t);
    const FrameMotion m = grain_motion(h, before, after, options.motion);
    const TabledMotion motion = tabled(m, rot);
    displacements.add(h, after.step, motion);
    per_frame.add(after.step, before.step, motion,
                  packing_structure(after.position, h.radius, options.structure));
    before = std::move(after);
  }
}

// The quantities whose pdfs are made: those asked for, else dr and the rotations the run has.
std::vector<std::string> pdf_quantities(const AnalysisOptions& options, const RunHeader& h) {
  std::vector<std::string> quantities = options.pdf_quantities;
  if (quantities.empty()) {
    quantities.push_back("dr");
    if (h.has_axis || h.has_orientation)
      quantities.insert(quantities.end(), {"theta_axis_deg", "rot_disp"});
    if (h.has_orientation)
      quantities.insert(quantities.end(),
                        {"theta_full_deg", "theta_body_x_deg", "theta_body_y_deg"});
  }
  return quantities;
}

// The rows of the displacements table in frames first to last (labels).
std::vector<std::size_t> rows_in_window(const Table& d, std::int64_t first, std::int64_t last) {
  const std::vector<double>& frame = d["frame"].values;
  std::vector<std::size_t> window;
  for (std::size_t r = 0; r < d.rows(); ++r) {
    if (frame[r] >= double(first) && frame[r] <= double(last)) window.push_back(r);
  }
  return window;
}

// Error unless `q` is a column of the displacements table other than frame and particle.
void check_quantity(const Table& d, const std::string& q) {
  if (q != "frame" && q != "particle" && d.has(q)) return;
  std::string names;
  for (const Column& c : d.columns()) {
    if (c.name != "frame" && c.name != "particle") names += (names.empty() ? "" : ", ") + c.name;
  }
  throw Error("pdf of '" + q + "': not a quantity of this run (it has " + names + ")");
}

// The pdf of each quantity over the window's rows: one asked for must be made; a default
// one without a measured value is skipped with a note.
void add_pdfs(MotionAnalysis& a, const std::vector<std::size_t>& window,
              const std::vector<std::string>& quantities, const AnalysisOptions& options) {
  const Table& d = a.displacements;
  const auto [first, last] = a.pdf_frames;
  for (const std::string& q : quantities) {
    check_quantity(d, q);
    const Column& c = d[q];
    std::vector<double> values;
    values.reserve(window.size());
    for (std::size_t r : window)
      values.push_back(c.values[r]);
    if (std::none_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); })) {
      const std::string why = "no measured values of " + q + " in frames " + std::to_string(first) +
                              " to " + std::to_string(last);
      if (!options.pdf_quantities.empty()) throw Error("pdf of '" + q + "': " + why);
      a.notes.push_back("no pdf of " + q + ": " + why);
      continue;
    }
    a.pdfs[q] = probability_density(values, options.density, c.unit);
  }
}

}  // namespace

void AnalysisOptions::validate() const {
  motion.validate();
  if (pdf_frames) check_window(pdf_frames->first, pdf_frames->second);
  density.validate();
}

MotionAnalysis analyze_motion(const TrajectoryReader& run, const AnalysisOptions& options) {
  options.validate();
  if (run.frame_count() < 2) {
    throw Error(run.file_name() + ": needs at least two frames for displacements, has " +
                std::to_string(run.frame_count()));
  }
  MotionAnalysis a;
  a.length_unit = run.header().length_unit;
  tabulate_motion(run, options, a);

  // Pdfs pooled over a window of frames.
  const std::vector<std::int64_t>& steps = run.steps();
  a.pdf_frames = options.pdf_frames.value_or(std::make_pair(steps[1], steps.back()));
  const auto [first, last] = a.pdf_frames;
  check_window(first, last);  // the default one too: a run's steps need not ascend
  const std::vector<std::string> quantities = pdf_quantities(options, run.header());
  const std::vector<std::size_t> window = rows_in_window(a.displacements, first, last);
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
  add_pdfs(a, window, quantities, options);
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
