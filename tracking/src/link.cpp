#include "granmem/tracking/link.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <utility>

#include "granmem/core/error.hpp"
#include "granmem/core/point_index.hpp"
#include "granmem/core/statistics.hpp"
#include "granmem/tracking/assignment.hpp"

// Why this method holds in dense packings
// ---------------------------------------
// In a packing at packing fraction ~0.6 the nearest other grain is one diameter d away, so a
// grain that moves by u between two scans is matched correctly by "the nearest detection"
// only while |u| < d/2, and at |u| ~ d/2 many grains have two detections at about the same
// distance. Three things make the linking robust there:
//  1. Prediction. Most of a scan-to-scan motion is collective (the wall compresses, the
//     sample shifts, a shear band slides). The global drift is found as the mode of all
//     pair displacements (a histogram, then mean shift), which needs no matching and works
//     for drifts larger than d, and refined into a uniform deformation (compression,
//     shear) by least squares on the unambiguous links. Motions that are smooth but not
//     uniform (a shear band) are then followed locally: each grain's motion is predicted
//     from the densest spot of the displacements of its neighbours to every detection near
//     them (again no matching needed), then from the median displacement of its
//     confidently linked neighbours; the grain itself is always left out. What is left to
//     match is the grain's own random motion, so the candidates within reach are few.
//  2. A global one-to-one assignment. Among the candidate pairs found with a kd-tree, the
//     links minimise the summed squared residual, leaving a track unlinked costing
//     max_displacement^2 (the trackpy objective), solved exactly (sparse Hungarian /
//     Jonker-Volgenant, min_cost_assignment()). Greedy nearest-neighbour choices cascade
//     errors through chains of competing grains; the exact optimum resolves a whole
//     connected group at once, whatever its size, and costs little more than the greedy
//     choice because each augmenting search stops at the first free detection.
//  3. Model choice by the same objective. Each prediction (none, drift, local field) is
//     kept only if it lowers the objective, so a wrong drift estimate (few grains) or a
//     noisy local field (random, uncorrelated motion) cannot make the links worse.

namespace granmem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kRefits = 8;  // most refits of the drift, and of the deformation, per scan pair
constexpr std::size_t kParallel = 2000;  // fewer grains than this: one thread
// The default max displacement, in grain diameters: above the largest random (non-collective)
// motion the linker is made for (half a diameter) plus detection errors; a wrong partner
// within reach costs little, as the one-to-one assignment sets it aside.
constexpr double kDefaultReach = 0.7;

using Hits = PointIndex::Hits;

Vectors3 to_rows(const std::vector<Eigen::Vector3d>& points) {
  Vectors3 m(Eigen::Index(points.size()), 3);
  for (std::size_t i = 0; i < points.size(); ++i)
    m.row(Eigen::Index(i)) = points[i].transpose();
  return m;
}

Eigen::Vector3d median_point(const Vectors3& p) {
  Eigen::Vector3d m;
  for (int k = 0; k < 3; ++k) {
    m[k] = median(std::vector<double>(p.col(k).data(), p.col(k).data() + p.rows()));
  }
  return m;
}

