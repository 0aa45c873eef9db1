// granmem._granmem: the libraries' entry points with numpy in and out. Tables cross as
// dicts of 1-D arrays (column name -> values) that granmem/__init__.py turns into pandas
// DataFrames; stacks as (z, y, x) arrays; options as keywords with the CLI's names, lengths
// as numbers or as text with a unit ("0.4mm"). Long calls release the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "granmem/calibration/calibrate.hpp"
#include "granmem/calibration/comparison.hpp"
#include "granmem/calibration/readout.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/import_table.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/run_info.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/trajectory_table.hpp"
#include "granmem/core/units.hpp"
#include "granmem/core/version.hpp"
#include "granmem/rotation/grain_motion.hpp"
#include "granmem/rotation/motion_analysis.hpp"
#include "granmem/sim/simulate.hpp"
#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/link_run.hpp"
#include "granmem/tracking/locate.hpp"
#include "granmem/tracking/render.hpp"
#include "granmem/tracking/stack.hpp"

namespace py = pybind11;

namespace granmem::python {
namespace {

using Vector3 = std::array<double, 3>;

Eigen::Vector3d vector_of(const Vector3& v) {
  return {v[0], v[1], v[2]};
}

py::object optional_vector(const std::optional<Eigen::Vector3d>& v) {
  if (!v) return py::none();
  return py::make_tuple((*v)[0], (*v)[1], (*v)[2]);
}

// ------------------------------------------------------------------------------ tables

// Integer columns (frame, particle, flags) as int64, the rest as float64.
py::dict columns_of(const Table& table) {
  py::dict out;
  for (const Column& c : table.columns()) {
    const auto n = py::ssize_t(c.values.size());
    if (c.integer) {
      py::array_t<std::int64_t> a(n);
      std::int64_t* p = a.mutable_data();
      for (py::ssize_t i = 0; i < n; ++i)
        p[i] = std::int64_t(c.values[std::size_t(i)]);
      out[py::str(c.name)] = a;
    } else {
      py::array_t<double> a(n);
      std::copy(c.values.begin(), c.values.end(), a.mutable_data());
      out[py::str(c.name)] = a;
    }
  }
  return out;
}

py::dict units_of(const Table& table) {
  py::dict out;
  for (const Column& c : table.columns())
    out[py::str(c.name)] = c.unit;
  return out;
}

// A dict of equal-length 1-D columns (numbers) -> a Table; `length_unit` for x, y, z, radius.
Table table_of(const py::dict& columns, const std::string& length_unit, const std::string& what) {
  Table t;
  std::size_t rows = 0;
  bool first = true;
  for (const auto& [key, value] : columns) {
    const std::string name = py::str(key);
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
    if (!a || a.ndim() != 1) throw Error(what + ": column '" + name + "' is not 1-D numbers");
    if (!first && std::size_t(a.size()) != rows) {
      throw Error(what + ": column '" + name + "' has " + std::to_string(a.size()) +
                  " rows, the others " + std::to_string(rows));
    }
    rows = std::size_t(a.size());
    first = false;
    const bool is_length = name == "x" || name == "y" || name == "z" || name == "radius" ||
                           name == "ep" || name == "ep_x" || name == "ep_y" || name == "ep_z";
    const bool integer =
        name == "frame" || name == "particle" || name == "edge" || name == "hole_contact";
    Column& c = t.add(name, is_length ? length_unit : "", integer);
    c.values.assign(a.data(), a.data() + a.size());
  }
  return t;
}

py::tuple table_result(const Table& table) {
  return py::make_tuple(columns_of(table), units_of(table));
}

// ------------------------------------------------------------------------------ stacks

Stack stack_of(const py::array& array, const std::optional<Vector3>& voxel_size,
               const std::string& unit) {
  if (array.ndim() != 3) {
    throw Error("stack: expected a 3-D array (z, y, x), got " + std::to_string(array.ndim()) +
                " dimensions");
  }
  const bool bits8 = py::isinstance<py::array_t<std::uint8_t>>(array);
  if (!bits8 && !py::isinstance<py::array_t<std::uint16_t>>(array)) {
    throw Error("stack: expected a uint8 or uint16 array, got " +
                std::string(py::str(array.dtype())));
  }
  Stack s(array.shape(2), array.shape(1), array.shape(0), bits8 ? 8 : 16);
  s.source = "stack";
  if (bits8) {
    const auto a = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>(array);
    std::copy(a.data(), a.data() + a.size(), s.voxels.begin());
  } else {
    const auto a = py::array_t<std::uint16_t, py::array::c_style | py::array::forcecast>(array);
    std::copy(a.data(), a.data() + a.size(), s.voxels.begin());
  }
  if (voxel_size) {
    if (!is_physical_length_unit(unit)) {
      throw Error("voxel_size needs a unit (m, cm, mm, um), e.g. unit='mm'");
    }
    s.voxel_size = vector_of(*voxel_size);
    if (!(s.voxel_size->array() > 0).all() || !s.voxel_size->allFinite()) {
      throw Error("voxel_size: expected three positive sizes");
    }
    s.unit = unit;
  }
  return s;
}

py::array array_of(const Stack& s) {
  const std::vector<py::ssize_t> shape{s.nz, s.ny, s.nx};
  if (s.bits == 8) {
    py::array_t<std::uint8_t> a(shape);
    std::transform(s.voxels.begin(), s.voxels.end(), a.mutable_data(),
                   [](std::uint16_t v) { return std::uint8_t(v); });
    return std::move(a);
  }
  py::array_t<std::uint16_t> a(shape);
  std::copy(s.voxels.begin(), s.voxels.end(), a.mutable_data());
  return std::move(a);
}

py::tuple read_stack_py(const std::filesystem::path& path, const std::string& dataset,
                        const std::optional<std::string>& region) {
  StackReadOptions options;
  options.dataset = dataset;
  if (region) options.region = parse_region(*region, "region");
  Stack s;
  {
    py::gil_scoped_release release;
    s = read_stack(path, options);
  }
  return py::make_tuple(array_of(s), optional_vector(s.voxel_size), s.unit);
}

void write_tiff_py(const py::array& array, const std::filesystem::path& path,
                   const std::optional<Vector3>& voxel_size, const std::string& unit) {
  const Stack s = stack_of(array, voxel_size, unit);
  py::gil_scoped_release release;
  write_tiff(s, path);
}

// ------------------------------------------------------------------------------ locate

LocateOptions locate_options(const Stack& stack, const std::string& diameter,
                             const std::string& polarity, double hole_fraction,
                             const std::string& beam, const std::string& axis, int passes,
                             bool illumination) {
  if (polarity != "dark" && polarity != "bright") {
    throw Error("polarity '" + polarity + "': expected 'dark' or 'bright'");
  }
  const std::vector<std::string> beams{"x", "y", "+x", "-x", "+y", "-y"};
  if (std::find(beams.begin(), beams.end(), beam) == beams.end()) {
    throw Error("beam '" + beam + "': expected x or y (or the side it enters: +x, -x, +y, -y)");
  }
  if (axis != "fit" && axis != "lab") throw Error("axis '" + axis + "': expected 'fit' or 'lab'");
  LocateOptions o;
  o.diameter = diameter_in_voxels(diameter, stack, "diameter");
  o.dark_grains = polarity == "dark";
  o.hole_fraction = o.dark_grains ? hole_fraction : 0.0;
  o.beam_axis = beam.back() == 'y' ? 1 : 0;
  o.fit_axis = axis == "fit";
  o.passes = passes;
  o.correct_illumination = illumination;
  o.validate();
  return o;
}

// ------------------------------------------------------------------------------ render

std::vector<RenderedGrain> grains_of(const py::dict& columns, const std::string& length_unit) {
  const Table t = table_of(columns, length_unit, "grains");
  for (const char* c : {"x", "y", "z", "radius"}) {
    if (!t.has(c)) throw Error(std::string("grains: no column '") + c + "'");
  }
  const bool axis = t.has("ax") && t.has("ay") && t.has("az");
  std::vector<RenderedGrain> grains(t.rows());
  for (std::size_t i = 0; i < grains.size(); ++i) {
    RenderedGrain& g = grains[i];
    g.id = t.has("particle") ? std::int64_t(t["particle"].values[i]) : std::int64_t(i);
    g.centre = {t["x"].values[i], t["y"].values[i], t["z"].values[i]};
    g.radius = t["radius"].values[i];
    if (axis) g.axis = {t["ax"].values[i], t["ay"].values[i], t["az"].values[i]};
  }
  return grains;
}

py::tuple render_py(const py::dict& grains, const std::string& length_unit, double diameter_px,
                    double slice_spacing_ratio, bool clean, double hole_fraction,
                    const std::string& polarity, int bits, std::uint64_t seed, std::int64_t frame) {
  if (polarity != "dark" && polarity != "bright") {
    throw Error("polarity '" + polarity + "': expected 'dark' or 'bright'");
  }
  RenderOptions o;
  o.length_unit = length_unit;
  o.diameter_px = diameter_px;
  o.slice_spacing_ratio = slice_spacing_ratio;
  o.hole_fraction = hole_fraction;
  o.polarity = polarity == "dark" ? Polarity::dark_grains : Polarity::bright_grains;
  o.bits = bits;
  o.seed = seed;
  o.frame = frame;
  if (clean) o = o.without_artefacts();
  const std::vector<RenderedGrain> drawn = grains_of(grains, length_unit);
  Table truth;
  Stack s;
  {
    py::gil_scoped_release release;
    s = render_scan(drawn, o, &truth);
  }
  return py::make_tuple(array_of(s), optional_vector(s.voxel_size), columns_of(truth));
}

// ------------------------------------------------------------------------------ runs

// A run as arrays: frames x grains x 3 positions (NaN: not seen), the header's fields, the
// observables.
py::dict run_arrays(const Trajectories& run) {
  const RunHeader& h = run.header;
  const auto frames = py::ssize_t(run.frames.size()), n = py::ssize_t(h.grain_count());
  auto stacked = [&](auto field, py::ssize_t width) {
    py::array_t<double> a(std::vector<py::ssize_t>{frames, n, width});
    double* p = a.mutable_data();
    for (const Frame& f : run.frames) {
      const auto& m = field(f);
      p = std::copy(m.data(), m.data() + m.size(), p);
    }
    return a;
  };
  py::dict out;
  out["length_unit"] = h.length_unit;
  out["time_unit"] = h.time_unit;
  out["sample"] = h.sample;
  out["id"] = py::array_t<std::int64_t>(n, h.id.data());
  out["radius"] = py::array_t<double>(n, h.radius.data());
  out["box"] =
      h.box
          ? py::object(py::make_tuple(optional_vector(h.box->lower), optional_vector(h.box->edges)))
          : py::object(py::none());
  out["voxel_size"] = optional_vector(h.voxel_size);
  std::vector<std::int64_t> step;
  std::vector<double> time;
  for (const Frame& f : run.frames) {
    step.push_back(f.step);
    time.push_back(f.time);
  }
  out["step"] = py::array_t<std::int64_t>(frames, step.data());
  out["time"] = py::array_t<double>(frames, time.data());
  out["position"] = stacked([](const Frame& f) -> const Vectors3& { return f.position; }, 3);
  out["axis"] =
      h.has_axis ? py::object(stacked([](const Frame& f) -> const Vectors3& { return f.axis; }, 3))
                 : py::object(py::none());
  out["orientation"] =
      h.has_orientation
          ? py::object(
                stacked([](const Frame& f) -> const Quaternions& { return f.orientation; }, 4))
          : py::object(py::none());
  out["position_error"] =
      h.has_position_error
          ? py::object(
                stacked([](const Frame& f) -> const Vectors3& { return f.position_error; }, 3))
          : py::object(py::none());
  out["axis_error"] =
      h.has_axis_error
          ? stacked([](const Frame& f) -> const std::vector<double>& { return f.axis_error; }, 1)
                .attr("reshape")(frames, n)
          : py::object(py::none());
  py::dict observables;
  for (const auto& [name, o] : run.observables) {
    py::dict d;
    d["unit"] = o.unit;
    d["step"] = py::array_t<std::int64_t>(py::ssize_t(o.step.size()), o.step.data());
    d["time"] = py::array_t<double>(py::ssize_t(o.time.size()), o.time.data());
    d["value"] = py::array_t<double>(py::ssize_t(o.value.size()), o.value.data());
    observables[py::str(name)] = d;
  }
  out["observables"] = observables;
  out["parameters"] = h.parameters;
  return out;
}

Trajectories read_run(const std::filesystem::path& path) {
  py::gil_scoped_release release;
  return read_trajectories(path);
}

ImportOptions import_options(const std::string& length_unit, const std::optional<double>& radius) {
  ImportOptions o;
  o.length_unit = length_unit;
  o.radius = radius;
  return o;
}

Trajectories run_of_table(const py::dict& columns, const std::string& length_unit,
                          const std::optional<double>& radius,
                          const std::filesystem::path& readings = {}) {
  ImportOptions o = import_options(length_unit, radius);
  o.readings = readings;
  return import_table(table_of(columns, length_unit, "tracks"), "tracks", o);
}

void write_run_py(const py::dict& columns, const std::filesystem::path& path,
                  const std::string& length_unit, const std::optional<double>& radius,
                  const std::optional<std::filesystem::path>& readings) {
  const Trajectories run = run_of_table(columns, length_unit, radius, readings.value_or(""));
  py::gil_scoped_release release;
  write_trajectories(path, run);
}

// ------------------------------------------------------------------------------ link

// One scan's detections: its columns and frame; all in `length_unit`.
Detections detections_of(const py::dict& columns, std::int64_t frame,
                         const std::string& length_unit, const std::optional<Vector3>& voxel_size) {
  const std::string where = "frame " + std::to_string(frame);
  Detections d = from_table(table_of(columns, length_unit, where), where);
  d.frame = frame;
  d.length_unit = length_unit;
  d.source = where;
  if (voxel_size) d.voxel_size = vector_of(*voxel_size);
  return d;
}

// ------------------------------------------------------------------------------ motion

std::size_t frame_index(const Trajectories& run, std::int64_t frame) {
  for (std::size_t t = 0; t < run.frames.size(); ++t) {
    if (run.frames[t].step == frame) return t;
  }
  throw Error("the run has no frame " + std::to_string(frame));
}

py::dict motion_of(const Trajectories& run, std::int64_t before, std::int64_t after,
                   bool subtract_drift, const std::string& wall_distance,
                   const std::string& hole_contacts) {
  MotionOptions o;
  o.subtract_drift = subtract_drift;
  o.wall_distance = parse_length(wall_distance, run.header.length_unit, "wall_distance");
  o.hole_contacts = hole_contact_policy(hole_contacts, "hole_contacts");
  if (o.wall_distance > 0 && !run.header.box) {
    throw Error("wall_distance: the run has no box (link with a container, or import with one)");
  }
  const FrameMotion m = grain_motion(run.header, run.frames[frame_index(run, before)],
                                     run.frames[frame_index(run, after)], o);
  const std::string& unit = run.header.length_unit;
  Table t;
  Column& particle = t.add("particle", "", true);
  Column* d[3] = {&t.add("dx", unit), &t.add("dy", unit), &t.add("dz", unit)};
  for (std::size_t k = 0; k < m.grain.size(); ++k) {
    particle.values.push_back(double(run.header.id[m.grain[k]]));
    for (int a = 0; a < 3; ++a)
      d[a]->values.push_back(m.displacement(Eigen::Index(k), a));
  }
  t.add("dr", unit).values = m.dr;
  if (m.has_rotation) {
    t.add("theta_axis", "rad").values = m.theta_axis;
    t.add("rot_disp", unit).values = m.rot_disp;
  }
  if (!m.theta_full.empty()) t.add("theta_full", "rad").values = m.theta_full;
  py::dict out;
  out["columns"] = columns_of(t);
  out["units"] = units_of(t);
  out["drift"] = py::make_tuple(m.drift[0], m.drift[1], m.drift[2]);
  return out;
}

// ------------------------------------------------------------------------------ analyze

py::dict analyze_py(const std::filesystem::path& path, bool subtract_drift,
                    const std::string& wall_distance, const std::optional<std::string>& container,
                    const std::string& hole_contacts, const std::vector<std::string>& pdf,
                    const std::optional<std::string>& window, std::size_t pdf_bins,
                    const std::string& pdf_scale, const std::optional<std::string>& pdf_range) {
  if (pdf_scale != "linear" && pdf_scale != "log") {
    throw Error("pdf_scale '" + pdf_scale + "': expected linear or log");
  }
  const TrajectoryReader run(path);
  AnalysisOptions o;
  o.motion.subtract_drift = subtract_drift;
  o.motion.wall_distance = parse_length(wall_distance, run.header().length_unit, "wall_distance");
  if (container) o.motion.box = parse_box(*container, "container");
  o.motion.hole_contacts = hole_contact_policy(hole_contacts, "hole_contacts");
  o.pdf_quantities = pdf;
  if (window) o.pdf_frames = parse_int_range(*window, "window");
  o.density.bins = pdf_bins;
  o.density.scale = pdf_scale == "log" ? BinScale::logarithmic : BinScale::linear;
  if (pdf_range) o.density.range = parse_range(*pdf_range, "pdf_range");
  MotionAnalysis a;
  {
    py::gil_scoped_release release;
    a = analyze_motion(run, o);
  }
  py::dict pdfs;
  for (const auto& [quantity, table] : a.pdfs)
    pdfs[py::str(quantity)] = table_result(table);
  py::dict out;
  out["displacements"] = table_result(a.displacements);
  out["per_frame"] = table_result(a.per_frame);
  out["pdfs"] = pdfs;
  out["length_unit"] = a.length_unit;
  out["notes"] = a.notes;
  return out;
}

// ------------------------------------------------------------------------------ simulate

// What a job running on another thread reports: a line of what it does, or a cycle done.
struct Report {
  std::string line;      // what the job does, or a run's progress as the CLI prints it
  CyclicProgress cycle;  // cycles == 0: a line only
};

// Reports queued by the job's thread, handed to Python on its own (main) thread.
class ReportQueue {
 public:
  void push(Report r) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      reports_.push_back(std::move(r));
    }
    ready_.notify_one();
  }
  void finish() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      finished_ = true;
    }
    ready_.notify_one();
  }
  // Waits up to `timeout` for reports or the end; returns those queued, and whether the job
  // has finished.
  std::vector<Report> wait(std::chrono::milliseconds timeout, bool* finished) {
    std::unique_lock<std::mutex> lock(mutex_);
    ready_.wait_for(lock, timeout, [&] { return finished_ || !reports_.empty(); });
    *finished = finished_;
    return std::exchange(reports_, {});
  }

 private:
  std::mutex mutex_;
  std::condition_variable ready_;
  std::vector<Report> reports_;
  bool finished_ = false;
};

