#include "granmem/tracking/holed_sphere.hpp"

namespace granmem {
namespace {

// The blur across a surface whose unit normal has z component nz (s^2 = a^2 (1 - nz^2) +
// z^2 nz^2, from the squares of the blurs across and along z), and, with `derivatives`,
// its derivatives with respect to the two blurs and nz.
struct SurfaceBlur {
  double s, ds_across = 0, ds_along_z = 0, ds_nz = 0;
  SurfaceBlur(double across, double along_z, double nz, bool derivatives) {
    const double a2 = across * across, z2 = along_z * along_z, nz2 = nz * nz;
    s = std::sqrt(a2 + (z2 - a2) * nz2);
    if (!derivatives) return;
    const double inverse = 1 / s;
    ds_across = across * (1 - nz2) * inverse;
    ds_along_z = along_z * nz2 * inverse;
    ds_nz = (z2 - a2) * nz * inverse;
  }
};

}  // namespace

HoledSphere::Fraction HoledSphere::fraction(const Eigen::Vector3d& p, bool derivatives) const {
  Fraction f;
  const double bz = along_z();
  const Eigen::Vector3d d = p - centre;
  const double r = d.norm();
  const Eigen::Vector3d n = r > 0 ? Eigen::Vector3d(d / r) : Eigen::Vector3d::Zero();
  const SurfaceBlur sb(blur, bz, n.z(), derivatives);
  const double u = (radius - r) / sb.s;
  const NormalCdfPdf su = normal_cdf_pdf(u);
  const double sphere = su.cdf;
  NormalCdfPdf hw{0, 0};
  SurfaceBlur hb(blur, blur, 0, false);
  double hole_value = 0, w = 0, rho = 0, t = 0;
  Eigen::Vector3d m = Eigen::Vector3d::Zero();  // the hole surface's normal
  if (hole > 0) {
    t = d.dot(axis);
    const Eigen::Vector3d q = d - t * axis;  // the part of d across the axis
    rho = q.norm();
    if (rho > 0) m = q / rho;
    hb = SurfaceBlur(blur, bz, m.z(), derivatives);
    w = (hole * radius - rho) / hb.s;
    hw = normal_cdf_pdf(w);
    hole_value = hw.cdf;
  }
  f.value = sphere * (1 - hole_value);
  if (!derivatives) return f;

  // dS: u = (R - r) / s(n_z), dr/dc = -n, dn_z/dc = -(e_z - n_z n) / r.
  const Eigen::Vector3d ez = Eigen::Vector3d::UnitZ();
  const double ds = su.pdf / sb.s;
  Eigen::Vector3d du_dc = n;
  if (r > 0) du_dc += u * sb.ds_nz * (ez - n.z() * n) / r;
  f.d_centre = ds * du_dc * (1 - hole_value);
  f.d_radius = ds * (1 - hole_value);
  f.d_blur = -ds * u * sb.ds_across * (1 - hole_value);
  f.d_blur_z = -ds * u * sb.ds_along_z * (1 - hole_value);
  if (hole > 0) {
    // dH: w = (h R - rho) / s(m_z), drho/dc = -m, drho/da = -t m,
    // dm_z/dc = -(e_z - a_z a - m_z m) / rho, dm_z/da = -(a_z d + t (e_z - m_z m)) / rho.
    const double dh = hw.pdf / hb.s;
    Eigen::Vector3d dw_dc = m, dw_da = t * m;
    if (rho > 0) {
      dw_dc += w * hb.ds_nz * (ez - axis.z() * axis - m.z() * m) / rho;
      dw_da += w * hb.ds_nz * (axis.z() * d + t * (ez - m.z() * m)) / rho;
    }
    f.d_centre -= sphere * dh * dw_dc;
    f.d_radius -= sphere * dh * hole;
    f.d_blur += sphere * dh * w * hb.ds_across;
    f.d_blur_z += sphere * dh * w * hb.ds_along_z;
    f.d_axis = -sphere * dh * dw_da;
  }
  if (!(blur_z > 0)) {  // one blur, alike in every direction
    f.d_blur += f.d_blur_z;
    f.d_blur_z = 0;
  }
  return f;
}

}  // namespace granmem