// The global drift from `from` to the scan indexed by `to`: the mode of the displacements
// of all pairs (sampled sources, every target within reach). The true partners pile up in
// one peak, as narrow as the non-affine motion; wrong partners spread over a shell about one
// grain spacing wide around it, so the peak wins without any matching. The mode is looked
// for within reach of no drift and of the shift of the median positions (large drifts with
// all grains in view), on a histogram of `scale`/5 bins smoothed over 3x3x3 bins, then
// refined by mean shift.
Eigen::Vector3d estimate_drift(const std::vector<Eigen::Vector3d>& from, const PointIndex& to,
                               double scale, double max_displacement) {
  if (from.empty() || to.size() == 0) return Eigen::Vector3d::Zero();
  const std::size_t stride = std::max<std::size_t>(1, (from.size() + 3999) / 4000);
  const double reach = std::max(2 * scale, 2 * max_displacement);
  const int bins = std::clamp(int(std::ceil(2 * reach / (scale / 5))), 8, 48);
  const double width = 2 * reach / bins;
  Hits hits;

  const Eigen::Vector3d shift = median_point(to.points()) - median_point(to_rows(from));
  double best_score = -1;
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& centre : {Eigen::Vector3d(Eigen::Vector3d::Zero()), shift}) {
    if (!centre.allFinite()) continue;
    std::vector<double> count(std::size_t(bins * bins * bins), 0.0);
    auto at = [&](int i, int j, int k) -> double& {
      return count[std::size_t((i * bins + j) * bins + k)];
    };
    for (std::size_t s = 0; s < from.size(); s += stride) {
      to.within(from[s] + centre, reach, hits);
      for (const auto& [j, d2] : hits) {
        const Eigen::Vector3d v = to.points().row(Eigen::Index(j)).transpose() - from[s] - centre;
        int b[3];
        for (int k = 0; k < 3; ++k)
          b[k] = std::clamp(int(std::floor((v[k] + reach) / width)), 0, bins - 1);
        at(b[0], b[1], b[2]) += 1;
      }
    }
    for (int i = 1; i + 1 < bins; ++i) {
      for (int j = 1; j + 1 < bins; ++j) {
        for (int k = 1; k + 1 < bins; ++k) {
          double sum = 0;
          for (int a = -1; a <= 1; ++a)
            for (int b = -1; b <= 1; ++b)
              for (int c = -1; c <= 1; ++c)
                sum += at(i + a, j + b, k + c);
          const Eigen::Vector3d at_bin = centre +
                                         Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) * width -
                                         Eigen::Vector3d::Constant(reach);
          // Among equal peaks, the smallest drift.
          if (sum > best_score || (sum == best_score && at_bin.norm() < best.norm())) {
            best_score = sum;
            best = at_bin;
          }
        }
      }
    }
  }
  if (best_score <= 0) return Eigen::Vector3d::Zero();
  // Mean shift with a flat kernel narrower than the distance to wrong partners.
  const double kernel = 0.4 * scale;
  for (int iteration = 0; iteration < 30; ++iteration) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t n = 0;
    for (std::size_t s = 0; s < from.size(); s += stride) {
      to.within(from[s] + best, kernel, hits);
      for (const auto& [j, d2] : hits) {
        sum += to.points().row(Eigen::Index(j)).transpose() - from[s];
        ++n;
      }
    }
    if (n == 0) break;
    const Eigen::Vector3d next = sum / double(n);
    const double moved = (next - best).norm();
    best = next;
    if (moved < 1e-9 * scale) break;
  }
  return best;
}

// A predicted motion, the same for every grain: u(x) = drift + gradient (x - centre).
struct Motion {
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();
  Eigen::Matrix3d gradient = Eigen::Matrix3d::Zero();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d at(const Eigen::Vector3d& x) const { return drift + gradient * (x - centre); }
};

// The candidates and links of one linking pass, and the objective they reach: the summed
// squared residuals of the links plus max_displacement^2 per source left unlinked.
struct Pass {
  std::vector<Eigen::Vector3d> expected;  // per source: where it is looked for
  std::vector<Hits> candidates;           // per source: targets within reach, nearest first
  std::vector<std::int64_t> target;       // per source: linked detection or -1
  double objective = std::numeric_limits<double>::infinity();
  std::size_t links = 0;
  double residual2 = 0;  // summed squared residuals of the links
  Motion motion;
  bool local_field = false;
};

// A displacement seen with confidence: a link of a grain of the scan before whose detection
// is its nearest candidate and which is its detection's nearest grain.
struct Confident {
  std::size_t source;
  Eigen::Vector3d where, moved;
};

// Links the sources of one scan pair (at `base`: their last positions, the fresh ones, seen
// in the scan before, first) to the detections of the next scan.
class PairLinker {
 public:
  PairLinker(const std::vector<Eigen::Vector3d>& base, std::size_t fresh, const PointIndex& to,
             double reach)
      : base_(base), fresh_(fresh), to_(to), reach_(reach) {}