py::dict report_dict(const Report& r) {
  py::dict d;
  if (!r.line.empty()) d["line"] = r.line;
  if (r.cycle.cycles == 0) return d;
  d["cycle"] = r.cycle.cycle;
  d["cycles"] = r.cycle.cycles;
  d["particle_steps_per_second"] = r.cycle.particle_steps_per_second;
  d["seconds_left"] = r.cycle.seconds_left;
  return d;
}

// Runs `job` on its own thread while Python's thread waits in 0.1 s slices without the GIL:
// between them it hands the reports to `progress` (a callable taking a dict, or None) and
// looks for Ctrl-C, which sets `stop` (the job then stops at its next check, a checkpoint
// written) and is raised as KeyboardInterrupt once the job has returned.
template <class Job>
auto run_interruptible(Job job, ReportQueue& queue, std::atomic<bool>& stop,
                       const py::object& progress) {
  decltype(job()) result{};
  std::exception_ptr failure;
  std::thread worker([&] {
    try {
      result = job();
    } catch (...) {
      failure = std::current_exception();
    }
    queue.finish();
  });
  std::optional<py::error_already_set> interrupt;
  for (bool finished = false; !finished;) {
    std::vector<Report> reports;
    {
      py::gil_scoped_release release;
      reports = queue.wait(std::chrono::milliseconds(100), &finished);
    }
    for (const Report& r : reports) {
      if (progress.is_none() || interrupt) continue;
      try {
        progress(report_dict(r));
      } catch (py::error_already_set& e) {  // the callback raised: stop, and raise it after
        interrupt.emplace(std::move(e));
        stop = true;
      }
    }
    if (!interrupt && PyErr_CheckSignals() != 0) {
      interrupt.emplace();  // takes Python's pending KeyboardInterrupt
      stop = true;
    }
  }
  {
    py::gil_scoped_release release;
    worker.join();
  }
  // Stopped: the job's own error (e.g. "stopped after 3 of 8 runs") is the interrupt's echo.
  if (interrupt) throw std::move(*interrupt);
  if (failure) std::rethrow_exception(failure);
  return result;
}

