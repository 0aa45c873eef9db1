#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <limits>

#include "granmem/core/inline.hpp"

namespace granmem {

// What every mode of the contact law reads about one contact between grain i and body j
// (a grain or a wall), computed once per contact and step.
struct ContactGeometry {
  Eigen::Vector3d n;             // unit normal, from j to i
  double overlap = 0;            // delta > 0 while in contact
  double l_i = 0, l_j = 0;       // centre to contact plane; l_j = inf for a wall
  double l_ij = 0;               // 2 l_i l_j / (l_i + l_j); 2 l_i for a wall
  double sqrt_reduced_mass = 0;  // sqrt(m_i m_j / (m_i + m_j)); sqrt(m_i) for a wall
  double v_n = 0;                // normal relative velocity at the contact, > 0 separating
  Eigen::Vector3d v_t;           // tangential relative velocity of i's surface over j's
  Eigen::Vector3d w_i, w_j;      // angular velocities (w_j = 0 for a wall)
  bool wall = false;
};

// Two spheres whose centres are `d = |x_i - x_j|` apart with d < R_i + R_j;
// `sqrt_reduced_mass` = sqrt(m_i m_j / (m_i + m_j)), which the caller may hold constant.
GRANMEM_INLINE ContactGeometry
sphere_contact(const Eigen::Vector3d& x_i, const Eigen::Vector3d& x_j, double r_i, double r_j,
               const Eigen::Vector3d& v_i, const Eigen::Vector3d& v_j, const Eigen::Vector3d& w_i,
               const Eigen::Vector3d& w_j, double sqrt_reduced_mass) {
  ContactGeometry g;
  const Eigen::Vector3d dx = x_i - x_j;
  const double d = dx.norm(), inv_d = 1.0 / d;
  g.n = dx * inv_d;
  g.overlap = r_i + r_j - d;
  // The contact plane is the radical plane of the two spheres.
  g.l_i = (d * d + r_i * r_i - r_j * r_j) * (0.5 * inv_d);
  g.l_j = d - g.l_i;
  g.l_ij = 2.0 * g.l_i * g.l_j * inv_d;  // l_i + l_j = d
  g.sqrt_reduced_mass = sqrt_reduced_mass;
  // Surface velocities at the contact point: i's at -l_i n, j's at +l_j n.
  const Eigen::Vector3d v = v_i - v_j + g.n.cross(g.l_i * w_i + g.l_j * w_j);
  g.v_n = v.dot(g.n);
  g.v_t = v - g.v_n * g.n;
  g.w_i = w_i;
  g.w_j = w_j;
  return g;
}

GRANMEM_INLINE double sqrt_reduced_mass(double m_i, double m_j) {
  return std::sqrt(m_i * m_j / (m_i + m_j));
}

// A sphere against a flat wall whose inward unit normal is `normal`, at signed distance
// `distance` (< r_i) from the sphere's centre, moving with `wall_velocity`; `sqrt_m_i` is
// the square root of the sphere's mass.
GRANMEM_INLINE ContactGeometry wall_contact(double distance, const Eigen::Vector3d& normal,
                                            double r_i, const Eigen::Vector3d& v_i,
                                            const Eigen::Vector3d& w_i, double sqrt_m_i,
                                            const Eigen::Vector3d& wall_velocity) {
  ContactGeometry g;
  g.wall = true;
  g.n = normal;
  g.overlap = r_i - distance;
  g.l_i = distance;
  g.l_j = std::numeric_limits<double>::infinity();
  g.l_ij = 2.0 * distance;         // the limit of 2 l_i l_j / (l_i + l_j)
  g.sqrt_reduced_mass = sqrt_m_i;  // a wall's mass is infinite
  const Eigen::Vector3d v = v_i - wall_velocity + g.l_i * g.n.cross(w_i);
  g.v_n = v.dot(g.n);
  g.v_t = v - g.v_n * g.n;
  g.w_i = w_i;
  g.w_j = Eigen::Vector3d::Zero();
  return g;
}

}  // namespace granmem
