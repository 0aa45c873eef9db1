#include "granmem/sim/placed_packing.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/point_index.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

// `frame`, each grain it misses taken (position, orientation, axis) from the first later
// frame that has it (NaN if none), unless a grain already placed lies within `reach` of it
// there: two grains' centres are a diameter apart, so it is that grain, whose track the
// linker broke across the scans between (on tracked scans of cycles 0 and 20-30, 3 of
// 2,500 tracks, 0.43-0.70 d from a placed grain), or a grain that cannot be placed there.
Frame filled_forward(const TrajectoryReader& run, std::size_t frame, double reach) {
  Frame f = run.read_frame(frame);
  std::vector<bool> taken(std::size_t(f.position.rows()), false);
  auto missing = [&] {  // a grain no later frame has decided yet
    for (Eigen::Index i = 0; i < f.position.rows(); ++i)
      if (!f.position.row(i).allFinite() && !taken[std::size_t(i)]) return true;
    return false;
  };
  for (std::size_t t = frame + 1; t < run.frame_count() && missing(); ++t) {
    const Frame later = run.read_frame(t);
    const PointIndex placed(finite_rows(f.position));
    PointIndex::Hits near;
    for (Eigen::Index i = 0; i < f.position.rows(); ++i) {
      if (f.position.row(i).allFinite() || taken[std::size_t(i)]) continue;
      if (!later.position.row(i).allFinite()) continue;
      taken[std::size_t(i)] = true;  // its first later frame decides
      placed.within(later.position.row(i).transpose(), reach, near);
      if (!near.empty()) continue;
      f.position.row(i) = later.position.row(i);
      if (f.orientation.rows() > i) f.orientation.row(i) = later.orientation.row(i);
      if (f.axis.rows() > i) f.axis.row(i) = later.axis.row(i);
    }
  }
  return f;
}

// Each grain inside the side walls and above the floor.
void keep_in_box(Grains& grains, const DepositOptions& deposit) {
  for (std::size_t i = 0; i < grains.size(); ++i) {
    Eigen::Vector3d& x = grains.x[i];
    const double r = grains.radius[i];
    for (int d = 0; d < 2; ++d)
      x(d) = std::clamp(x(d), r, deposit.box_side - r);
    x.z() = std::max(x.z(), r);
  }
}

Eigen::Quaterniond orientation_of(const Frame& f, Eigen::Index i) {
  if (f.orientation.rows() > i && f.orientation.row(i).allFinite()) {
    const auto q = f.orientation.row(i);
    return Eigen::Quaterniond(q(0), q(1), q(2), q(3)).normalized();
  }
  if (f.axis.rows() > i && f.axis.row(i).allFinite()) {
    return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), f.axis.row(i).transpose());
  }
  return Eigen::Quaterniond::Identity();
}

}  // namespace

Grains grains_of_frame(const TrajectoryReader& run, std::size_t frame,
                       const DepositOptions& deposit, const PhysicsOptions& physics) {
  if (frame >= run.frame_count()) {
    throw Error(run.file_name() + ": has no frame " + std::to_string(frame) +
                " to place grains from");
  }
  const RunHeader& h = run.header();
  if (h.length_unit == "voxel") {
    throw Error(run.file_name() + ": positions in voxels; grains are placed in a length unit " +
                "(track with --voxel-size)");
  }
  const double metres = metres_per(h.length_unit);
  const Eigen::Vector3d corner = h.box ? h.box->lower : Eigen::Vector3d::Zero();
  const Frame f = filled_forward(run, frame, 1.5 * deposit.radius / metres);  // 0.75 d
  const Vectors3& x = f.position;
  Grains grains;
  for (Eigen::Index i = 0; i < x.rows(); ++i) {
    if (!x.row(i).allFinite()) continue;
    const double located = h.radius[std::size_t(i)] * metres;
    const double r =
        deposit.polydispersity == 0 || !std::isfinite(located) ? deposit.radius : located;
    grains.add(h.id[std::size_t(i)], (x.row(i).transpose() - corner) * metres, r, physics.density);
    grains.q.back() = orientation_of(f, i);
  }
  if (grains.size() == 0) throw Error(run.file_name() + ": no grain located to place");
  return grains;
}

Grains jittered(Grains grains, double jitter, std::uint64_t seed, const DepositOptions& deposit) {
  return jittered(std::move(grains), Eigen::Vector3d::Constant(jitter), seed, deposit);
}

Grains jittered(Grains grains, const Eigen::Vector3d& jitter, std::uint64_t seed,
                const DepositOptions& deposit) {
  Random random(seed);
  for (Eigen::Vector3d& x : grains.x)
    x += jitter.cwiseProduct(normal_vector(random));
  keep_in_box(grains, deposit);
  return grains;
}

}  // namespace granmem
