#pragma once

// Small setups and checks the sim tests share.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "granmem/sim/simulation.hpp"

namespace granmem::testing {

// 0.5 cm acrylic grains, as in the paper.
inline constexpr double kRadius = 0.0025, kDensity = 1180;
inline constexpr double kGravity = 9.81;

// The same double, bit for bit (so -0.0 differs from 0.0 and NaNs compare by payload).
inline bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof(double)) == 0;
}
inline bool same_bits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}
inline bool same_bits(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  return std::memcmp(a.coeffs().data(), b.coeffs().data(), 4 * sizeof(double)) == 0;
}

// Every per-grain state array of `a` equal bit for bit to `b`'s, grains matched by index.
inline ::testing::AssertionResult same_grain_state(const Grains& a, const Grains& b) {
  if (a.size() != b.size()) {
    return ::testing::AssertionFailure() << a.size() << " vs " << b.size() << " grains";
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    auto fail = [&](const char* what) {
      return ::testing::AssertionFailure()
             << what << " of grain " << i << " (id " << a.id[i] << ") differs";
    };
    if (a.id[i] != b.id[i]) return fail("id");
    if (!same_bits(a.radius[i], b.radius[i])) return fail("radius");
    if (!same_bits(a.mass[i], b.mass[i])) return fail("mass");
    if (!same_bits(a.inv_mass[i], b.inv_mass[i])) return fail("inverse mass");
    if (!same_bits(a.inv_inertia[i], b.inv_inertia[i])) return fail("inverse inertia");
    if (!same_bits(a.x[i], b.x[i])) return fail("position");
    if (!same_bits(a.v[i], b.v[i])) return fail("velocity");
    if (!same_bits(a.w[i], b.w[i])) return fail("angular velocity");
    if (!same_bits(a.q[i], b.q[i])) return fail("orientation");
    if (!same_bits(a.force[i], b.force[i])) return fail("force");
    if (!same_bits(a.torque[i], b.torque[i])) return fail("torque");
  }
  return ::testing::AssertionSuccess();
}

// A number for RecordProperty, to 9 significant digits.
inline std::string number(double x) {
  std::ostringstream out;
  out.precision(9);
  out << x;
  return out.str();
}

// A box whose side walls are far from everything.
inline Container wide_box(double side = 1.0) {
  Container c;
  c.size = {side, side};
  return c;
}

// Weight-bearing overlap of a grain resting on the floor: m g / k_n.
inline double resting_overlap(double mass, const PhysicsOptions& p) {
  return mass * p.gravity / p.contact.k_n;
}

// A dense, touching cluster: an nx x ny x nz cubic lattice of grains of radius kRadius
// (+- `polydispersity`), `spacing` times the diameter apart (< 1: overlapping), with random
// velocities, spins and orientations. Ids are 10 * index + 3.
inline Grains lattice_cluster(int nx, int ny, int nz, double spacing, unsigned seed,
                              double polydispersity = 0.02) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Grains g;
  const double pitch = 2 * kRadius * spacing;
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        const Eigen::Vector3d x(kRadius + pitch * i, kRadius + pitch * j, kRadius + pitch * k);
        const Eigen::Vector3d jitter(u(rng), u(rng), u(rng));
        g.add(10 * std::int64_t(g.size()) + 3, x + 2e-5 * jitter,
              kRadius * (1 + polydispersity * u(rng)), kDensity);
        g.v.back() = 0.05 * Eigen::Vector3d(u(rng), u(rng), u(rng));
        g.w.back() = 20.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
        g.q.back() = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized();
      }
    }
  }
  return g;
}

}  // namespace granmem::testing
