#include "granmem/sim/placed_packing.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/point_index.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/units.hpp"

namespace granmem {
namespace {

// A grain a frame misses, as the first later frame that has it holds it (position,
// orientation, axis), and its clearance: how far that lies from the nearest grain the frame
// holds.
struct LaterGrain {
  Eigen::Index row;
  Eigen::RowVector3d position, axis;  // axis: NaN where the run has none
  Eigen::RowVector4d orientation;     // NaN where the run has none
  double clearance;
};

LaterGrain later_grain(const Frame& next, Eigen::Index i, double clearance) {
  LaterGrain g{i, next.position.row(i), Eigen::RowVector3d::Constant(NAN),
               Eigen::RowVector4d::Constant(NAN), clearance};
  if (next.axis.rows() > i) g.axis = next.axis.row(i);
  if (next.orientation.rows() > i) g.orientation = next.orientation.row(i);
  return g;
}

std::vector<LaterGrain> missed_grains_later(const TrajectoryReader& run, std::size_t frame,
                                            const Frame& f) {
  const PointIndex located(finite_rows(f.position));
  std::vector<bool> decided(std::size_t(f.position.rows()));
  for (Eigen::Index i = 0; i < f.position.rows(); ++i)
    decided[std::size_t(i)] = f.position.row(i).allFinite();
  std::vector<LaterGrain> later;
  PointIndex::Hits nearest;
  for (std::size_t t = frame + 1; t < run.frame_count(); ++t) {
    const Frame next = run.read_frame(t);
    for (Eigen::Index i = 0; i < f.position.rows(); ++i) {
      if (decided[std::size_t(i)] || !next.position.row(i).allFinite()) continue;
      decided[std::size_t(i)] = true;  // its first later frame decides
      located.nearest(next.position.row(i).transpose(), 1, nearest);
      later.push_back(
          later_grain(next, i, nearest.empty() ? INFINITY : std::sqrt(nearest[0].second)));
    }
    if (std::all_of(decided.begin(), decided.end(), [](bool d) { return d; })) break;
  }
  return later;
}

// `frame`, with grains it misses taken (position, orientation, axis) from the first later
// frame that has them, none within `reach` of a grain already placed there: two grains'
// centres are a diameter apart, so it is that grain, whose track the linker broke across the
// scans between. Where the packing's grain count is known, no more than the frame lacks, the
// farthest from the frame's grains first: a grain the scan missed leaves a hole a diameter
// wide, while a broken track lies where its grain moved to, often further than `reach`
// (docs/CALIBRATION.md, "A broken track placed twice").
Frame filled_forward(const TrajectoryReader& run, std::size_t frame, double reach,
                     std::optional<std::size_t> grains) {
  Frame f = run.read_frame(frame);
  std::vector<LaterGrain> later = missed_grains_later(run, frame, f);
  std::sort(later.begin(), later.end(),
            [](const LaterGrain& a, const LaterGrain& b) { return a.clearance > b.clearance; });
  const auto located = std::size_t(f.position.array().isFinite().rowwise().all().count());
  std::size_t room = grains ? *grains - std::min(*grains, located) : later.size();
  std::vector<Eigen::Vector3d> taken;
  for (const LaterGrain& g : later) {
    if (room == 0 || g.clearance < reach) break;  // the rest lie nearer
    const Eigen::Vector3d x = g.position.transpose();
    if (std::any_of(taken.begin(), taken.end(),
                    [&](const Eigen::Vector3d& y) { return (x - y).norm() < reach; }))
      continue;
    taken.push_back(x);
    --room;
    f.position.row(g.row) = g.position;
    if (f.orientation.rows() > g.row) f.orientation.row(g.row) = g.orientation;
    if (f.axis.rows() > g.row) f.axis.row(g.row) = g.axis;
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
  const std::optional<std::size_t> count =
      deposit.grains > 0 ? std::optional<std::size_t>(std::size_t(deposit.grains)) : std::nullopt;
  const Frame f = filled_forward(run, frame, 1.5 * deposit.radius / metres, count);  // 0.75 d
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
