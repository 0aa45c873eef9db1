#pragma once

// Dense random packings and scans made from them with known displacements, for the tests
// of the linker.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <random>
#include <unordered_map>
#include <vector>

#include "granmem/core/trajectories.hpp"
#include "granmem/tracking/detections.hpp"

namespace granmem::testing {

// `n` non-overlapping spheres of diameter 1 in a walled cube, at packing fraction `phi`
// (counted over the cube), disordered: random points pushed apart (overlapping pairs each
// moved by half their overlap, centres kept in the cube) while the diameter grows to 1,
// until the largest overlap is below 1e-3. Fine up to phi ~0.6.
inline std::vector<Eigen::Vector3d> random_packing(std::size_t n, double phi, std::uint32_t seed,
                                                   double* edge = nullptr) {
  const double pi = 3.14159265358979323846;
  const double L = std::cbrt(double(n) * pi / 6 / phi);
  if (edge) *edge = L;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uniform(0, L);
  std::vector<Eigen::Vector3d> x(n);
  for (auto& p : x)
    p = {uniform(rng), uniform(rng), uniform(rng)};
  const int cells = std::max(3, int(std::floor(L)));
  const double cell = L / cells;
  std::vector<std::vector<std::uint32_t>> grid(std::size_t(cells * cells * cells));
  auto index = [&](const Eigen::Vector3d& p, int k) {
    return std::clamp(int(p[k] / cell), 0, cells - 1);
  };
  auto wrap = [&](Eigen::Vector3d& p) {
    for (int k = 0; k < 3; ++k)
      p[k] -= L * std::floor(p[k] / L);
  };
  // Gauss-Seidel: each pair is pushed apart at once, which settles far faster than moving
  // all grains together.
  for (int iteration = 0; iteration < 2000; ++iteration) {
    const double d = std::min(1.0, 0.8 + 0.01 * iteration);
    for (auto& g : grid)
      g.clear();
    for (std::size_t i = 0; i < n; ++i) {
      grid[std::size_t((index(x[i], 0) * cells + index(x[i], 1)) * cells + index(x[i], 2))]
          .push_back(std::uint32_t(i));
    }
    double worst = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int a = index(x[i], 0), b = index(x[i], 1), c = index(x[i], 2);
      for (int p = a - 1; p <= a + 1; ++p) {
        for (int q = b - 1; q <= b + 1; ++q) {
          for (int r = c - 1; r <= c + 1; ++r) {
            const int P = (p + cells) % cells, Q = (q + cells) % cells, R = (r + cells) % cells;
            for (std::uint32_t j : grid[std::size_t((P * cells + Q) * cells + R)]) {
              if (j == i) continue;
              Eigen::Vector3d v = x[i] - x[j];
              for (int k = 0; k < 3; ++k)
                v[k] += v[k] > L / 2 ? -L : v[k] < -L / 2 ? L : 0;
              const double dist2 = v.squaredNorm();
              if (dist2 >= d * d) continue;
              const double dist = std::sqrt(dist2);
              const double overlap = d - dist;
              worst = std::max(worst, overlap);
              const Eigen::Vector3d dir =
                  dist > 1e-12 ? Eigen::Vector3d(v / dist) : Eigen::Vector3d(1, 0, 0);
              x[i] += 0.6 * overlap * dir;
              x[j] -= 0.6 * overlap * dir;
              wrap(x[i]);
              wrap(x[j]);
            }
          }
        }
      }
    }
    if (d == 1.0 && worst < 1e-3) {
      break;
    }
  }
  return x;
}

// The smallest distance between two of the points (brute force over a cell grid is not
// needed for the few thousand points of a test).
inline double closest_pair(const std::vector<Eigen::Vector3d>& x) {
  double best = INFINITY;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j)
      best = std::min(best, (x[i] - x[j]).norm());
  return best;
}

// A random displacement uniform in the ball of radius `a`.
inline Eigen::Vector3d in_ball(std::mt19937& rng, double a) {
  std::uniform_real_distribution<double> u(-1, 1);
  for (;;) {
    const Eigen::Vector3d v(u(rng), u(rng), u(rng));
    if (v.squaredNorm() <= 1) return a * v;
  }
}