  // One pass: every source expected at base + motion (+ its own `offset`, when given).
  Pass run(const Motion& motion, const std::vector<Eigen::Vector3d>* offset = nullptr) const {
    Pass pass;
    pass.motion = motion;
    const std::size_t n = base_.size();
    pass.candidates.resize(n);
    pass.expected.resize(n);
#pragma omp parallel for schedule(dynamic, 256) if (n > kParallel)
    for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(n); ++i) {
      const auto s = std::size_t(i);
      pass.expected[s] = base_[s] + (offset ? (*offset)[s] : motion.at(base_[s]));
      to_.within(pass.expected[s], reach_, pass.candidates[s]);
    }
    SparseCosts graph;
    graph.rows = n;
    graph.cols = to_.size();
    graph.offsets.reserve(n + 1);
    for (const Hits& hits : pass.candidates) {
      for (const auto& [j, d2] : hits) {
        graph.columns.push_back(j);
        graph.costs.push_back(d2);
      }
      graph.offsets.push_back(graph.columns.size());
    }
    const double unlinked_cost = reach_ * reach_;
    pass.target = min_cost_assignment(graph, unlinked_cost);
    pass.objective = 0;
    for (std::size_t s = 0; s < n; ++s) {
      if (pass.target[s] < 0) {
        pass.objective += unlinked_cost;
        continue;
      }
      for (const auto& [j, d2] : pass.candidates[s]) {
        if (std::int64_t(j) == pass.target[s]) {
          pass.objective += d2;
          pass.residual2 += d2;
          break;
        }
      }
      ++pass.links;
    }
    return pass;
  }

  std::vector<Confident> confident(const Pass& pass) const {
    const std::size_t m = to_.size();
    std::vector<std::int64_t> nearest_source(m, -1);
    std::vector<double> nearest_d2(m, std::numeric_limits<double>::infinity());
    for (std::size_t s = 0; s < base_.size(); ++s) {
      for (const auto& [j, d2] : pass.candidates[s]) {
        if (d2 < nearest_d2[j]) {
          nearest_d2[j] = d2;
          nearest_source[j] = std::int64_t(s);
        }
      }
    }
    std::vector<Confident> out;
    for (std::size_t s = 0; s < fresh_; ++s) {
      const std::int64_t j = pass.target[s];
      if (j < 0 || pass.candidates[s].front().first != std::uint32_t(j) ||
          nearest_source[std::size_t(j)] != std::int64_t(s)) {
        continue;
      }
      out.push_back({s, base_[s], to_.points().row(Eigen::Index(j)).transpose() - base_[s]});
    }
    return out;
  }

  // The mean displacement of the confident links.
  static std::optional<Motion> fit_drift(const std::vector<Confident>& links) {
    if (links.empty()) return std::nullopt;
    Motion m;
    for (const Confident& c : links) {
      m.drift += c.moved;
      m.centre += c.where;
    }
    m.drift /= double(links.size());
    m.centre /= double(links.size());
    return m;
  }

  // The least-squares uniform deformation (drift and displacement gradient) of the confident
  // links; none where they do not span the three dimensions.
  static std::optional<Motion> fit_affine(const std::vector<Confident>& links) {
    std::optional<Motion> m = fit_drift(links);
    if (!m || links.size() < 12) return std::nullopt;
    Eigen::Matrix3d xx = Eigen::Matrix3d::Zero(), ux = Eigen::Matrix3d::Zero();
    for (const Confident& c : links) {
      const Eigen::Vector3d dx = c.where - m->centre;
      xx += dx * dx.transpose();
      ux += (c.moved - m->drift) * dx.transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(xx);
    if (!(eigen.eigenvalues()[0] > 1e-6 * eigen.eigenvalues()[2])) return std::nullopt;
    m->gradient = ux * xx.inverse();
    return m;
  }

  // Each source's motion from the collective motion of its neighbourhood, found without
  // any link: the displacements from each of its `k` nearest sources (itself included),
  // moved as `predicted`, to every detection within `search` of where that source is
  // predicted form a cloud in which the neighbourhood's common motion is the one dense
  // spot (a wrong partner is another grain, about a diameter away, in a direction of its
  // own). The spot is the cloud point with the most others within `kernel`; the source is
  // predicted at the mean of those. Follows motions that are smooth but not uniform (a
  // shear band) far beyond what linking with the global motion alone can reach.
  std::vector<Eigen::Vector3d> local_mode(const std::vector<Eigen::Vector3d>& predicted,
                                          std::size_t k, double search, double kernel) const {
    std::vector<Eigen::Vector3d> offset = predicted;
    if (base_.size() < 3 || to_.size() == 0) return offset;
    const PointIndex sources(to_rows(base_));
#pragma omp parallel if (base_.size() > kParallel)
    {
      Hits neighbours, hits;
      std::vector<Eigen::Vector3d> cloud;
      constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
      const int cells = int(std::ceil(2 * (search + kernel) / kernel)) + 1;
      std::vector<std::uint32_t> head, next;
#pragma omp for schedule(dynamic, 256)
      for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(base_.size()); ++i) {
        const auto s = std::size_t(i);
        sources.nearest(base_[s], k + 1, neighbours);
        cloud.clear();
        for (const auto& [n, d2] : neighbours) {
          if (n == s) continue;
          const Eigen::Vector3d from = base_[n] + predicted[n];
          to_.within(from, search, hits);
          for (const auto& [j, e2] : hits)
            cloud.push_back(to_.points().row(Eigen::Index(j)).transpose() - from);
        }
        // Counted on a grid of `kernel` cells: only the 27 cells around a point can hold
        // points within `kernel` of it.
        const double lo = -search - kernel;
        head.assign(std::size_t(cells * cells * cells), kNone);
        next.resize(cloud.size());
        auto cell = [&](const Eigen::Vector3d& v, int a) {
          return std::clamp(int((v[a] - lo) / kernel), 0, cells - 1);
        };
        for (std::size_t p = 0; p < cloud.size(); ++p) {
          const int c = (cell(cloud[p], 0) * cells + cell(cloud[p], 1)) * cells + cell(cloud[p], 2);
          next[p] = head[std::size_t(c)];
          head[std::size_t(c)] = std::uint32_t(p);
        }
        auto around = [&](const Eigen::Vector3d& a, auto&& f) {
          const int x = cell(a, 0), y = cell(a, 1), z = cell(a, 2);
          for (int i = std::max(0, x - 1); i <= std::min(cells - 1, x + 1); ++i)
            for (int j = std::max(0, y - 1); j <= std::min(cells - 1, y + 1); ++j)
              for (int l = std::max(0, z - 1); l <= std::min(cells - 1, z + 1); ++l)
                for (std::uint32_t q = head[std::size_t((i * cells + j) * cells + l)]; q != kNone;
                     q = next[q]) {
                  if ((a - cloud[q]).squaredNorm() <= kernel * kernel) f(cloud[q]);
                }
        };
        std::size_t best_count = 0;
        const Eigen::Vector3d* best = nullptr;
        for (const Eigen::Vector3d& a : cloud) {
          std::size_t count = 0;
          around(a, [&](const Eigen::Vector3d&) { ++count; });
          if (count > best_count ||
              (count == best_count && a.squaredNorm() < best->squaredNorm())) {
            best_count = count;
            best = &a;
          }
        }
        if (best_count < 3) continue;
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        around(*best, [&](const Eigen::Vector3d& b) { mean += b; });
        offset[s] += mean / double(best_count);
      }
    }
    return offset;
  }

  // Each source's motion from the confident links of its `k` nearest neighbours within
  // `within` (itself left out): the global motion plus the component-wise median of their
  // deviations from it; the global motion alone where fewer than three are there.
  std::vector<Eigen::Vector3d> local_field(const Pass& pass, std::size_t k, double within) const {
    const std::vector<Confident> links = confident(pass);
    std::vector<Eigen::Vector3d> offset(base_.size());
    for (std::size_t s = 0; s < base_.size(); ++s)
      offset[s] = pass.motion.at(base_[s]);
    if (links.size() < 3) return offset;
    std::vector<Eigen::Vector3d> where;
    for (const Confident& c : links)
      where.push_back(c.where);
    const PointIndex index(to_rows(where));
#pragma omp parallel if (base_.size() > kParallel)
    {
      Hits hits;
      std::vector<double> component[3];
#pragma omp for schedule(dynamic, 256)
      for (std::ptrdiff_t i = 0; i < std::ptrdiff_t(base_.size()); ++i) {
        const auto s = std::size_t(i);
        index.nearest(base_[s], k + 1, hits);
        for (auto& c : component)
          c.clear();
        for (const auto& [n, d2] : hits) {
          const Confident& c = links[n];
          if (c.source == s || d2 > within * within) continue;
          if (component[0].size() == k) break;
          const Eigen::Vector3d deviation = c.moved - pass.motion.at(c.where);
          for (int a = 0; a < 3; ++a)
            component[a].push_back(deviation[a]);
        }
        if (component[0].size() < 3) continue;
        for (int a = 0; a < 3; ++a)
          offset[s][a] += median(component[a]);
      }
    }
    return offset;
  }

 private:
  const std::vector<Eigen::Vector3d>& base_;
  std::size_t fresh_;
  const PointIndex& to_;
  double reach_;
};

