#pragma once

// Rendered scans of dense random packings and the score of `locate` on them: which grains
// were found, spurious detections, position errors, pixel locking and hole-axis errors. For
// the locate tests and bench/locate_bench.cpp.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "granmem/core/table.hpp"
#include "granmem/rotation/hole_contacts.hpp"
#include "granmem/tracking/detections.hpp"
#include "granmem/tracking/render.hpp"
#include "link_packing.hpp"

namespace granmem::testing {

// A scan of a dense random packing (random_packing: diameter 1, lengths in mm) cut to the
// packing's cube [0, L]^3, so that grains at the faces are cut by the stack's border as in
// a real scan. Voxels: 1/diameter_px along x and y, z_ratio times that along z.
struct PackingScan {
  std::vector<RenderedGrain> grains;
  RenderOptions options;  // artefacts as RenderOptions' defaults unless changed
  double edge = 0;        // L, in diameters
};

inline PackingScan packing_scan(std::size_t n, double phi, double diameter_px, double z_ratio,
                                std::uint32_t seed) {
  PackingScan s;
  const std::vector<Eigen::Vector3d> x = random_packing(n, phi, seed, &s.edge);
  std::mt19937 rng(seed * 7919u + 1);
  std::normal_distribution<double> gauss(0, 1);
  for (std::size_t i = 0; i < x.size(); ++i) {
    RenderedGrain g;
    g.id = std::int64_t(i);
    g.centre = x[i];
    g.radius = 0.5;
    Eigen::Vector3d a;
    do {
      a = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    } while (a.norm() < 1e-6);
    g.axis = a.normalized();
    s.grains.push_back(g);
  }
  const double px = 1.0 / diameter_px;
  const Eigen::Vector3d voxel(px, px, z_ratio * px);
  s.options.voxel_size = voxel;
  s.options.origin = Eigen::Vector3d::Zero();
  s.options.length_unit = "mm";
  std::array<std::int64_t, 3> size{};
  for (int k = 0; k < 3; ++k)
    size[std::size_t(k)] = std::int64_t(std::floor(s.edge / voxel[k])) + 1;
  s.options.size = size;
  s.options.seed = seed;
  return s;
}

// The q-quantile of v (the value at rank floor(q n), clamped to the last); NaN when empty.
inline double percentile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  const std::size_t k = std::min(v.size() - 1, std::size_t(q * double(v.size())));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

// How well a set of detections matches the truth of a rendered scan. Errors in voxels of
// each axis (z in slices).
struct LocateScore {
  std::size_t grains = 0, interior = 0;  // in the truth; interior: not cut by the border
  std::size_t detections = 0;
  std::size_t interior_found = 0, edge_found = 0;
  std::size_t spurious = 0;                        // detections matching no grain
  std::size_t interior_flagged = 0;                // interior grains found but flagged edge
  std::size_t edge_unflagged = 0;                  // edge grains found but not flagged
  Eigen::Vector3d rms = Eigen::Vector3d::Zero();   // interior grains found, per axis
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();  // mean error per axis
  Eigen::Vector3d max_error = Eigen::Vector3d::Zero();
  // Pixel locking, per axis: the Kolmogorov-Smirnov distance of the fractional parts of the
  // detected positions from the uniform distribution (with its asymptotic p-value), and the
  // amplitude of the first harmonic of the error as a function of the true fractional part
  // (a locked position is pulled to the voxel centres: error ~ -A sin(2 pi frac)).
  Eigen::Vector3d ks = Eigen::Vector3d::Zero(), ks_p = Eigen::Vector3d::Zero();
  Eigen::Vector3d locking = Eigen::Vector3d::Zero();
  // Hole axis: angle between the lines in degrees, interior grains found.
  std::vector<double> axis_degrees;
  // What locate says of its own errors, interior grains found: the RMS of the centres'
  // standard errors per axis (voxels, like rms), and each axis' standard error (degrees,
  // beside axis_degrees where both are known; the standard deviation of the tilt in the
  // worse direction).
  Eigen::Vector3d rms_standard_error = Eigen::Vector3d::Zero();
  std::vector<double> axis_standard_error, axis_error_seen;

