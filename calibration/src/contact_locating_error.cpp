#include "granmem/calibration/contact_locating_error.hpp"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/point_index.hpp"
#include "granmem/core/statistics.hpp"

namespace granmem {
namespace {

// The distances of neighbouring centres near contact, as gaps in diameters (r / d - 1),
// each with its direction's |u_z|.
struct NeighbourGaps {
  std::vector<double> gap, cos_z;
};

void add_neighbour_gaps(const Vectors3& position, double diameter, double reach,
                        NeighbourGaps& out) {
  const Vectors3 finite = finite_rows(position);
  const Eigen::Index n = finite.rows();
  const PointIndex index(finite);
  PointIndex::Hits hits;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d x = finite.row(i).transpose();
    index.within(x, (1 + reach) * diameter, hits);
    for (const auto& [j, squared] : hits) {
      if (Eigen::Index(j) <= i) continue;
      const double r = std::sqrt(squared);
      out.gap.push_back(r / diameter - 1);
      out.cos_z.push_back(std::abs(finite(j, 2) - x.z()) / r);
    }
  }
}

// The scanned gaps counted by |u_z| and gap; the reference's gaps finely, over a range
// wide enough for the error to carry them into the scanned range.
struct BinnedGaps {
  std::vector<double> edges;                           // of the scanned range's bins
  std::vector<std::vector<double>> counts;             // [direction][bin]
  std::vector<double> mean_cos2;                       // of each direction's scanned pairs
  std::vector<double> reference_gap, reference_count;  // fine bins' centres, counts
  std::size_t pairs = 0;
};

// The gaps fitted, in diameters: [-below, above] in `bins` bins.
struct GapRange {
  double below, above;
  int bins, directions;
  double bin() const { return (below + above) / bins; }
};

BinnedGaps binned_gaps(const NeighbourGaps& scanned, const NeighbourGaps& reference,
                       const GapRange& o) {
  BinnedGaps b;
  const int bins = o.bins;
  for (int j = 0; j <= bins; ++j)
    b.edges.push_back(-o.below + j * o.bin());
  b.counts.assign(o.directions, std::vector<double>(bins, 0));
  std::vector<double> cos2(o.directions, 0), in_direction(o.directions, 0);
  for (std::size_t p = 0; p < scanned.gap.size(); ++p) {
    const int j = int(std::floor((scanned.gap[p] + o.below) / o.bin()));
    if (j < 0 || j >= bins) continue;
    const int k = std::min(o.directions - 1, int(scanned.cos_z[p] * o.directions));
    b.counts[k][j] += 1;
    cos2[k] += scanned.cos_z[p] * scanned.cos_z[p];
    in_direction[k] += 1;
    ++b.pairs;
  }
  for (int k = 0; k < o.directions; ++k)
    b.mean_cos2.push_back(in_direction[k] > 0 ? cos2[k] / in_direction[k] : 0);
  const double fine = o.bin() / 5, low = -2 * o.below, high = o.above + o.below;
  const int fine_bins = int(std::lround((high - low) / fine));
  std::vector<double> count(fine_bins, 0);
  for (double g : reference.gap) {
    const int m = int(std::floor((g - low) / fine));
    if (m >= 0 && m < fine_bins) count[m] += 1;
  }
  for (int m = 0; m < fine_bins; ++m) {
    if (count[m] == 0) continue;
    b.reference_gap.push_back(low + (m + 0.5) * fine);
    b.reference_count.push_back(count[m]);
  }
  return b;
}

// Minus the log likelihood of the scanned gaps: in each direction's bins, the reference's
// gaps moved by the offset and spread by the two centres' errors along the direction,
// conditioned on the scanned range. Parameters: offset, ln across, ln along_z (diameters).
struct ContactSpreadLikelihood {
  const BinnedGaps& b;
  // erf(b) - erf(a), a < b, from each edge's tail, erfc(|x|): where both edges lie on one
  // side the plain difference cancels to nothing, and a distance far from the reference's
  // would weigh nothing, without a gradient.
  template <typename T>
  static T erf_difference(const T& a, const T& tail_a, const T& b, const T& tail_b) {
    if (a > T(0)) return tail_a - tail_b;
    if (b < T(0)) return tail_b - tail_a;
    return T(2) - tail_a - tail_b;
  }