struct Track {
  // Where the grain was last seen, moved by the motion predicted for the scans it missed.
  Eigen::Vector3d at;
  std::size_t last_scan = 0;
  std::vector<std::pair<std::size_t, std::size_t>> seen;  // (scan, detection)
};

void check_scans(const std::vector<Detections>& scans, const LinkOptions& options) {
  if (scans.empty()) throw Error("link: no scans to link");
  if (!(options.max_displacement >= 0) || !std::isfinite(options.max_displacement)) {
    throw Error("link: the max displacement must be a finite length >= 0");
  }
  if (options.memory < 0) throw Error("link: memory must be >= 0 scans");
  if (options.neighbours < 3) throw Error("link: the local field needs >= 3 neighbours");
  if (options.refinements < 0) throw Error("link: refinements must be >= 0");
  const Detections& first = scans.front();
  auto name = [&](std::size_t t) {
    return "scan " + std::to_string(t) +
           (scans[t].source.empty() ? "" : " (" + scans[t].source + ")");
  };
  auto vector_text = [](const std::optional<Eigen::Vector3d>& v) {
    if (!v) return std::string("none");
    std::ostringstream s;
    s << (*v)[0] << "," << (*v)[1] << "," << (*v)[2];
    return s.str();
  };
  for (std::size_t t = 0; t < scans.size(); ++t) {
    const Detections& d = scans[t];
    if (d.length_unit != first.length_unit) {
      throw Error("link: " + name(t) + " has lengths in " + d.length_unit + ", " + name(0) +
                  " in " + first.length_unit + ": all scans must use one length unit");
    }
    if (d.voxel_size.has_value() != first.voxel_size.has_value() ||
        (d.voxel_size && *d.voxel_size != *first.voxel_size)) {
      throw Error("link: " + name(t) + " has voxel size " + vector_text(d.voxel_size) + ", " +
                  name(0) + " " + vector_text(first.voxel_size) +
                  ": all scans must have the same voxel size");
    }
    if (t > 0 && d.frame <= scans[t - 1].frame) {
      throw Error("link: " + name(t) + " has frame " + std::to_string(d.frame) +
                  ", not after frame " + std::to_string(scans[t - 1].frame) + " of " + name(t - 1) +
                  ": give the scans in order, each with its own frame");
    }
    // The standard errors may be left empty (unknown).
    const auto sized = [&](std::size_t n) { return n == d.size(); };
    if (!sized(d.radius.size()) ||
        !(d.position_error.rows() == 0 || sized(std::size_t(d.position_error.rows()))) ||
        (d.has_axis && (!sized(std::size_t(d.axis.rows())) || !sized(d.hole_contact.size()) ||
                        !(d.axis_error.empty() || sized(d.axis_error.size()))))) {
      throw Error("link: " + name(t) + ": detection fields of unequal lengths");
    }
    if (!d.position.allFinite()) {
      throw Error("link: " + name(t) + ": a detection has a non-finite position");
    }
  }
}