// A job that says what it does a line at a time and stops on a flag (locate, link): the
// queue of its lines and the flag, for run_interruptible.
struct LineJob {
  ReportQueue queue;
  std::atomic<bool> stop{false};
  std::function<void(const std::string&)> log() {
    return [this](const std::string& line) { queue.push(Report{line, {}}); };
  }
};

// ---------------------------------- locate on its own thread: its stages as progress, Ctrl-C

py::tuple locate_py(const py::array& array, const std::string& diameter,
                    const std::optional<Vector3>& voxel_size, const std::string& unit,
                    std::int64_t frame, const std::string& polarity, double hole_fraction,
                    const std::string& beam, const std::string& axis, int passes, bool illumination,
                    const py::object& progress) {
  Stack stack = stack_of(array, voxel_size, unit);  // a copy: the caller's array stays as it is
  LocateOptions o =
      locate_options(stack, diameter, polarity, hole_fraction, beam, axis, passes, illumination);
  LineJob job;
  o.log = job.log();
  o.stop = &job.stop;
  LocateSummary sum;
  const Detections d = run_interruptible(
      [&] {
        Detections found = locate(std::move(stack), o, &sum);
        found.frame = frame;
        return found;
      },
      job.queue, job.stop, progress);
  py::dict summary;
  summary["candidates"] = sum.candidates;
  summary["located"] = sum.located;
  summary["rejected"] = sum.rejected;
  summary["on_edge"] = sum.on_edge;
  summary["seconds"] = sum.seconds;
  summary["length_unit"] = d.length_unit;
  summary["voxel_size"] = optional_vector(d.voxel_size);
  const Table t = to_table(d);
  return py::make_tuple(columns_of(t), units_of(t), summary);
}

