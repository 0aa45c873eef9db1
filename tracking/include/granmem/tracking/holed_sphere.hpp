#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

namespace granmem {

// The image of a grain: a sphere of radius R with a cylindrical hole of radius h R along
// its unit axis a, through its centre c, seen through a Gaussian blur of width s_xy across
// the slices (x, y) and s_z along z (the sheet's thickness and the slices' spacing). The
// "grain fraction" at point p (physical coordinates) is
//   M(p) = S(p) (1 - H(p)),  S = Phi((R - |p - c|) / s(n)),  H = Phi((h R - rho) / s(m)),
// rho the distance of p from the axis line, Phi the normal CDF, n and m the unit normals
// of the sphere and the hole's wall at p (from the centre, from the axis) and
// s(n)^2 = s_xy^2 (1 - n_z^2) + s_z^2 n_z^2 the blur across a surface of normal n: the
// exact image of a plane blurred by that Gaussian, up to the surface's curvature (a
// partial-volume box filter adds voxel^2/12 to each s^2). Why both: a scan's slices are
// often coarser than its pixels and the sheet thicker than the camera's blur, and a model
// blurred alike in every direction, fitted to such a scan, pulls the grains at a
// packing's edges inward by a tenth of a voxel and more (its neighbours, modelled with
// the same wrong blur, are on one side only). A normalised scan reads b - (b - g) M(p)
// (b the fluid level, g the grain level).
struct HoledSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 1;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double hole = 0.3;  // hole radius over grain radius; 0: no hole
  double blur = 0.5;  // s_xy, same unit as the radius
  double blur_z = 0;  // s_z; 0: as blur

  double along_z() const { return blur_z > 0 ? blur_z : blur; }
  // The widest of the two blurs: how far the image reaches beyond the radius.
  double widest_blur() const { return std::max(blur, along_z()); }

  // M and its derivatives with respect to centre, radius, the two blurs and axis (the axis
  // derivative is the full 3-vector gradient; callers project it on their parameters).
  struct Fraction {
    double value = 0;
    Eigen::Vector3d d_centre = Eigen::Vector3d::Zero();
    double d_radius = 0, d_blur = 0, d_blur_z = 0;
    Eigen::Vector3d d_axis = Eigen::Vector3d::Zero();
  };
  Fraction fraction(const Eigen::Vector3d& p, bool derivatives) const;
  // M alone.
  double value(const Eigen::Vector3d& p) const { return fraction(p, false).value; }
};

// The normal CDF Phi(u) and density phi(u) together, from one exponential: Phi by
// Abramowitz & Stegun 7.1.26 (|error| < 1e-7, far below any scan's noise), a few times
// cheaper than erfc; the model is evaluated some 10^9 times per scan.
struct NormalCdfPdf {
  double cdf, pdf;
};
inline NormalCdfPdf normal_cdf_pdf(double u) {
  const double e = std::exp(-0.5 * u * u);
  const double t = 1 / (1 + 0.3275911 * M_SQRT1_2 * std::abs(u));
  const double lower_tail =  // Phi(-|u|) = erfc(|u| / sqrt 2) / 2
      0.5 * e * t *
      (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  return {u >= 0 ? 1 - lower_tail : lower_tail, 0.3989422804014327 * e};
}

}  // namespace granmem
