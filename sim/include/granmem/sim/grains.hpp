#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace granmem {

// The grains of a simulation, as arrays (one entry per grain), SI units. A grain's
// orientation is a unit quaternion; its body z axis is the cavity axis.
struct Grains {
  std::vector<std::int64_t> id;
  std::vector<double> radius, mass, inv_mass, inv_inertia;
  std::vector<Eigen::Vector3d> x, v, w;  // position, velocity, angular velocity
  std::vector<Eigen::Quaterniond> q;
  std::vector<Eigen::Vector3d> force, torque;

  std::size_t size() const { return x.size(); }
  // A solid sphere of `density` at rest: m = 4/3 pi r^3 rho, I = 2/5 m r^2.
  void add(std::int64_t grain_id, const Eigen::Vector3d& position, double r, double density);
  double kinetic_energy() const;  // translational + rotational
};

}  // namespace granmem