// ------------------------------------ link on its own thread: its scans as progress, Ctrl-C

py::tuple link_py(const py::list& scans, const std::string& length_unit,
                  const std::optional<Vector3>& voxel_size, const std::string& max_displacement,
                  int memory, bool collective_motion, const std::optional<std::string>& container,
                  const std::optional<std::string>& container_size, const py::object& progress) {
  if (!is_length_unit(length_unit)) {
    throw Error("length_unit '" + length_unit + "': expected m, cm, mm, um or voxel");
  }
  LinkRunOptions o;
  o.max_displacement = max_displacement;
  o.memory = memory;
  o.collective_motion = collective_motion;
  o.container = container.value_or("");
  o.container_size = container_size.value_or("");
  o.validate();
  std::vector<Detections> found;
  std::vector<std::string> names;
  for (const py::handle& scan : scans) {
    const auto pair = scan.cast<py::tuple>();
    found.push_back(detections_of(pair[0].cast<py::dict>(), pair[1].cast<std::int64_t>(),
                                  length_unit, voxel_size));
    names.push_back(found.back().source);
  }
  LineJob job;
  o.log = job.log();
  o.stop = &job.stop;
  const LinkRun linked = run_interruptible([&] { return link_run(std::move(found), names, o); },
                                           job.queue, job.stop, progress);
  const LinkSummary& sum = linked.summary;
  const Trajectories& run = linked.run;
  py::list per_scan;
  for (const ScanLinks& r : sum.scans) {
    py::dict d;
    d["frame"] = r.frame;
    d["detections"] = r.detections;
    d["linked"] = r.linked;
    d["relinked"] = r.relinked;
    d["started"] = r.started;
    d["lost"] = r.unlinked;
    d["linked_fraction"] = r.linked_fraction();
    d["rms_residual"] = r.rms_residual;
    per_scan.append(d);
  }
  py::dict summary;
  summary["tracks"] = sum.tracks;
  summary["max_displacement"] = sum.max_displacement;
  summary["length_unit"] = sum.length_unit;
  summary["notes"] = linked.notes;
  summary["report"] = linked.Report();
  summary["scans"] = per_scan;
  const Table t = trajectory_table(run);
  return py::make_tuple(columns_of(t), units_of(t), summary);
}