// A scan of grains: detection k is grain grain[k] (-1: a spurious detection), radius 0.5
// (diameter 1), lengths in mm.
struct Scan {
  Detections detections;
  std::vector<std::int64_t> grain;
};

// A scan of the grains at `x`, each seen at its position plus Gaussian noise of `noise` per
// axis, in a shuffled order; a fraction `missing` of the grains is not seen, and `extra`
// spurious detections are added at random places in the bounding box.
inline Scan scan_of(const std::vector<Eigen::Vector3d>& x, std::int64_t frame, std::mt19937& rng,
                    double noise = 0, double missing = 0, std::size_t extra = 0) {
  std::normal_distribution<double> gauss(0, 1);
  std::uniform_real_distribution<double> uniform(0, 1);
  Scan s;
  for (std::size_t g = 0; g < x.size(); ++g) {
    if (missing > 0 && uniform(rng) < missing) continue;
    s.grain.push_back(std::int64_t(g));
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3d& p : x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (std::size_t e = 0; e < extra; ++e)
    s.grain.push_back(-1);
  std::shuffle(s.grain.begin(), s.grain.end(), rng);
  Detections& d = s.detections;
  d.frame = frame;
  d.length_unit = "mm";
  d.position.resize(Eigen::Index(s.grain.size()), 3);
  for (std::size_t k = 0; k < s.grain.size(); ++k) {
    Eigen::Vector3d p;
    if (s.grain[k] < 0) {
      for (int a = 0; a < 3; ++a)
        p[a] = lo[a] + (hi[a] - lo[a]) * uniform(rng);
    } else {
      p = x[std::size_t(s.grain[k])];
      if (noise > 0) p += noise * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng));
    }
    d.position.row(Eigen::Index(k)) = p.transpose();
  }
  d.radius.assign(s.grain.size(), 0.5);
  d.quality.assign(s.grain.size(), 1.0);
  d.edge.assign(s.grain.size(), 0);
  return s;
}

// How the links of a run join the true grains between two of its frames.
struct LinkScore {
  std::size_t links = 0;     // tracks seen in both frames
  std::size_t correct = 0;   // of those, the same grain in both
  std::size_t possible = 0;  // grains detected in both scans
  double fraction_correct() const { return links ? double(correct) / double(links) : 1.0; }
  double fraction_found() const { return possible ? double(correct) / double(possible) : 1.0; }
};

// Scores frames `a` and `b` of `run` (linked from scans including sa and sb): positions are
// copied from the detections, so each is traced back to its detection and grain.
inline LinkScore score_links(const Trajectories& run, std::size_t a, std::size_t b, const Scan& sa,
                             const Scan& sb) {
  auto key = [](const Eigen::Vector3d& p) { return std::array<double, 3>{p[0], p[1], p[2]}; };
  auto grains = [&](const Scan& s) {
    std::map<std::array<double, 3>, std::int64_t> m;
    for (std::size_t k = 0; k < s.grain.size(); ++k)
      m[key(s.detections.position.row(Eigen::Index(k)).transpose())] = s.grain[k];
    return m;
  };
  const auto ga = grains(sa), gb = grains(sb);
  LinkScore score;
  std::unordered_map<std::int64_t, int> seen;
  for (std::int64_t g : sa.grain)
    if (g >= 0) seen[g] |= 1;
  for (std::int64_t g : sb.grain)
    if (g >= 0) seen[g] |= 2;
  for (const auto& [g, both] : seen)
    score.possible += both == 3;
  const Vectors3 &pa = run.frames[a].position, &pb = run.frames[b].position;
  for (Eigen::Index k = 0; k < pa.rows(); ++k) {
    if (!pa.row(k).allFinite() || !pb.row(k).allFinite()) continue;
    ++score.links;
    const std::int64_t x = ga.at(key(pa.row(k).transpose())), y = gb.at(key(pb.row(k).transpose()));
    score.correct += x >= 0 && x == y;
  }
  return score;
}

}  // namespace granmem::testing
