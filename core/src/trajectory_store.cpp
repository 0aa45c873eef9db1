#include "granmem/core/trajectory_store.hpp"

#include <cstdlib>
#include <set>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/units.hpp"
#include "granmem/core/version.hpp"
#include "granmem/core/xdmf.hpp"

namespace granmem {
namespace {

constexpr const char* kGrains = "/particles/grains";

// H5MD's units module (system SI) allows unit symbols such as cm, s, N; granmem's voxel and
// cycle are none, and a dimensionless quantity has no unit: those go in an attribute of
// granmem's own, `granmem_unit`, which other readers ignore.
bool is_h5md_unit(const std::string& unit) {
  static const std::set<std::string> si{"m", "cm", "mm", "um", "s", "N", "J", "Pa", "kg", "rad"};
  return si.count(unit) > 0;
}
std::string h5md_unit(const std::string& unit) {
  return is_h5md_unit(unit) ? unit : std::string();
}
// A unit only granmem has (voxel, cycle): it goes in `granmem_unit`.
bool is_granmem_only_unit(const std::string& unit) {
  return !unit.empty() && unit != "1" && !is_h5md_unit(unit);
}
void mark_granmem_unit(hid_t obj, const std::string& unit) {
  if (is_granmem_only_unit(unit)) {
    h5::write_attribute(obj, "granmem_unit", unit);
  }
}
template <class T>
void write_with_unit(hid_t loc, const std::string& name, const T* data,
                     const std::vector<hsize_t>& dims, const std::string& unit) {
  h5::write(loc, name, data, dims, h5md_unit(unit));
  if (is_granmem_only_unit(unit)) {
    const h5::Handle set(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
    mark_granmem_unit(set.get(), unit);
  }
}
// A dataset's unit as granmem wrote it (H5MD's `unit`, else `granmem_unit`), or `fallback`.
std::string unit_of(hid_t obj, const std::string& fallback) {
  if (auto u = h5::read_string_attribute(obj, "unit")) return *u;
  return h5::read_string_attribute(obj, "granmem_unit").value_or(fallback);
}

// A time-dependent H5MD element: value[T,...], step[T], time[T], grown frame by frame.
struct ElementWriter {
  h5::Handle group, value, step, time;

  template <class T>
  static ElementWriter create(hid_t file, const std::string& path,
                              const std::vector<hsize_t>& frame_dims, const std::string& unit,
                              const std::string& time_unit) {
    ElementWriter e;
    e.group = h5::create_group(file, path);
    e.value = h5::create_frames<T>(e.group.get(), "value", frame_dims, h5md_unit(unit));
    mark_granmem_unit(e.value.get(), unit);
    e.step = h5::create_frames<std::int64_t>(e.group.get(), "step", {}, "");
    e.time = h5::create_frames<double>(e.group.get(), "time", {}, h5md_unit(time_unit));
    mark_granmem_unit(e.time.get(), time_unit);
    return e;
  }

  // An element of a file written before, cut to its first `frames` frames.
  static ElementWriter open(const h5::File& file, const std::string& path, hsize_t frames) {
    ElementWriter e;
    e.group = h5::open_group(file, path);
    e.value = h5::open_dataset(file, path + "/value");
    e.step = h5::open_dataset(file, path + "/step");
    e.time = h5::open_dataset(file, path + "/time");
    for (const h5::Handle* d : {&e.value, &e.step, &e.time})
      h5::truncate_frames(d->get(), frames);
    return e;
  }

  template <class T>
  void append(const T* data, const Frame& frame) const {
    h5::append_frame(value.get(), data);
    h5::append_frame(step.get(), &frame.step);
    h5::append_frame(time.get(), &frame.time);
  }
};

// "<group>/<key>" -> attribute `key` on group /parameters/<group>.
void write_parameters(hid_t file, const std::map<std::string, std::string>& parameters) {
  h5::Handle root = h5::create_group(file, "/parameters");
  for (const auto& [key, value] : parameters) {
    const std::size_t slash = key.rfind('/');
    if (slash == std::string::npos) {
      h5::write_attribute(root.get(), key, value);
    } else {
      h5::Handle g = h5::create_group(root.get(), key.substr(0, slash));
      h5::write_attribute(g.get(), key.substr(slash + 1), value);
    }
  }
}

// /parameters: what produced the file, and the voxel size of image data.
void write_run_parameters(hid_t file, const RunHeader& h) {
  write_parameters(file, h.parameters);
  if (h.voxel_size) {
    h5::Handle params = h5::create_group(file, "/parameters");
    write_with_unit(params.get(), "voxel_size", h.voxel_size->data(), {3}, h.length_unit);
  }
}

void read_parameters(const h5::File& file, const std::string& path, const std::string& prefix,
                     std::map<std::string, std::string>& out) {
  h5::Handle g = h5::open_group(file, path);
  for (const std::string& name : h5::attribute_names(g.get())) {
    if (auto v = h5::read_string_attribute(g.get(), name)) out[prefix + name] = *v;
  }
  for (const std::string& name : h5::member_names(g.get())) {
    const h5::Handle member(H5Oopen(g.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
    if (H5Iget_type(member.get()) == H5I_GROUP) {
      read_parameters(file, path + "/" + name, prefix + name + "/", out);
    }
  }
}

// An H5MD element's step or time: one entry per frame, or (H5MD's fixed interval) a scalar
// increment with an optional `offset`: entry i = i x increment + offset.
template <class T>
std::vector<T> frame_labels(const h5::File& file, const std::string& path, hsize_t frames) {
  const h5::Handle set = h5::open_dataset(file, path);
  std::vector<T> v = h5::read<T>(file, path);
  if (!h5::shape(set.get()).empty()) return v;
  const double offset = h5::read_number_attribute(set.get(), "offset").value_or(0);
  std::vector<T> out(frames);
  for (hsize_t i = 0; i < frames; ++i)
    out[i] = static_cast<T>(double(i) * double(v.at(0)) + offset);
  return out;
}

std::string& author_given() {
  static std::string name;
  return name;
}

std::string default_author() {
  if (!author_given().empty()) return author_given();
  const char* user = std::getenv("USER");
  return user && *user ? user : "unknown";
}

}  // namespace

void set_default_author(const std::string& name) {
  author_given() = name;
}

struct TrajectoryWriter::Impl {
  RunHeader header;
  AtomicFile out;
  h5::File file;
  ElementWriter position, axis, orientation, hole_contact, position_error, axis_error;
  std::map<std::string, Observable> observables;
  std::vector<std::int64_t> steps;
  std::vector<double> times;

  Impl(const std::filesystem::path& path, RunHeader h)
      : header(std::move(h)), out(path), file(h5::File::create(out)) {}
  Impl(RunHeader h, h5::File opened, AtomicFile temp)
      : header(std::move(h)), out(std::move(temp)), file(std::move(opened)) {}

  void check_open(const std::string& what) const {
    if (file.id() < 0) throw Error(out.target().string() + ": cannot " + what + " after commit()");
  }
  bool parameters_changed = false;

  // Observables are written whole, replacing what an earlier publish() wrote; so are the
  // parameters when they changed.
  void write_observables() {
    if (parameters_changed) {
      h5::remove(file.id(), "/parameters");
      write_run_parameters(file.id(), header);
      parameters_changed = false;
    }
    h5::remove(file.id(), "/observables");
    for (const auto& [name, obs] : observables) {
      h5::Handle g = h5::create_group(file.id(), "/observables/" + name);
      const std::vector<hsize_t> dims{obs.value.size()};
      write_with_unit(g.get(), "value", obs.value.data(), dims, obs.unit);
      h5::write(g.get(), "step", obs.step.data(), dims, "");
      write_with_unit(g.get(), "time", obs.time.data(), dims, header.time_unit);
    }
  }
};

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& path, RunHeader header) {
  check_header(header, path.string());
  impl_ = std::make_unique<Impl>(path, std::move(header));
  const RunHeader& h = impl_->header;
  const hid_t f = impl_->file.id();
  const hsize_t n = h.grain_count();

  h5::Handle h5md = h5::create_group(f, "/h5md");
  h5::write_attribute(h5md.get(), "version", std::vector<int>{1, 1});
  h5::Handle author = h5::create_group(h5md.get(), "author");
  h5::write_attribute(author.get(), "name", h.author.empty() ? default_author() : h.author);
  h5::Handle creator = h5::create_group(h5md.get(), "creator");
  h5::write_attribute(creator.get(), "name", h.creator_name);
  h5::write_attribute(creator.get(), "version",
                      h.creator_version.empty() ? std::string(kVersion) : h.creator_version);
  h5::Handle units = h5::create_group(h5md.get(), "modules/units");
  h5::write_attribute(units.get(), "version", std::vector<int>{1, 0});
  h5::write_attribute(units.get(), "system", std::string("SI"));

  h5::Handle grains = h5::create_group(f, kGrains);
  h5::write(grains.get(), "id", h.id.data(), {n}, "");
  write_with_unit(grains.get(), "radius", h.radius.data(), {n}, h.length_unit);
  h5::Handle box = h5::create_group(grains.get(), "box");
  h5::write_attribute(box.get(), "dimension", std::vector<int>{3});
  h5::write_attribute(box.get(), "boundary", std::vector<std::string>{"none", "none", "none"});
  if (h.box) {
    write_with_unit(box.get(), "edges", h.box->edges.data(), {3}, h.length_unit);
    write_with_unit(box.get(), "offset", h.box->lower.data(), {3}, h.length_unit);
  }

  impl_->position = ElementWriter::create<double>(f, std::string(kGrains) + "/position", {n, 3},
                                                  h.length_unit, h.time_unit);
  h5::write_attribute(impl_->position.group.get(), "sample", h.sample);
  if (h.has_axis) {
    impl_->axis =
        ElementWriter::create<double>(f, std::string(kGrains) + "/axis", {n, 3}, "", h.time_unit);
  }
  if (h.has_orientation) {
    impl_->orientation = ElementWriter::create<double>(f, std::string(kGrains) + "/orientation",
                                                       {n, 4}, "", h.time_unit);
  }
  if (h.has_hole_contact) {
    impl_->hole_contact = ElementWriter::create<std::uint8_t>(
        f, std::string(kGrains) + "/hole_contact", {n}, "", h.time_unit);
  }
  if (h.has_position_error) {
    impl_->position_error = ElementWriter::create<double>(
        f, std::string(kGrains) + "/position_error", {n, 3}, h.length_unit, h.time_unit);
  }
  if (h.has_axis_error) {
    impl_->axis_error = ElementWriter::create<double>(f, std::string(kGrains) + "/axis_error", {n},
                                                      "rad", h.time_unit);
  }

  write_run_parameters(f, h);
}

void TrajectoryWriter::set_parameters(std::map<std::string, std::string> parameters) {
  impl_->check_open("set parameters");
  impl_->header.parameters = std::move(parameters);
  impl_->parameters_changed = true;
}

TrajectoryWriter::~TrajectoryWriter() = default;

void TrajectoryWriter::append(const Frame& frame) {
  Impl& w = *impl_;
  w.check_open("append");
  check_frame(w.header, frame,
              w.out.target().string() + " frame " + std::to_string(w.steps.size()));
  w.position.append(frame.position.data(), frame);
  if (w.header.has_axis) w.axis.append(frame.axis.data(), frame);
  if (w.header.has_orientation) w.orientation.append(frame.orientation.data(), frame);
  if (w.header.has_hole_contact) w.hole_contact.append(frame.hole_contact.data(), frame);
  if (w.header.has_position_error) w.position_error.append(frame.position_error.data(), frame);
  if (w.header.has_axis_error) w.axis_error.append(frame.axis_error.data(), frame);
  w.steps.push_back(frame.step);
  w.times.push_back(frame.time);
}

void TrajectoryWriter::set_observable(const std::string& name, Observable observable) {
  if (observable.step.size() != observable.value.size() ||
      observable.time.size() != observable.value.size()) {
    throw Error("observable " + name + ": value, step and time must have equal lengths");
  }
  impl_->check_open("set observable " + name);
  impl_->observables[name] = std::move(observable);
}

std::size_t TrajectoryWriter::frame_count() const {
  return impl_->steps.size();
}

void TrajectoryWriter::publish() {
  Impl& w = *impl_;
  w.check_open("publish");
  w.write_observables();
  w.file.flush();
  // A copy of the flushed file goes into place; the original stays open for writing.
  AtomicFile copy(w.out.target());
  std::error_code ec;
  std::filesystem::copy_file(w.out.temp_path(), copy.temp_path(),
                             std::filesystem::copy_options::overwrite_existing, ec);
  if (ec) throw Error(w.out.target().string() + ": cannot publish: " + ec.message());
  AtomicFile sidecar = write_xdmf(w.out.target(), kGrains, w.header, w.steps, w.times);
  sidecar.commit();  // before the store: a store in place always has its sidecar
  copy.commit();
}

void TrajectoryWriter::commit() {
  Impl& w = *impl_;
  w.check_open("commit");
  w.write_observables();
  w.position = {};
  w.axis = {};
  w.orientation = {};
  w.hole_contact = {};
  w.position_error = {};
  w.axis_error = {};
  w.file.close();
  // Sidecar first: if it cannot be written, an existing run of this name stays as it was;
  // and it is renamed into place first, so that a store in place (what a later call reads
  // to reuse a finished run) always has its sidecar, even if the process is killed
  // between the two renames (the sidecar's temporary is then not left behind either).
  AtomicFile sidecar = write_xdmf(w.out.target(), kGrains, w.header, w.steps, w.times);
  sidecar.commit();
  w.out.commit();
}

TrajectoryWriter TrajectoryWriter::resume(const std::filesystem::path& path,
                                          std::size_t keep_frames) {
  RunHeader header;
  std::map<std::string, Observable> observables;
  std::vector<std::int64_t> steps;
  std::vector<double> times;
  {
    const TrajectoryReader before(path);
    if (keep_frames > before.frame_count()) {
      throw Error(path.string() + ": has " + std::to_string(before.frame_count()) +
                  " frames, cannot continue after frame " + std::to_string(keep_frames));
    }
    if (before.particles_group() != kGrains) {
      throw Error(path.string() + ": only granmem's own runs can be continued");
    }
    header = before.header();
    steps.assign(before.steps().begin(), before.steps().begin() + std::ptrdiff_t(keep_frames));
    times.assign(before.times().begin(), before.times().begin() + std::ptrdiff_t(keep_frames));
    // Observables of steps after the last kept frame belong to the part that is redone.
    const std::int64_t last = keep_frames ? steps.back() : std::numeric_limits<std::int64_t>::min();
    for (const auto& [name, obs] : before.observables()) {
      Observable kept;
      kept.unit = obs.unit;
      for (std::size_t k = 0; k < obs.value.size(); ++k) {
        if (obs.step[k] > last) continue;
        kept.value.push_back(obs.value[k]);
        kept.step.push_back(obs.step[k]);
        kept.time.push_back(obs.time[k]);
      }
      observables[name] = std::move(kept);
    }
  }
  AtomicFile temp(path);
  std::error_code ec;
  std::filesystem::copy_file(path, temp.temp_path(), ec);
  if (ec) throw Error(path.string() + ": cannot copy to continue it: " + ec.message());
  h5::File file = h5::File::open_for_writing(temp.temp_path());

  TrajectoryWriter writer;
  writer.impl_ = std::make_unique<Impl>(std::move(header), std::move(file), std::move(temp));
  Impl& w = *writer.impl_;
  const std::string g = kGrains;
  w.position = ElementWriter::open(w.file, g + "/position", keep_frames);
  if (w.header.has_axis) w.axis = ElementWriter::open(w.file, g + "/axis", keep_frames);
  if (w.header.has_orientation) {
    w.orientation = ElementWriter::open(w.file, g + "/orientation", keep_frames);
  }
  if (w.header.has_hole_contact) {
    w.hole_contact = ElementWriter::open(w.file, g + "/hole_contact", keep_frames);
  }
  if (w.header.has_position_error) {
    w.position_error = ElementWriter::open(w.file, g + "/position_error", keep_frames);
  }
  if (w.header.has_axis_error) {
    w.axis_error = ElementWriter::open(w.file, g + "/axis_error", keep_frames);
  }
  w.observables = std::move(observables);
  w.steps = std::move(steps);
  w.times = std::move(times);
  return writer;
}

TrajectoryWriter::TrajectoryWriter(TrajectoryWriter&&) noexcept = default;
const std::map<std::string, Observable>& TrajectoryWriter::observables() const {
  return impl_->observables;
}
const RunHeader& TrajectoryWriter::header() const {
  return impl_->header;
}

namespace {

// The file's particles group: granmem's /particles/grains, or another H5MD producer's
// single particle group. Error for a file that is not H5MD.
std::string particles_group_of(const h5::File& file) {
  const hid_t f = file.id();
  if (!h5::exists(f, "/h5md")) {
    throw Error(file.name() + ": not a granmem/H5MD trajectory file (no /h5md group)");
  }
  std::string group = kGrains;
  if (!h5::exists(f, group) && h5::exists(f, "/particles")) {
    h5::Handle particles = h5::open_group(file, "/particles");
    const std::vector<std::string> groups = h5::member_names(particles.get());
    if (groups.size() == 1) group = "/particles/" + groups.front();
  }
  return group;
}

// The positions' dataset <pos>/value, checked to be [frames, grains, 3].
h5::Handle open_positions(const h5::File& file, const std::string& pos) {
  h5::Handle position = h5::open_dataset(file, pos + "/value");
  const std::vector<hsize_t> dims = h5::shape(position.get());
  if (dims.size() != 3 || dims[2] != 3) {
    throw Error(file.name() + ": dataset " + pos + "/value has shape " + h5::shape_text(dims) +
                ", expected [frames,grains,3]");
  }
  return position;
}

struct FrameLabels {
  std::vector<std::int64_t> steps;
  std::vector<double> times;
  std::string time_unit;
};

// Each frame's step and time. H5MD makes `time` optional: frames are then known by their
// step alone (time = step, unit "step").
FrameLabels read_frame_labels(const h5::File& file, const std::string& pos, hsize_t frames) {
  FrameLabels l;
  l.steps = frame_labels<std::int64_t>(file, pos + "/step", frames);
  if (h5::exists(file.id(), pos + "/time")) {
    l.times = frame_labels<double>(file, pos + "/time", frames);
    l.time_unit = unit_of(h5::open_dataset(file, pos + "/time").get(), "s");
  } else {
    l.times.assign(l.steps.begin(), l.steps.end());
    l.time_unit = "step";
  }
  if (l.steps.size() != frames || l.times.size() != frames) {
    throw Error(file.name() + ": " + pos + "/step and /time must have one entry per frame (" +
                std::to_string(frames) + ")");
  }
  return l;
}

// The positions' unit as the file states it into h.length_unit, checked, and what a frame
// is (`sample`). H5MD makes `unit` optional: a file without one is taken in metres. Returns
// the stated unit ("": none).
std::string read_position_header(const h5::File& file, const std::string& pos,
                                 const h5::Handle& position, RunHeader& h) {
  const std::string stated = unit_of(position.get(), "");
  h.length_unit = stated.empty() ? "m" : stated;
  if (!is_length_unit(h.length_unit)) {
    throw Error(file.name() + ": dataset " + pos + "/value has unit '" + h.length_unit +
                "', expected one of m, cm, mm, um, voxel");
  }
  h5::Handle group = h5::open_group(file, pos);
  h.sample = h5::read_string_attribute(group.get(), "sample").value_or(kSampleEndOfCycle);
  return stated;
}

// The per-grain datasets: ids (default 0 ... n-1) and radii (default NaN), one per grain.
void read_grains(const h5::File& file, const std::string& group, hsize_t n, RunHeader& h) {
  const std::string id_path = group + "/id";
  if (h5::exists(file.id(), id_path)) {
    h.id = h5::read<std::int64_t>(file, id_path);
    if (h.id.size() != n) {
      throw Error(file.name() + ": dataset " + id_path + " must hold one id per grain (" +
                  std::to_string(n) + ")");
    }
  } else {
    for (hsize_t i = 0; i < n; ++i)
      h.id.push_back(static_cast<std::int64_t>(i));
  }
  const std::string radius_path = group + "/radius";
  h.radius.assign(n, std::numeric_limits<double>::quiet_NaN());
  if (h5::exists(file.id(), radius_path)) {
    h.radius = h5::read<double>(file, radius_path);
    if (h.radius.size() != n) {
      throw Error(file.name() + ": dataset " + radius_path + " must hold one radius per grain (" +
                  std::to_string(n) + ")");
    }
  }
}

// A dataset of three values (Error naming it otherwise).
Eigen::Vector3d read_vector3(const h5::File& file, const std::string& path) {
  const std::vector<double> v = h5::read<double>(file, path);
  if (v.size() != 3) throw Error(file.name() + ": dataset " + path + " must hold 3 values");
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

// The container: <group>/box/edges and, where given, its lower corner (box/offset).
std::optional<Box> read_box(const h5::File& file, const std::string& group) {
  const std::string edges_path = group + "/box/edges";
  if (!h5::exists(file.id(), edges_path)) return std::nullopt;
  Box box;
  box.edges = read_vector3(file, edges_path);
  const std::string offset_path = group + "/box/offset";
  if (h5::exists(file.id(), offset_path)) box.lower = read_vector3(file, offset_path);
  return box;
}

// An optional per-frame element <group>/<element>/value into `out`, checked to match the
// positions frame for frame: [frames, frame_dims...]. False where the file has none.
bool open_element(const h5::File& file, const std::string& group, const std::string& element,
                  hsize_t frames, std::vector<hsize_t> frame_dims, h5::Handle& out) {
  const std::string path = group + "/" + element + "/value";
  if (!h5::exists(file.id(), path)) return false;
  out = h5::open_dataset(file, path);
  frame_dims.insert(frame_dims.begin(), frames);
  if (h5::shape(out.get()) != frame_dims) {
    throw Error(file.name() + ": dataset " + path + " has shape " +
                h5::shape_text(h5::shape(out.get())) + ", expected " + h5::shape_text(frame_dims));
  }
  return true;
}

// Who made the file (/h5md's creator and author) and with what (/parameters, the voxel
// size of image data among them).
void read_provenance(const h5::File& file, RunHeader& h) {
  const hid_t f = file.id();
  if (h5::exists(f, "/h5md/creator")) {
    h5::Handle creator = h5::open_group(file, "/h5md/creator");
    h.creator_name = h5::read_string_attribute(creator.get(), "name").value_or("");
    h.creator_version = h5::read_string_attribute(creator.get(), "version").value_or("");
  }
  if (h5::exists(f, "/h5md/author")) {
    h5::Handle author = h5::open_group(file, "/h5md/author");
    h.author = h5::read_string_attribute(author.get(), "name").value_or("");
  }
  if (h5::exists(f, "/parameters")) {
    read_parameters(file, "/parameters", "", h.parameters);
    if (h5::exists(f, "/parameters/voxel_size")) {
      h.voxel_size = read_vector3(file, "/parameters/voxel_size");
    }
  }
}

// /observables/<name>/{value, step, time}, each of equal length.
std::map<std::string, Observable> read_observables(const h5::File& file) {
  std::map<std::string, Observable> observables;
  if (!h5::exists(file.id(), "/observables")) return observables;
  h5::Handle obs = h5::open_group(file, "/observables");
  for (const std::string& o : h5::member_names(obs.get())) {
    const std::string base = "/observables/" + o;
    Observable ob;
    ob.value = h5::read<double>(file, base + "/value");
    ob.step = h5::read<std::int64_t>(file, base + "/step");
    ob.time = h5::read<double>(file, base + "/time");
    h5::Handle value = h5::open_dataset(file, base + "/value");
    ob.unit = unit_of(value.get(), "1");
    if (ob.step.size() != ob.value.size() || ob.time.size() != ob.value.size()) {
      throw Error(file.name() + ": observable " + base +
                  " needs value, step and time of equal length");
    }
    observables[o] = std::move(ob);
  }
  return observables;
}

}  // namespace

struct TrajectoryReader::Impl {
  h5::File file;
  std::string group;
  RunHeader header;
  std::vector<std::int64_t> steps;
  std::vector<double> times;
  std::map<std::string, Observable> observables;
  h5::Handle position, axis, orientation, hole_contact, position_error, axis_error;
};

TrajectoryReader::TrajectoryReader(const std::filesystem::path& path)
    : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.file = h5::File::open(path);
  r.group = particles_group_of(r.file);
  const std::string pos = r.group + "/position";
  r.position = open_positions(r.file, pos);
  const std::vector<hsize_t> dims = h5::shape(r.position.get());
  const hsize_t t_count = dims[0], n = dims[1];
  RunHeader& h = r.header;
  FrameLabels labels = read_frame_labels(r.file, pos, t_count);
  r.steps = std::move(labels.steps);
  r.times = std::move(labels.times);
  h.time_unit = labels.time_unit;
  const std::string stated_unit = read_position_header(r.file, pos, r.position, h);
  read_grains(r.file, r.group, n, h);
  h.box = read_box(r.file, r.group);
  h.has_axis = open_element(r.file, r.group, "axis", t_count, {n, 3}, r.axis);
  h.has_orientation = open_element(r.file, r.group, "orientation", t_count, {n, 4}, r.orientation);
  h.has_hole_contact = open_element(r.file, r.group, "hole_contact", t_count, {n}, r.hole_contact);
  h.has_position_error =
      open_element(r.file, r.group, "position_error", t_count, {n, 3}, r.position_error);
  h.has_axis_error = open_element(r.file, r.group, "axis_error", t_count, {n}, r.axis_error);
  read_provenance(r.file, h);
  if (stated_unit.empty())
    h.parameters["h5md/length_unit"] = "m, assumed: the file's positions have no unit";
  check_header(h, r.file.name());
  r.observables = read_observables(r.file);
}

TrajectoryReader::~TrajectoryReader() = default;
TrajectoryReader::TrajectoryReader(TrajectoryReader&&) noexcept = default;

const RunHeader& TrajectoryReader::header() const {
  return impl_->header;
}
std::size_t TrajectoryReader::frame_count() const {
  return impl_->steps.size();
}
const std::vector<std::int64_t>& TrajectoryReader::steps() const {
  return impl_->steps;
}
const std::vector<double>& TrajectoryReader::times() const {
  return impl_->times;
}
const std::map<std::string, Observable>& TrajectoryReader::observables() const {
  return impl_->observables;
}
const std::string& TrajectoryReader::file_name() const {
  return impl_->file.name();
}
const h5::File& TrajectoryReader::file() const {
  return impl_->file;
}
const std::string& TrajectoryReader::particles_group() const {
  return impl_->group;
}

Frame TrajectoryReader::read_frame(std::size_t t) const {
  const Impl& r = *impl_;
  if (t >= r.steps.size()) {
    throw Error(r.file.name() + ": no frame " + std::to_string(t) + " (file has " +
                std::to_string(r.steps.size()) + ")");
  }
  Frame frame = Frame::unknown(r.header);
  frame.step = r.steps[t];
  frame.time = r.times[t];
  const std::string& g = r.group;
  h5::read_frame(r.file, r.position.get(), g + "/position/value", t, frame.position.data());
  if (r.header.has_axis) {
    h5::read_frame(r.file, r.axis.get(), g + "/axis/value", t, frame.axis.data());
  }
  if (r.header.has_orientation) {
    h5::read_frame(r.file, r.orientation.get(), g + "/orientation/value", t,
                   frame.orientation.data());
  }
  if (r.header.has_hole_contact) {
    h5::read_frame(r.file, r.hole_contact.get(), g + "/hole_contact/value", t,
                   frame.hole_contact.data());
  }
  if (r.header.has_position_error) {
    h5::read_frame(r.file, r.position_error.get(), g + "/position_error/value", t,
                   frame.position_error.data());
  }
  if (r.header.has_axis_error) {
    h5::read_frame(r.file, r.axis_error.get(), g + "/axis_error/value", t, frame.axis_error.data());
  }
  return frame;
}

void write_trajectories(const std::filesystem::path& path, const Trajectories& run) {
  TrajectoryWriter writer(path, run.header);
  for (const Frame& frame : run.frames)
    writer.append(frame);
  for (const auto& [name, obs] : run.observables)
    writer.set_observable(name, obs);
  writer.commit();
}

Trajectories read_trajectories(const std::filesystem::path& path) {
  TrajectoryReader reader(path);
  Trajectories run;
  run.header = reader.header();
  run.observables = reader.observables();
  for (std::size_t t = 0; t < reader.frame_count(); ++t)
    run.frames.push_back(reader.read_frame(t));
  return run;
}

}  // namespace granmem