std::string setting_text(const py::handle& value) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value)) {
    return py::str(py::repr(value));
  }
  if (py::isinstance<py::sequence>(value)) {  // a list of grain ids or cycles
    std::string text;
    for (const py::handle& item : value.cast<py::sequence>())
      text += (text.empty() ? "" : ",") + setting_text(item);
    return text;
  }
  throw Error("a setting must be text, a number, a bool or a list, got " +
              std::string(py::str(value.get_type())));
}

// Keyword arguments (`_` for `-`) onto a job's settings; `allowed` says which names the
// job takes (`refused`'s % is the name). Returns the names set.
std::set<std::string> set_settings(const py::dict& given, RunSettings& settings,
                                   const std::function<bool(const std::string&)>& allowed,
                                   const std::string& refused) {
  std::set<std::string> names;
  for (const auto& [key, value] : given) {
    std::string name = py::str(key);
    std::replace(name.begin(), name.end(), '_', '-');
    if (!allowed(name)) {
      std::string message = refused;
      throw Error(message.replace(message.find('%'), 1, name));
    }
    settings[name] = setting_text(value);
    names.insert(name);
  }
  return names;
}

py::dict simulate_py(const py::dict& settings, const std::string& resume,
                     const std::string& start_from, int threads, const py::object& progress) {
  SimulateOptions o;
  o.given = set_settings(
      settings, o.settings, [&](const std::string& name) { return o.settings.count(name) > 0; },
      "simulate: no setting '%' (see granmem simulate --help)");
  o.resume = resume;
  o.start_from = start_from;
  o.threads = threads;
  ReportQueue queue;
  std::atomic<bool> stop{false};
  o.log = [&](const std::string& line) { queue.push({line, {}}); };
  o.progress = [&](const CyclicProgress& p) { queue.push({"", p}); };
  o.stop = &stop;
  const SimulateSummary s = run_interruptible([&] { return simulate(o); }, queue, stop, progress);
  py::dict out;
  out["settings"] = s.settings;
  out["grains"] = s.grains;
  out["cycles_done"] = s.cycles.cycles_done;
  out["particle_steps_per_second"] = s.cycles.particle_steps_per_second;
  std::vector<std::string> written;
  for (const auto& p : s.cycles.written)
    written.push_back(p.string());
  out["written"] = written;
  out["checkpoint"] = s.checkpoint;
  out["report"] = s.Report();
  return out;
}

