#include "granmem/tracking/holed_sphere.hpp"

namespace granmem {

HoledSphere::Fraction HoledSphere::fraction(const Eigen::Vector3d& p, bool derivatives) const {
  Fraction f;
  const Eigen::Vector3d d = p - centre;
  const double r = d.norm();
  const double u = (radius - r) / blur;
  const NormalCdfPdf su = normal_cdf_pdf(u);
  const double sphere = su.cdf;
  NormalCdfPdf hw{0, 0};
  double hole_value = 0, w = 0, rho = 0, t = 0;
  Eigen::Vector3d q = Eigen::Vector3d::Zero();
  if (hole > 0) {
    t = d.dot(axis);
    q = d - t * axis;  // the part of d across the axis
    rho = q.norm();
    w = (hole * radius - rho) / blur;
    hw = normal_cdf_pdf(w);
    hole_value = hw.cdf;
  }
  f.value = sphere * (1 - hole_value);
  if (!derivatives) return f;

  // dS: u = (R - r)/s, dr/dc = -d/r.
  const double ds = su.pdf / blur;
  const Eigen::Vector3d du_dc = r > 0 ? Eigen::Vector3d(d / r) : Eigen::Vector3d::Zero();
  f.d_centre = ds * du_dc * (1 - hole_value);
  f.d_radius = ds * (1 - hole_value);
  f.d_blur = -ds * u * (1 - hole_value);
  if (hole > 0) {
    // dH: w = (h R - rho)/s, drho/dc = -q/rho, drho/da = -t q/rho.
    const double dh = hw.pdf / blur;
    const Eigen::Vector3d q_unit = rho > 0 ? Eigen::Vector3d(q / rho) : Eigen::Vector3d::Zero();
    f.d_centre -= sphere * dh * q_unit;  // dw/dc = +q/rho
    f.d_radius -= sphere * dh * hole;
    f.d_blur += sphere * dh * w;
    f.d_axis = -sphere * dh * t * q_unit;  // dw/da = +t q/rho
  }
  return f;
}

}  // namespace granmem
