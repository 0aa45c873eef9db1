#include "granmem/tracking/render_run.hpp"

#include <cmath>
#include <iomanip>
#include <optional>
#include <sstream>

#include "granmem/core/atomic_file.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/option_values.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/core/units.hpp"
#include "granmem/tracking/stack.hpp"

namespace granmem {
namespace {

// The index of the frame labelled `label`.
std::size_t frame_index(const TrajectoryReader& run, std::int64_t label,
                        const std::filesystem::path& path) {
  for (std::size_t t = 0; t < run.frame_count(); ++t) {
    if (run.steps()[t] == label) return t;
  }
  std::string have = "it has no frames";
  if (run.frame_count() > 0) {
    have = "its frames are " + std::to_string(run.steps().front()) + " to " +
           std::to_string(run.steps().back());
  }
  throw Error("--frame " + std::to_string(label) + ": " + path.string() + " has no such frame; " +
              have);
}

// "X[,Y,Z]<unit>" in the run's length unit.
Eigen::Vector3d voxel_size_in(const std::string& text, const std::string& run_unit) {
  const VoxelSize v = parse_voxel_size(text, "--voxel-size");
  if (v.unit.empty() || v.unit == run_unit) return v.size;
  if (!is_physical_length_unit(v.unit) || !is_physical_length_unit(run_unit)) {
    throw Error("--voxel-size '" + text + "': cannot convert " + v.unit + " to the run's unit " +
                run_unit);
  }
  return v.size * convert_length(1, v.unit, run_unit);
}

std::vector<std::string> truth_comment(const RenderRunOptions& o, const Stack& stack) {
  std::ostringstream voxel;
  voxel << std::setprecision(17) << stack.voxel_size->x() << " x " << stack.voxel_size->y() << " x "
        << stack.voxel_size->z() << " " << stack.unit;
  std::vector<std::string> comment = {
      "granmem render " + o.run.string() + " --frame " + std::to_string(o.frame),
      "positions and radius in voxels of " + voxel.str() + "; voxel (0,0,0) is the origin"};
  for (const auto& [key, value] : o.parameters)
    comment.push_back(key + " = " + value);
  return comment;
}

}  // namespace

std::string RenderSummary::Report() const {
  std::ostringstream s;
  s << "rendered " << grains << " grains of frame " << frame << " of " << run.string() << ": " << nx
    << " x " << ny << " x " << nz << " voxels of " << voxel_size.x() << " x " << voxel_size.y()
    << " x " << voxel_size.z() << " " << length_unit << ", " << bits << "-bit"
    << (artefacts ? "" : ", no artefacts") << "\nwrote " << out.string() << "\n";
  if (!truth.empty()) s << "wrote " << truth.string() << "\n";
  return s.str();
}

void RenderRunOptions::validate() const {
  if (run.empty()) throw Error("render: no run to draw (a trajectory store)");
  if (out.empty()) throw Error("render: no --out (the TIFF stack to write)");
  if (!voxel_size.empty()) parse_voxel_size(voxel_size, "--voxel-size");
  render.validate();
}

namespace {

// A run with a container: its scans share one frame, as a lab's scanner stays where it is
// while the grains move. The stack's first voxel `margin` voxels below the container's lower
// corner (a grain further out is cut by the stack's border, as by a scanner's field of
// view), its far side where the grains' own stack ends; without, each frame's stack is
// centred on its grains and the frames' origins differ by up to half a voxel and by the
// packing's changes of height.
void fix_to_the_container(const std::vector<RenderedGrain>& grains, const RunHeader& h,
                          RenderOptions& o) {
  if (!h.box || o.origin || o.size) return;
  const ScanGeometry own = scan_geometry(grains, o);
  const Eigen::Vector3d& vs = own.voxel_size;
  const Eigen::Vector3d origin = h.box->lower - o.margin * vs;
  const Eigen::Vector3d last =
      own.origin +
      Eigen::Vector3d(double(own.nx - 1), double(own.ny - 1), double(own.nz - 1)).cwiseProduct(vs);
  // Voxels from the origin to the last (1e-9: a whole number of voxels not one more).
  const Eigen::Vector3d count =
      ((last - origin).cwiseQuotient(vs).array() + 1 - 1e-9).ceil().max(1.0).matrix();
  o.voxel_size = vs;
  o.origin = origin;
  o.size = {std::int64_t(count.x()), std::int64_t(count.y()), std::int64_t(count.z())};
}

}  // namespace

RenderSummary render_run(const RenderRunOptions& options) {
  options.validate();
  const TrajectoryReader run(options.run);
  const RunHeader& h = run.header();
  const std::size_t index = frame_index(run, options.frame, options.run);
  RenderOptions o = options.render;
  if (!options.voxel_size.empty()) o.voxel_size = voxel_size_in(options.voxel_size, h.length_unit);
  o.length_unit = h.length_unit;
  o.frame = options.frame;
  const std::vector<RenderedGrain> grains = rendered_grains(run.read_frame(index), h, o.seed);
  if (grains.empty()) {
    throw Error("--frame " + std::to_string(options.frame) + ": " + options.run.string() +
                " has no grain with a position in that frame; nothing to draw");
  }
  // Every frame of a run at one voxel size: from the run's grains, not this frame's.
  std::vector<double> radii;
  for (double r : h.radius)
    if (std::isfinite(r) && r > 0) radii.push_back(r);
  if (!o.voxel_size && !radii.empty()) o.voxel_size = voxel_size_for(median(radii), o);
  fix_to_the_container(grains, h, o);
  // Both places are checked before the drawing, which takes a while.
  AtomicFile{options.out};
  std::optional<AtomicFile> truth_file;
  if (!options.truth.empty()) truth_file.emplace(options.truth);
  Table truth;
  Stack stack = render_scan(grains, o, &truth);
  stack.source = options.run.string() + " frame " + std::to_string(options.frame);
  if (truth_file) write_csv(truth, *truth_file, truth_comment(options, stack));
  write_tiff(stack, options.out);
  if (truth_file) truth_file->commit();

  RenderSummary s;
  s.run = options.run;
  s.out = options.out;
  s.truth = options.truth;
  s.frame = options.frame;
  s.grains = grains.size();
  s.nx = stack.nx;
  s.ny = stack.ny;
  s.nz = stack.nz;
  s.voxel_size = *stack.voxel_size;
  s.length_unit = h.length_unit;
  s.bits = stack.bits;
  s.artefacts = o.read_noise > 0 || o.gain > 0 || o.flicker > 0 || o.streaks_per_slice > 0 ||
                o.attenuation > 0 || o.blur_sigma.norm() > 0 || o.wall.has_value();
  return s;
}

}  // namespace granmem