// ------------------------------------------------------------------------------ readout

py::dict readout_py(const std::vector<std::filesystem::path>& states,
                    const std::filesystem::path& out, const std::string& amplitudes,
                    std::int64_t cycles, const std::string& drive, const std::string& wall_motion,
                    double inertial_number, bool training_amplitude, int parallel,
                    std::size_t bootstrap, const py::object& progress) {
  ReadoutOptions o;
  o.sweep.states = states;
  o.sweep.amplitudes = parse_amplitude_sweep(amplitudes);
  o.sweep.cycles = cycles;
  o.sweep.symmetry = parse_drive_symmetry(drive);
  o.sweep.shape = parse_drive_shape(wall_motion);
  o.sweep.inertial_number = inertial_number;
  o.sweep.include_training_amplitude = training_amplitude;
  o.sweep.pool.parallel = parallel;
  o.sweep.dir = out;
  o.bootstrap = bootstrap;
  ReportQueue queue;
  std::atomic<bool> stop{false};
  o.sweep.pool.stop = &stop;
  const ReadoutSummary s = run_interruptible(
      [&] {
        return readout(o, [&](const ReadoutSweepProgress& p) {
          queue.push(
              {"readout: " + std::to_string(p.done) + "/" + std::to_string(p.runs) + " runs done",
               {}});
        });
      },
      queue, stop, progress);
  py::dict d;
  d["points"] = table_result(readout_table(s.points));
  d["signatures"] = table_result(signature_table(s.signatures));
  d["diameter"] = s.diameter;
  d["table"] = s.table.string();
  d["signature_table"] = s.signature_table.string();
  return d;
}

// ---------------------------------------------------------------------------- calibrate