  double interior_fraction() const { return interior ? double(interior_found) / interior : 1.0; }
  double spurious_fraction() const { return grains ? double(spurious) / grains : 0.0; }
  double axis_percentile(double q) const { return percentile(axis_degrees, q); }
};

// Asymptotic Kolmogorov distribution: P(sqrt(n) D > t).
inline double kolmogorov_p(double t) {
  if (t < 0.2) return 1;
  double p = 0;
  for (int k = 1; k <= 100; ++k)
    p += 2 * ((k % 2) ? 1 : -1) * std::exp(-2.0 * k * k * t * t);
  return std::clamp(p, 0.0, 1.0);
}

inline double ks_uniform(std::vector<double> u) {
  if (u.empty()) return 0;
  std::sort(u.begin(), u.end());
  const double n = double(u.size());
  double d = 0;
  for (std::size_t i = 0; i < u.size(); ++i)
    d = std::max({d, double(i + 1) / n - u[i], u[i] - double(i) / n});
  return d;
}

// Detections matched to the truth (render_truth's table, voxel coordinates): each grain to
// the nearest detection within a quarter diameter, nearest pairs first, one to one.
// `voxel_size` turns the detections back into voxels (ones when they are in voxels).
struct LocateMatch {
  std::vector<Eigen::Vector3d> truth, detected;      // voxels
  std::vector<bool> edge;                            // truth: cut by the border
  std::vector<std::int64_t> of_grain, of_detection;  // -1: unmatched
  double diameter = 0;                               // voxels along x
};

inline LocateMatch match_locate(const Detections& d, const Table& truth,
                                const Eigen::Vector3d& voxel_size) {
  LocateMatch r;
  const std::size_t n = truth.rows();
  auto& t = r.truth;
  auto& det = r.detected;
  t.resize(n);
  det.resize(d.size());
  r.edge.resize(n);
  double& diameter = r.diameter;
  for (std::size_t i = 0; i < n; ++i) {
    t[i] = {truth["x"].values[i], truth["y"].values[i], truth["z"].values[i]};
    r.edge[i] = truth["edge"].values[i] != 0;
    diameter = std::max(diameter, 2 * truth["radius"].values[i]);
  }
  for (std::size_t k = 0; k < d.size(); ++k)
    det[k] = d.position.row(Eigen::Index(k)).transpose().cwiseQuotient(voxel_size);
  // Candidate pairs by distance (physical: voxels scaled to x pixels), through a grid.
  const Eigen::Vector3d scale = voxel_size / voxel_size.x();
  const double reach = 0.25 * diameter;
  struct Pair {
    double dist;
    std::size_t grain, detection;
  };
  std::vector<Pair> pairs;
  {
    std::vector<std::vector<std::size_t>> cells;
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (const auto& p : det) {
      lo = lo.cwiseMin(p.cwiseProduct(scale));
      hi = hi.cwiseMax(p.cwiseProduct(scale));
    }
    const double cell = std::max(reach, 1.0);
    const Eigen::Array3i dims =
        d.size() ? ((hi - lo) / cell).array().floor().cast<int>() + 1 : Eigen::Array3i(1, 1, 1);
    cells.resize(std::size_t(dims.prod()));
    auto index = [&](const Eigen::Vector3d& p) {
      return ((p.cwiseProduct(scale) - lo) / cell).array().floor().cast<int>().eval();
    };
    for (std::size_t k = 0; k < det.size(); ++k) {
      const Eigen::Array3i c = index(det[k]);
      cells[std::size_t((c.z() * dims.y() + c.y()) * dims.x() + c.x())].push_back(k);
    }
    for (std::size_t i = 0; i < n && !det.empty(); ++i) {
      const Eigen::Array3i c = index(t[i]);
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const Eigen::Array3i q = c + Eigen::Array3i(dx, dy, dz);
            if ((q < 0).any() || (q >= dims).any()) continue;
            for (std::size_t k :
                 cells[std::size_t((q.z() * dims.y() + q.y()) * dims.x() + q.x())]) {
              const double dist = (det[k] - t[i]).cwiseProduct(scale).norm();
              if (dist < reach) pairs.push_back({dist, i, k});
            }
          }
    }
  }
  std::sort(pairs.begin(), pairs.end(),
            [](const Pair& a, const Pair& b) { return a.dist < b.dist; });
  r.of_grain.assign(n, -1);
  r.of_detection.assign(d.size(), -1);
  for (const Pair& p : pairs) {
    if (r.of_grain[p.grain] >= 0 || r.of_detection[p.detection] >= 0) continue;
    r.of_grain[p.grain] = std::int64_t(p.detection);
    r.of_detection[p.detection] = std::int64_t(p.grain);
  }
  return r;
}