// The typical grain diameter: twice the median radius, else the median nearest-neighbour
// distance; 0 when neither can be had.
double typical_diameter(const std::vector<Detections>& scans) {
  std::vector<double> radii;
  for (const Detections& d : scans) {
    for (double r : d.radius)
      if (std::isfinite(r) && r > 0) radii.push_back(r);
  }
  if (!radii.empty()) return 2 * median(radii);
  std::vector<double> spacing;
  for (const Detections& d : scans) {
    if (d.size() < 2) continue;
    const PointIndex index(d.position);
    Hits hits;
    for (std::size_t i = 0; i < d.size(); ++i) {
      index.nearest(d.position.row(Eigen::Index(i)).transpose(), 2, hits);
      if (hits.size() == 2) spacing.push_back(std::sqrt(hits[1].second));
    }
  }
  return spacing.empty() ? 0.0 : median(spacing);
}

}  // namespace

double default_max_displacement(const std::vector<Detections>& scans) {
  return kDefaultReach * typical_diameter(scans);
}

namespace {

// The largest displacement a link may have: given, or kDefaultReach grain diameters; and the
// length scale of the motion estimates (the grains' diameter, or what the reach implies).
std::pair<double, double> reach_and_scale(const std::vector<Detections>& scans,
                                          const LinkOptions& options) {
  double scale = typical_diameter(scans);
  const double reach =
      options.max_displacement > 0 ? options.max_displacement : kDefaultReach * scale;
  if (!(scale > 0)) scale = reach / kDefaultReach;
  if (!(reach > 0)) {
    bool several = false;
    for (const Detections& d : scans)
      several = several || d.size() > 0;
    if (several && scans.size() > 1) {
      throw Error(
          "link: no grain radius and too few grains to choose a max displacement: give one");
    }
  }
  return {reach, scale};
}

// The tracks, scan by scan: every detection of the first starts one; each later scan is
// linked to the tracks seen in the scan before and those in memory.
class TrackBuilder {
 public:
  TrackBuilder(const std::vector<Detections>& scans, const LinkOptions& options, double reach,
               double scale)
      : scans_(scans), options_(options), reach_(reach), scale_(scale) {}