py::dict calibrate_py(const std::filesystem::path& experiment, const std::filesystem::path& out,
                      const std::optional<std::string>& mu_s,
                      const std::optional<std::string>& mu_r, const std::string& observables,
                      const std::vector<std::string>& only,
                      const std::optional<std::string>& window, const std::string& noise,
                      const std::string& summaries, const std::string& wall_distance,
                      bool subtract_drift, int degree, const std::optional<int>& replicas,
                      const std::optional<int>& refine, const std::string& axis_noise,
                      const std::string& deposit, const std::string& placed_jitter,
                      const std::string& placed_cycle, bool fit_only,
                      const std::optional<bool>& one_cycle_ahead, int ahead_burn_in,
                      const std::optional<double>& true_mu_s,
                      const std::optional<double>& true_mu_r, int parallel, const py::dict& twin,
                      const py::object& progress) {
  CalibrateOptions o;
  o.experiment = experiment;
  o.out = out;
  o.twin_given =
      set_settings(twin, o.twin, is_twin_setting,
                   "calibrate: '%' is not a setting of the twin (see granmem calibrate --help)");
  if (mu_s) o.mu_s = parse_frictions(*mu_s, "mu_s");
  if (mu_r) o.mu_r = parse_frictions(*mu_r, "mu_r");
  if (observables != "displacements" && observables != "steady-state") {
    throw Error("observables '" + observables + "': expected displacements or steady-state");
  }
  o.observables = observables == "steady-state" ? CalibrationObservables::steady_state
                                                : CalibrationObservables::displacements;
  o.only = only;
  if (window) o.set_window(*window, "window");
  o.noise = noise;
  if (summaries != "pooled" && summaries != "per-cycle") {
    throw Error("summaries '" + summaries + "': expected pooled or per-cycle");
  }
  o.per_cycle = summaries == "per-cycle";
  o.wall_distance = parse_si(wall_distance, Dimension::length, "m", "wall_distance");
  o.subtract_drift = subtract_drift;
  o.degree = degree;
  if (replicas) {
    if (*replicas < 1) throw Error("replicas: at least one packing");
    o.replicas = *replicas;
  }
  o.refine = refine;  // none: the design's own
  o.axis_noise = parse_axis_noise(axis_noise, "axis_noise");
  o.preparation = preparation_named(deposit, "deposit");
  o.placed_jitter = parse_placed_jitter(placed_jitter, "placed_jitter");
  o.placed_cycle = parse_placed_cycle(placed_cycle, "placed_cycle");
  o.fit_only = fit_only;
  o.one_cycle_ahead = one_cycle_ahead;
  o.ahead_burn_in = ahead_burn_in;
  o.true_mu_s = true_mu_s;
  o.true_mu_r = true_mu_r;
  o.parallel = parallel;
  ReportQueue queue;
  std::atomic<bool> stop{false};
  o.log = [&](const std::string& line) { queue.push({line, {}}); };
  o.progress = [&](const FrictionRunSpec& run, const CyclicProgress& p) {
    queue.push({friction_run_progress(run, p), p});
  };
  o.stop = &stop;
  const CalibrateSummary s = run_interruptible([&] { return calibrate(o); }, queue, stop, progress);
  py::dict d;
  d["mu_s"] = s.mu_s;
  d["mu_s_ci95"] = py::make_tuple(s.mu_s_ci95[0], s.mu_s_ci95[1]);
  if (s.mu_r >= 0) {
    d["mu_r"] = s.mu_r;
    d["mu_r_ci95"] = py::make_tuple(s.mu_r_ci95[0], s.mu_r_ci95[1]);
    d["correlation"] = s.correlation;
  }
  d["true_mu_s"] = s.true_mu_s;
  d["true_mu_r"] = s.true_mu_r;
  d["simulations"] = s.simulations;
  d["simulations_fitted"] = s.simulations_fitted;
  d["notes"] = s.notes;
  std::vector<std::string> written;
  for (const auto& p : s.written)
    written.push_back(p.string());
  d["written"] = written;
  d["report"] = s.Report();
  return d;
}

// ------------------------------------------------------------------------------ compare

py::dict compare_py(const std::filesystem::path& a, const std::filesystem::path& b,
                    const std::filesystem::path& out, const std::optional<std::string>& window,
                    const std::optional<std::string>& diameter, const std::string& label_a,
                    const std::string& label_b, const std::string& wall_distance,
                    bool subtract_drift, std::size_t steady_points) {
  const TrajectoryReader run_a(a), run_b(b);
  CompareOptions o;
  o.label_a = label_a;
  o.label_b = label_b;
  if (window) o.window = parse_int_range(*window, "window");
  if (diameter) o.diameter = parse_si(*diameter, Dimension::length, "", "diameter");
  o.wall_distance = parse_si(wall_distance, Dimension::length, "m", "wall_distance");
  o.subtract_drift = subtract_drift;
  o.steady_points = steady_points;
  o.dir = out;
  Comparison c;
  {
    py::gil_scoped_release release;
    c = compare(run_a, run_b, o);
  }
  py::dict distances;
  for (const auto& [quantity, d] : c.distances) {
    py::dict q;
    q["ks"] = d.first;
    q["wasserstein1_d"] = d.second;
    distances[py::str(quantity)] = q;
  }
  std::vector<std::string> written;
  for (const auto& p : c.written)
    written.push_back(p.string());
  py::dict r;
  r["distances"] = distances;
  r["written"] = written;
  r["notes"] = c.notes;
  r["report"] = c.Report();
  return r;
}

}  // namespace
}  // namespace granmem::python

