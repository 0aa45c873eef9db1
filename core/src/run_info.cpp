#include "granmem/core/run_info.hpp"

#include <cmath>
#include <sstream>

#include "granmem/core/hdf5.hpp"
#include "granmem/core/trajectory_store.hpp"

namespace granmem {
namespace {

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

void list_datasets(std::ostream& out, const h5::File& file) {
  for (const h5::DatasetInfo& d : h5::list_datasets(file)) {
    out << "    " << d.path << " " << h5::shape_text(d.dims);
    if (!d.unit.empty() && d.unit != "1") out << " [" << d.unit << "]";
    out << "\n";
  }
}

}  // namespace

std::string run_info(const std::filesystem::path& store) {
  std::ostringstream out;
  const TrajectoryReader run(store.string());
  const RunHeader& h = run.header();
  const auto& steps = run.steps();
  out << store.string() << ": trajectory store (H5MD), group " << run.particles_group() << "\n";
  out << "  producer    " << h.creator_name << " " << h.creator_version;
  if (!h.author.empty()) out << ", author " << h.author;
  out << "\n  frames      " << run.frame_count();
  if (!steps.empty()) out << " (steps " << steps.front() << " to " << steps.back() << ")";
  out << ", sample " << h.sample << ", time in " << h.time_unit << "\n";
  std::size_t known = 0;
  double sum = 0;
  for (double r : h.radius) {
    if (std::isfinite(r)) {
      ++known;
      sum += r;
    }
  }
  out << "  grains      " << h.grain_count();
  if (known) out << ", mean radius " << sum / double(known) << " " << h.length_unit;
  if (known < h.grain_count()) out << ", radius unknown for " << h.grain_count() - known;
  out << "\n  lengths     " << h.length_unit;
  if (h.voxel_size) out << ", voxel size " << vec(*h.voxel_size) << " " << h.length_unit;
  out << "\n  box         ";
  if (h.box) {
    out << "lower " << vec(h.box->lower) << ", edges " << vec(h.box->edges) << " " << h.length_unit;
  } else {
    out << "none";
  }
  out << "\n  per grain   position";
  if (h.has_axis) out << ", cavity axis";
  if (h.has_orientation) out << ", orientation";
  if (h.has_hole_contact) out << ", hole contact flag";
  if (h.has_position_error) out << ", position standard errors";
  if (h.has_axis_error) out << ", axis standard errors";
  out << "\n";
  if (!run.observables().empty()) {
    out << "  observables";
    for (const auto& [name, obs] : run.observables()) {
      out << " " << name << " [" << obs.unit << "] (" << obs.value.size() << ")";
    }
    out << "\n";
  }
  if (!h.parameters.empty()) {
    out << "  parameters\n";
    for (const auto& [key, value] : h.parameters) {
      out << "    " << key << " = " << value << "\n";
    }
  }
  out << "  datasets\n";
  list_datasets(out, run.file());
  return out.str();
}

}  // namespace granmem