  ScanLinks first_scan() {
    const Detections& scan = scans_.front();
    ScanLinks report;
    report.frame = scan.frame;
    report.detections = scan.size();
    for (std::size_t j = 0; j < scan.size(); ++j)
      start_track(0, j);
    report.started = scan.size();
    return report;
  }

  ScanLinks next_scan(std::size_t t) {
    const Detections& scan = scans_[t];
    ScanLinks report;
    report.frame = scan.frame;
    report.detections = scan.size();
    // Sources: the tracks seen in the scan before first, then those in memory; each at its
    // last position moved by the motion predicted for the scans it missed.
    std::stable_sort(active_.begin(), active_.end(), [&](std::size_t a, std::size_t b) {
      return tracks_[a].last_scan > tracks_[b].last_scan;
    });
    std::vector<Eigen::Vector3d> base;
    std::size_t fresh = 0;
    for (std::size_t id : active_) {
      const Track& track = tracks_[id];
      base.push_back(track.at);
      if (track.last_scan == t - 1) ++fresh;
    }
    const PointIndex to(scan.position);
    const PairLinker linker(base, fresh, to, reach_);
    const Pass best = best_pass(linker, base, fresh, to);
    record(t, base, fresh, best, report);
    return report;
  }

  std::size_t track_count() const { return tracks_.size(); }

