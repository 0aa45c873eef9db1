#include "granmem/sim/grains.hpp"

#include <cmath>

namespace granmem {

void Grains::add(std::int64_t grain_id, const Eigen::Vector3d& position, double r, double density) {
  const double m = 4.0 / 3.0 * M_PI * r * r * r * density;
  id.push_back(grain_id);
  radius.push_back(r);
  mass.push_back(m);
  inv_mass.push_back(1.0 / m);
  inv_inertia.push_back(1.0 / (0.4 * m * r * r));
  x.push_back(position);
  v.push_back(Eigen::Vector3d::Zero());
  w.push_back(Eigen::Vector3d::Zero());
  q.push_back(Eigen::Quaterniond::Identity());
  force.push_back(Eigen::Vector3d::Zero());
  torque.push_back(Eigen::Vector3d::Zero());
}

double Grains::kinetic_energy() const {
  double e = 0;
  for (std::size_t i = 0; i < size(); ++i) {
    e += 0.5 * mass[i] * v[i].squaredNorm() + 0.5 / inv_inertia[i] * w[i].squaredNorm();
  }
  return e;
}

}  // namespace granmem