PYBIND11_MODULE(_granmem, m) {
  using namespace granmem;
  using namespace granmem::python;
  m.doc() = "granmem's libraries: locate, link, render, trajectory stores, grain motion";
  m.attr("__version__") = granmem::kVersion;
  m.attr("QUASI_STATIC_INERTIAL_NUMBER") = granmem::kQuasiStaticInertialNumber;
  static py::exception<Error> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      error(e.what());
    }
  });

  m.def(
      "info", [](const std::filesystem::path& path) { return run_info(path); }, py::arg("path"));
  m.def("set_author", &set_default_author, py::arg("name"));
  m.def("read_stack", &read_stack_py, py::arg("path"), py::arg("dataset") = "",
        py::arg("region") = py::none());
  m.def("write_tiff", &write_tiff_py, py::arg("stack"), py::arg("path"),
        py::arg("voxel_size") = py::none(), py::arg("unit") = "");
  m.def("locate", &locate_py, py::arg("stack"), py::arg("diameter"),
        py::arg("voxel_size") = py::none(), py::arg("unit") = "", py::arg("frame") = 0,
        py::arg("polarity") = "dark", py::arg("hole_fraction") = LocateOptions{}.hole_fraction,
        py::arg("beam") = "x", py::arg("axis") = "fit", py::arg("passes") = LocateOptions{}.passes,
        py::arg("illumination") = true, py::arg("progress") = py::none());
  m.def("render", &render_py, py::arg("grains"), py::arg("length_unit"),
        py::arg("diameter_px") = RenderOptions{}.diameter_px,
        py::arg("slice_spacing_ratio") = RenderOptions{}.slice_spacing_ratio,
        py::arg("clean") = false, py::arg("hole_fraction") = RenderOptions{}.hole_fraction,
        py::arg("polarity") = "dark", py::arg("bits") = RenderOptions{}.bits,
        py::arg("seed") = RenderOptions{}.seed, py::arg("frame") = 0);
  m.def("link", &link_py, py::arg("scans"), py::arg("length_unit"),
        py::arg("voxel_size") = py::none(), py::arg("max_displacement") = "auto",
        py::arg("memory") = LinkOptions{}.memory, py::arg("collective_motion") = true,
        py::arg("container") = py::none(), py::arg("container_size") = py::none(),
        py::arg("progress") = py::none());
  m.def(
      "read_run", [](const std::filesystem::path& path) { return run_arrays(read_run(path)); },
      py::arg("path"));
  m.def(
      "track_table",
      [](const std::filesystem::path& path) {
        return table_result(trajectory_table(read_run(path)));
      },
      py::arg("path"));
  m.def("write_run", &write_run_py, py::arg("columns"), py::arg("path"), py::arg("length_unit"),
        py::arg("radius") = py::none(), py::arg("readings") = py::none());
  m.def("simulate", &simulate_py, py::arg("settings"), py::arg("resume") = "",
        py::arg("start_from") = "", py::arg("threads") = 0, py::arg("progress") = py::none());
  m.def("calibrate", &calibrate_py, py::arg("experiment"), py::arg("out"),
        py::arg("mu_s") = py::none(), py::arg("mu_r") = py::none(),
        py::arg("observables") = "steady-state", py::arg("only") = std::vector<std::string>{},
        py::arg("window") = py::none(), py::arg("noise") = "auto", py::arg("summaries") = "pooled",
        py::arg("wall_distance") = "0", py::arg("subtract_drift") = true,
        py::arg("degree") = CalibrateOptions{}.degree, py::arg("replicas") = py::none(),
        py::arg("refine") = py::none(), py::arg("axis_noise") = "auto", py::arg("deposit") = "auto",
        py::arg("placed_jitter") = "auto", py::arg("placed_cycle") = "auto",
        py::arg("fit_only") = false, py::arg("one_cycle_ahead") = py::none(),
        py::arg("ahead_burn_in") = CalibrateOptions{}.ahead_burn_in,
        py::arg("true_mu_s") = py::none(), py::arg("true_mu_r") = py::none(),
        py::arg("parallel") = 0, py::arg("twin") = py::dict(), py::arg("progress") = py::none());
  m.def("compare", &compare_py, py::arg("a"), py::arg("b"), py::arg("out"),
        py::arg("window") = py::none(), py::arg("diameter") = py::none(),
        py::arg("label_a") = CompareOptions{}.label_a,
        py::arg("label_b") = CompareOptions{}.label_b, py::arg("wall_distance") = "0",
        py::arg("subtract_drift") = true, py::arg("steady_points") = 0);
  m.def("readout", &readout_py, py::arg("states"), py::arg("out"),
        py::arg("amplitudes") = "0.05%:2.5%:12", py::arg("cycles") = 1,
        py::arg("drive") = "asymmetric", py::arg("wall_motion") = "cosine",
        py::arg("inertial_number") = ReadoutSweepOptions{}.inertial_number,
        py::arg("training_amplitude") = true, py::arg("parallel") = 0,
        py::arg("bootstrap") = ReadoutOptions{}.bootstrap, py::arg("progress") = py::none());
  m.def("analyze", &analyze_py, py::arg("path"), py::arg("subtract_drift") = false,
        py::arg("wall_distance") = "0", py::arg("container") = py::none(),
        py::arg("hole_contacts") = "keep", py::arg("pdf") = std::vector<std::string>{},
        py::arg("window") = py::none(), py::arg("pdf_bins") = 50, py::arg("pdf_scale") = "linear",
        py::arg("pdf_range") = py::none());
  m.def(
      "motion_of_run",
      [](const std::filesystem::path& path, std::int64_t before, std::int64_t after,
         bool subtract_drift, const std::string& wall_distance, const std::string& hole_contacts) {
        return motion_of(read_run(path), before, after, subtract_drift, wall_distance,
                         hole_contacts);
      },
      py::arg("path"), py::arg("before"), py::arg("after"), py::arg("subtract_drift") = false,
      py::arg("wall_distance") = "0", py::arg("hole_contacts") = "keep");
  m.def(
      "motion_of_table",
      [](const py::dict& columns, const std::string& length_unit, std::int64_t before,
         std::int64_t after, bool subtract_drift, const std::string& wall_distance,
         const std::string& hole_contacts) {
        return motion_of(run_of_table(columns, length_unit, std::nullopt), before, after,
                         subtract_drift, wall_distance, hole_contacts);
      },
      py::arg("columns"), py::arg("length_unit"), py::arg("before"), py::arg("after"),
      py::arg("subtract_drift") = false, py::arg("wall_distance") = "0",
      py::arg("hole_contacts") = "keep");
}