  // The run: one grain per track (its radius the mean of its detections'), one frame per
  // scan.
  Trajectories run() const {
    Trajectories run;
    RunHeader& h = run.header;
    h.length_unit = scans_.front().length_unit;
    h.time_unit = "cycle";
    h.voxel_size = scans_.front().voxel_size;
    // A scan's standard errors are stored where some scan has them.
    const auto finite = [](double e) { return std::isfinite(e); };
    for (const Detections& d : scans_) {
      h.has_axis = h.has_axis || d.has_axis;
      h.has_position_error = h.has_position_error || d.position_error.array().isFinite().any();
      h.has_axis_error =
          h.has_axis_error || std::any_of(d.axis_error.begin(), d.axis_error.end(), finite);
    }
    h.has_hole_contact = h.has_axis;
    h.id.resize(tracks_.size());
    h.radius.assign(tracks_.size(), kNaN);
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      h.id[k] = std::int64_t(k);
      double total = 0;
      std::size_t n = 0;
      for (const auto& [t, j] : tracks_[k].seen) {
        const double r = scans_[t].radius[j];
        if (std::isfinite(r)) {
          total += r;
          ++n;
        }
      }
      if (n) h.radius[k] = total / double(n);
    }
    std::ostringstream reach_text;
    reach_text.precision(12);
    reach_text << reach_ << " " << h.length_unit;
    h.parameters["link/max_displacement"] = reach_text.str();
    h.parameters["link/memory"] = std::to_string(options_.memory);
    h.parameters["link/drift"] = options_.estimate_drift ? "on" : "off";
    h.parameters["link/local_field"] = options_.local_field ? "on" : "off";
    run.frames.reserve(scans_.size());
    for (std::size_t t = 0; t < scans_.size(); ++t) {
      Frame frame = Frame::unknown(h);
      frame.step = scans_[t].frame;
      frame.time = double(scans_[t].frame);
      run.frames.push_back(std::move(frame));
    }
    for (std::size_t k = 0; k < tracks_.size(); ++k) {
      const auto g = Eigen::Index(k);
      for (const auto& [t, j] : tracks_[k].seen) {
        const Detections& d = scans_[t];
        Frame& frame = run.frames[t];
        frame.position.row(g) = d.position.row(Eigen::Index(j));
        if (d.position_error.rows() > 0 && h.has_position_error) {
          frame.position_error.row(g) = d.position_error.row(Eigen::Index(j));
        }
        if (d.has_axis) {
          frame.axis.row(g) = d.axis.row(Eigen::Index(j));
          frame.hole_contact[k] = d.hole_contact[j];
          if (!d.axis_error.empty() && h.has_axis_error) frame.axis_error[k] = d.axis_error[j];
        }
      }
    }
    return run;
  }

 private:
  void start_track(std::size_t t, std::size_t j) {
    Track track;
    track.at = scans_[t].position.row(Eigen::Index(j)).transpose();
    track.last_scan = t;
    track.seen.emplace_back(t, j);
    active_.push_back(tracks_.size());
    tracks_.push_back(std::move(track));
  }

  // No prediction, then the drift, the uniform deformation and the local field, each
  // refined from the links it gives (as in iterative closest point) and kept only while it
  // lowers the objective.
  Pass best_pass(const PairLinker& linker, const std::vector<Eigen::Vector3d>& base,
                 std::size_t fresh, const PointIndex& to) const {
    Pass best = linker.run(Motion{});
    auto better = [&](Pass&& pass) {
      // A pass must lower the objective by more than rounding and dithering (refits that
      // gain less than 1e-4 of it are not worth another pass).
      if (!(pass.objective < best.objective * (1 - 1e-4))) return false;
      best = std::move(pass);
      return true;
    };
    if (options_.estimate_drift && fresh > 0 && to.size() > 0) {
      const std::vector<Eigen::Vector3d> fresh_base(base.begin(),
                                                    base.begin() + std::ptrdiff_t(fresh));
      Motion mode;
      mode.drift = estimate_drift(fresh_base, to, scale_, reach_);
      better(linker.run(mode));
      for (int i = 0; i < kRefits; ++i) {
        const std::optional<Motion> m = PairLinker::fit_drift(linker.confident(best));
        if (!m || !better(linker.run(*m))) break;
      }
      for (int i = 0; options_.deformation && i < kRefits; ++i) {
        const std::optional<Motion> m = PairLinker::fit_affine(linker.confident(best));
        if (!m || !better(linker.run(*m))) break;
      }
    }
    if (options_.local_field && base.size() > 0) {
      std::vector<Eigen::Vector3d> predicted(base.size());
      for (std::size_t s = 0; s < base.size(); ++s)
        predicted[s] = best.motion.at(base[s]);
      const std::vector<Eigen::Vector3d> offset =
          linker.local_mode(predicted, 2 * std::size_t(options_.neighbours),
                            std::max(2 * reach_, scale_), 0.3 * scale_);
      Pass refined = linker.run(best.motion, &offset);
      refined.local_field = true;
      better(std::move(refined));
    }
    for (int i = 0; options_.local_field && i < options_.refinements; ++i) {
      const std::vector<Eigen::Vector3d> offset =
          linker.local_field(best, std::size_t(options_.neighbours), 3 * scale_);
      Pass refined = linker.run(best.motion, &offset);
      refined.local_field = true;
      if (!better(std::move(refined))) break;
    }
    return best;
  }