// How much longer the detections read the distances of touching neighbours than they are:
// the mean over matched interior pairs whose true centres are within `gap` of touching
// (distances scaled to x voxels), and how many.
struct NeighbourDistance {
  double offset = 0;  // voxels along x; < 0: read too close
  std::size_t pairs = 0;
};
inline NeighbourDistance touching_distance_offset(const LocateMatch& m,
                                                  const Eigen::Vector3d& voxel_size,
                                                  double gap = 0.02) {
  const Eigen::Vector3d scale = voxel_size / voxel_size.x();
  NeighbourDistance r;
  double sum = 0;
  for (std::size_t i = 0; i < m.truth.size(); ++i) {
    if (m.edge[i] || m.of_grain[i] < 0) continue;
    for (std::size_t j = i + 1; j < m.truth.size(); ++j) {
      if (m.edge[j] || m.of_grain[j] < 0) continue;
      const double truth = (m.truth[i] - m.truth[j]).cwiseProduct(scale).norm();
      if (truth > (1 + gap) * m.diameter) continue;
      const Eigen::Vector3d a = m.detected[std::size_t(m.of_grain[i])];
      const Eigen::Vector3d b = m.detected[std::size_t(m.of_grain[j])];
      sum += (a - b).cwiseProduct(scale).norm() - truth;
      ++r.pairs;
    }
  }
  if (r.pairs) r.offset = sum / double(r.pairs);
  return r;
}

// The true grains touching a neighbour through their hole (hole_contacts.hpp): centres
// within 2 % of a diameter of touching, radii 0.5 (the packings' diameter is 1).
inline std::vector<std::uint8_t> true_hole_contacts(const Table& truth, const LocateMatch& m,
                                                    const Eigen::Vector3d& voxel_size,
                                                    double hole_fraction) {
  const std::size_t n = truth.rows();
  Vectors3 centre(Eigen::Index(n), 3), axis(Eigen::Index(n), 3);
  for (std::size_t i = 0; i < n; ++i) {
    centre.row(Eigen::Index(i)) = m.truth[i].cwiseProduct(voxel_size).transpose();
    axis.row(Eigen::Index(i)) << truth["ax"].values[i], truth["ay"].values[i],
        truth["az"].values[i];
  }
  HoleContactOptions touching;
  touching.hole_fraction = hole_fraction;
  touching.gap = 0.02;
  return hole_contacts(centre, std::vector<double>(n, 0.5), axis, touching);
}

// Scores the detections of a rendered scan (see match_locate).
inline LocateScore score_locate(const Detections& d, const Table& truth,
                                const Eigen::Vector3d& voxel_size) {
  const LocateMatch r = match_locate(d, truth, voxel_size);
  LocateScore s;
  const std::size_t n = truth.rows();
  s.grains = n;
  s.detections = d.size();
  const auto& t = r.truth;
  const auto& det = r.detected;
  const auto& edge = r.edge;
  const auto& of_grain = r.of_grain;
  const auto& of_detection = r.of_detection;
  for (std::size_t i = 0; i < n; ++i)
    s.interior += !edge[i];
  for (std::size_t k = 0; k < d.size(); ++k)
    s.spurious += of_detection[k] < 0;

  std::array<std::vector<double>, 3> frac;
  Eigen::Vector3d sum2 = Eigen::Vector3d::Zero(), sum = Eigen::Vector3d::Zero();
  Eigen::Vector3d standard_error2 = Eigen::Vector3d::Zero();
  Eigen::Vector3d sin_sum = Eigen::Vector3d::Zero(), cos_sum = Eigen::Vector3d::Zero();
  std::size_t m = 0;
  const double two_pi = 2 * 3.14159265358979323846;
  for (std::size_t i = 0; i < n; ++i) {
    if (of_grain[i] < 0) continue;
    const std::size_t k = std::size_t(of_grain[i]);
    const bool flagged = d.edge[k] != 0;
    if (edge[i]) {
      ++s.edge_found;
      s.edge_unflagged += !flagged;
      continue;
    }
    ++s.interior_found;
    s.interior_flagged += flagged;
    const Eigen::Vector3d e = det[k] - t[i];
    sum += e;
    sum2 += e.cwiseAbs2();
    if (d.position_error.rows() > 0) {
      standard_error2 +=
          d.position_error.row(Eigen::Index(k)).transpose().cwiseQuotient(voxel_size).cwiseAbs2();
    }
    s.max_error = s.max_error.cwiseMax(e.cwiseAbs());
    for (int a = 0; a < 3; ++a) {
      frac[std::size_t(a)].push_back(det[k][a] - std::floor(det[k][a]));
      const double ft = t[i][a] - std::floor(t[i][a]);
      sin_sum[a] += e[a] * std::sin(two_pi * ft);
      cos_sum[a] += e[a] * std::cos(two_pi * ft);
    }
    ++m;
    if (d.has_axis) {
      const Eigen::Vector3d a = d.axis.row(Eigen::Index(k)).transpose();
      const Eigen::Vector3d b(truth["ax"].values[i], truth["ay"].values[i], truth["az"].values[i]);
      if (a.allFinite() && b.allFinite()) {
        const double c = std::min(1.0, std::abs(a.normalized().dot(b.normalized())));
        s.axis_degrees.push_back(std::acos(c) * 180 / 3.14159265358979323846);
        if (!d.axis_error.empty() && std::isfinite(d.axis_error[k])) {
          s.axis_error_seen.push_back(s.axis_degrees.back());
          s.axis_standard_error.push_back(d.axis_error[k] * 180 / 3.14159265358979323846);
        }
      }
    }
  }
  if (m > 0) {
    s.rms = (sum2 / double(m)).cwiseSqrt();
    s.rms_standard_error = (standard_error2 / double(m)).cwiseSqrt();
    s.bias = sum / double(m);
    for (int a = 0; a < 3; ++a) {
      s.ks[a] = ks_uniform(frac[std::size_t(a)]);
      s.ks_p[a] = kolmogorov_p(std::sqrt(double(m)) * s.ks[a]);
      s.locking[a] = 2 * std::hypot(sin_sum[a], cos_sum[a]) / double(m);
    }
  }
  return s;
}