  template <typename T>
  bool operator()(const T* p, T* cost) const {
    using std::abs, std::erfc, std::exp, std::log, std::sqrt;
    const T across2 = exp(T(2) * p[1]), along2 = exp(T(2) * p[2]);
    cost[0] = T(0);
    for (std::size_t k = 0; k < b.counts.size(); ++k) {
      const double c2 = b.mean_cos2[k];
      const T inv = T(1) / sqrt(T(4) * (across2 * (1 - c2) + along2 * c2));  // 1/(s sqrt 2)
      std::vector<T> prob(b.counts[k].size(), T(0));
      for (std::size_t m = 0; m < b.reference_gap.size(); ++m) {
        const T centre = b.reference_gap[m] + p[0];
        T below = (b.edges[0] - centre) * inv, below_tail = erfc(abs(below));
        for (std::size_t j = 0; j < prob.size(); ++j) {
          const T above = (b.edges[j + 1] - centre) * inv, above_tail = erfc(abs(above));
          prob[j] += b.reference_count[m] * erf_difference(below, below_tail, above, above_tail);
          below = above;
          below_tail = above_tail;
        }
      }
      T total = T(0);
      for (const T& q : prob)
        total += q;
      for (std::size_t j = 0; j < prob.size(); ++j)
        if (b.counts[k][j] > 0) cost[0] -= b.counts[k][j] * log(prob[j] / total + 1e-300);
    }
    return true;
  }
};

// The fit of the scanned gaps in `range` against the reference's.
ContactLocatingError fitted_contact_error(const NeighbourGaps& scan, const NeighbourGaps& ref,
                                          double diameter, const GapRange& range) {
  ContactLocatingError e;
  const BinnedGaps binned = binned_gaps(scan, ref, range);
  e.pairs = binned.pairs;
  if (binned.pairs < 100 || binned.reference_gap.empty()) return e;
  // Started narrow and wide (a start far narrower than the spread sees no gradient where
  // the distances lie), the likelier kept.
  ceres::GradientProblem problem(new ceres::AutoDiffFirstOrderFunction<ContactSpreadLikelihood, 3>(
      new ContactSpreadLikelihood{binned}));
  ceres::GradientProblemSolver::Options solver;
  solver.logging_type = ceres::SILENT;
  double p[3] = {0, 0, 0}, best = INFINITY;
  for (double start : {0.1, 0.3}) {
    const double spread = start * range.below;
    double q[3] = {0, std::log(spread), std::log(spread)};
    ceres::GradientProblemSolver::Summary summary;
    ceres::Solve(solver, problem, q, &summary);
    if (summary.final_cost < best) {
      best = summary.final_cost;
      std::copy(q, q + 3, p);
    }
  }
  // A spread the range cannot hold is not read from it.
  const double widest = range.below / 2;
  if (!std::isfinite(best) || std::exp(std::max(p[1], p[2])) > widest) return e;
  e.offset = p[0] * diameter;
  e.across = std::exp(p[1]) * diameter;
  e.along_z = std::exp(p[2]) * diameter;
  return e;
}

// A first fit over a range wide enough for a coarse scan's errors (a quarter of a
// diameter below contact) finds the spread; the second fits the range it needs, six and
// three times a contact's spread below and above, at least the options' range, in finer
// bins.
constexpr GapRange kScout{0.25, 0.05, 60, 5};

ContactLocatingError contact_error(const NeighbourGaps& scan, const NeighbourGaps& ref,
                                   double diameter, const ContactErrorOptions& o) {
  const ContactLocatingError scout = fitted_contact_error(scan, ref, diameter, kScout);
  if (!std::isfinite(scout.across)) return scout;
  const double spread = std::sqrt(2.0) * std::max(scout.across, scout.along_z) / diameter;
  const GapRange range{std::min(std::max(6 * spread, o.below), kScout.below),
                       std::min(std::max(3 * spread, o.above), kScout.above), o.bins, o.directions};
  return fitted_contact_error(scan, ref, diameter, range);
}

// Every frame's neighbour gaps, the positions in m.
NeighbourGaps gaps_of_every_frame(const TrajectoryReader& run, double diameter, double reach) {
  const double metres = metres_per_length(run);
  NeighbourGaps gaps;
  for (std::size_t t = 0; t < run.frame_count(); ++t)
    add_neighbour_gaps(run.read_frame(t).position * metres, diameter, reach, gaps);
  return gaps;
}

// The change of each persistent contact's length over one cycle, by its direction.
struct ContactChanges {
  std::vector<double> horizontal, vertical;
};

void add_contact_changes(const Vectors3& before, const Vectors3& after, double diameter,
                         ContactChanges& out) {
  std::vector<Eigen::Index> seen;  // grains located in both frames
  for (Eigen::Index i = 0; i < before.rows(); ++i) {
    if (before.row(i).allFinite() && after.row(i).allFinite()) seen.push_back(i);
  }
  Vectors3 start(Eigen::Index(seen.size()), 3);
  for (std::size_t k = 0; k < seen.size(); ++k)
    start.row(Eigen::Index(k)) = before.row(seen[k]);
  const PointIndex index(start);
  PointIndex::Hits hits;
  const double touching = 1.01 * diameter;
  for (std::size_t k = 0; k < seen.size(); ++k) {
    index.within(start.row(Eigen::Index(k)).transpose(), touching, hits);
    for (const auto& [j, squared] : hits) {
      if (j <= k) continue;
      const double r0 = std::sqrt(squared);
      const double r1 = (after.row(seen[j]) - after.row(seen[k])).norm();
      if (r1 >= touching) continue;
      const double cos_z = std::abs(start(Eigen::Index(j), 2) - start(Eigen::Index(k), 2)) / r0;
      if (cos_z < 0.3) out.horizontal.push_back(r1 - r0);
      if (cos_z > 0.8) out.vertical.push_back(r1 - r0);
    }
  }
}

// Every cycle of `window`'s contact changes, the positions in m.
ContactChanges contact_changes(const TrajectoryReader& run, double diameter,
                               std::pair<std::int64_t, std::int64_t> window) {
  const double metres = metres_per_length(run);
  const std::vector<std::int64_t>& steps = run.steps();
  ContactChanges changes;
  for (std::size_t t = 1; t < steps.size(); ++t) {
    if (steps[t] != steps[t - 1] + 1 || steps[t] < window.first || steps[t] > window.second)
      continue;
    add_contact_changes(run.read_frame(t - 1).position * metres,
                        run.read_frame(t).position * metres, diameter, changes);
  }
  return changes;
}

// 1.4826 x the median absolute deviation: a normal core's standard deviation.
double robust_spread(const std::vector<double>& x) {
  const double centre = median(x);
  std::vector<double> deviation;
  for (double v : x)
    deviation.push_back(std::abs(v - centre));
  return 1.4826 * median(deviation);
}

// Half the scans' spread less the reference's, in quadrature; NaN from under 100 contacts.
double per_frame_error(const std::vector<double>& scanned, const std::vector<double>& reference) {
  if (scanned.size() < 100 || reference.size() < 100) return ContactLocatingError::kNaN;
  const double s = robust_spread(scanned), r = robust_spread(reference);
  return 0.5 * std::sqrt(std::max(0.0, s * s - r * r));
}

}  // namespace