  // The links of scan t: tracks moved on, kept in memory or ended; the detections left
  // start new tracks.
  void record(std::size_t t, const std::vector<Eigen::Vector3d>& base, std::size_t fresh,
              const Pass& best, ScanLinks& report) {
    const Detections& scan = scans_[t];
    report.previous = fresh;
    report.drift = best.motion.drift;
    report.gradient = best.motion.gradient;
    report.local_field = best.local_field;
    report.rms_residual = best.links ? std::sqrt(best.residual2 / double(best.links)) : 0.0;
    std::vector<char> taken(scan.size(), 0);
    std::vector<std::size_t> source_degree(base.size(), 0), target_degree(scan.size(), 0);
    for (std::size_t s = 0; s < base.size(); ++s) {
      source_degree[s] = best.candidates[s].size();
      for (const auto& [j, d2] : best.candidates[s])
        ++target_degree[j];
    }
    Eigen::Vector3d moved = Eigen::Vector3d::Zero();
    std::vector<std::size_t> still_active;
    for (std::size_t s = 0; s < base.size(); ++s) {
      Track& track = tracks_[active_[s]];
      const std::int64_t j = best.target[s];
      if (j >= 0) {
        const auto jj = std::size_t(j);
        taken[jj] = 1;
        ++report.linked;
        if (s >= fresh) ++report.relinked;
        if (s < fresh) moved += scan.position.row(Eigen::Index(jj)).transpose() - base[s];
        if (source_degree[s] > 1 || target_degree[jj] > 1) ++report.ambiguous;
        track.at = scan.position.row(Eigen::Index(jj)).transpose();
        track.last_scan = t;
        track.seen.emplace_back(t, jj);
        still_active.push_back(active_[s]);
        continue;
      }
      if (s < fresh) {
        ++report.unlinked;
        report.unlinked_tracks.push_back(std::int64_t(active_[s]));
      }
      if (t - track.last_scan <= std::size_t(options_.memory)) {
        track.at = best.expected[s];
        ++report.kept;
        still_active.push_back(active_[s]);
      } else {
        ++report.ended;
      }
    }
    std::sort(report.unlinked_tracks.begin(), report.unlinked_tracks.end());
    const std::size_t fresh_links = report.linked - report.relinked;
    if (fresh_links) report.mean_displacement = moved / double(fresh_links);

    active_ = std::move(still_active);
    report.first_new_track = std::int64_t(tracks_.size());
    for (std::size_t j = 0; j < scan.size(); ++j) {
      if (taken[j]) continue;
      report.new_detections.push_back(j);
      start_track(t, j);
    }
    report.started = report.new_detections.size();
  }

  const std::vector<Detections>& scans_;
  const LinkOptions& options_;
  const double reach_, scale_;
  std::vector<Track> tracks_;
  std::vector<std::size_t> active_;  // tracks that may still be linked
};

}  // namespace

Trajectories link_scans(const std::vector<Detections>& scans, const LinkOptions& options,
                        LinkSummary* summary) {
  check_scans(scans, options);
  const auto [reach, scale] = reach_and_scale(scans, options);
  LinkSummary local_summary;
  LinkSummary& sum = summary ? *summary : local_summary;
  sum = LinkSummary{};
  sum.max_displacement = reach;
  sum.length_unit = scans.front().length_unit;
  TrackBuilder tracks(scans, options, reach, scale);
  sum.scans.push_back(tracks.first_scan());
  for (std::size_t t = 1; t < scans.size(); ++t) {
    const std::string what =
        "scan " + std::to_string(t + 1) + " of " + std::to_string(scans.size());
    if (options.stop && options.stop->load()) throw Error("link: stopped before " + what);
    if (options.log) options.log("linking " + what);
    sum.scans.push_back(tracks.next_scan(t));
  }
  sum.tracks = tracks.track_count();
  return tracks.run();
}

}  // namespace granmem