// One line per interior grain missed and per spurious detection, with what is near it.
inline std::vector<std::string> describe_misses(const Detections& d, const Table& truth,
                                                const Eigen::Vector3d& voxel_size) {
  const LocateMatch r = match_locate(d, truth, voxel_size);
  const Eigen::Vector3d scale = voxel_size / voxel_size.x();
  std::vector<std::string> lines;
  auto nearest = [&](const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& among,
                     std::size_t skip) {
    double best = 1e300;
    std::size_t k = 0;
    for (std::size_t j = 0; j < among.size(); ++j) {
      const double dist = (among[j] - p).cwiseProduct(scale).norm();
      if (j != skip && dist < best) best = dist, k = j;
    }
    return std::pair<double, std::size_t>(best, k);
  };
  auto text = [](const Eigen::Vector3d& v) {
    std::ostringstream o;
    o.precision(4);
    o << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
    return o.str();
  };
  for (std::size_t i = 0; i < r.truth.size(); ++i) {
    if (r.edge[i] || r.of_grain[i] >= 0) continue;
    const auto [dist, k] = nearest(r.truth[i], r.detected, std::size_t(-1));
    const auto [gap, j] = nearest(r.truth[i], r.truth, i);
    std::ostringstream o;
    o << "missed grain " << truth["particle"].values[i] << " at " << text(r.truth[i])
      << ": nearest detection " << dist << " px away at " << text(r.detected[k])
      << (r.of_detection[k] >= 0 ? " (another grain's)" : " (unmatched)") << ", nearest grain "
      << gap << " px";
    lines.push_back(o.str());
  }
  // Grains cut by the border whose detection is not flagged: by how much they are cut.
  for (std::size_t i = 0; i < r.truth.size(); ++i) {
    if (!r.edge[i] || r.of_grain[i] < 0) continue;
    const std::size_t k = std::size_t(r.of_grain[i]);
    if (d.edge[k]) continue;
    const Eigen::Vector3d radius =
        Eigen::Vector3d::Constant(truth["radius"].values[i]).cwiseQuotient(scale);
    const Eigen::Vector3d fitted = Eigen::Vector3d::Constant(d.radius[k]).cwiseQuotient(voxel_size);
    std::ostringstream o;
    o << "edge grain " << truth["particle"].values[i] << " at " << text(r.truth[i])
      << " not flagged: true radius " << radius.x() << " px, fitted " << fitted.x() << " px";
    lines.push_back(o.str());
  }
  for (std::size_t k = 0; k < r.detected.size(); ++k) {
    if (r.of_detection[k] >= 0) continue;
    const auto [dist, i] = nearest(r.detected[k], r.truth, std::size_t(-1));
    std::ostringstream o;
    o << "spurious detection at " << text(r.detected[k]) << " radius "
      << d.radius[k] / voxel_size.x() << " px, quality " << d.quality[k] << ", edge "
      << int(d.edge[k]) << ": nearest grain " << dist << " px" << (r.edge[i] ? " (edge)" : "")
      << (r.of_grain[i] >= 0 ? ", found" : ", not found");
    lines.push_back(o.str());
  }
  return lines;
}

}  // namespace granmem::testing