DisplacementError displacement_error_from_contacts(const TrajectoryReader& scans,
                                                   const TrajectoryReader& reference,
                                                   double diameter,
                                                   std::pair<std::int64_t, std::int64_t> window) {
  const ContactChanges scanned = contact_changes(scans, diameter, window);
  const ContactChanges exact = contact_changes(reference, diameter, window);
  DisplacementError e;
  e.across = per_frame_error(scanned.horizontal, exact.horizontal);
  e.along_z = per_frame_error(scanned.vertical, exact.vertical);
  e.contacts = scanned.horizontal.size() + scanned.vertical.size();
  return e;
}

void ContactErrorOptions::validate(double diameter) const {
  if (!(diameter > 0) || !std::isfinite(diameter))
    throw Error("the contacts' error: a grain diameter above 0, not " + std::to_string(diameter));
  if (!(below > 0 && below <= kScout.below && above > 0 && above <= kScout.above))
    throw Error("the contacts' error: a range within 0.75-1.05 diameters");
  if (bins < 10 || directions < 1) throw Error("the contacts' error: 10 bins or more, a direction");
}

ContactLocatingError locating_error_from_contacts(const Vectors3& scanned,
                                                  const Vectors3& reference, double diameter,
                                                  const ContactErrorOptions& options) {
  options.validate(diameter);
  const double reach = kScout.below + kScout.above;
  NeighbourGaps scan, ref;
  add_neighbour_gaps(scanned, diameter, reach, scan);
  add_neighbour_gaps(reference, diameter, reach, ref);
  return contact_error(scan, ref, diameter, options);
}

ContactLocatingError locating_error_from_contacts(const TrajectoryReader& scans,
                                                  const TrajectoryReader& reference,
                                                  double diameter,
                                                  const ContactErrorOptions& options) {
  options.validate(diameter);
  const double reach = kScout.below + kScout.above;
  return contact_error(gaps_of_every_frame(scans, diameter, reach),
                       gaps_of_every_frame(reference, diameter, reach), diameter, options);
}

}  // namespace granmem
