#pragma once

#include <Eigen/Core>
#include <cmath>

namespace granmem {

// The image of a grain: a sphere of radius R with a cylindrical hole of radius h R along
// its unit axis a, through its centre c, seen through a blur of width s. The "grain
// fraction" at point p (physical coordinates) is
//   M(p) = S(p) (1 - H(p)),  S = Phi((R - |p - c|) / s),  H = Phi((h R - rho) / s),
// rho the distance of p from the axis line and Phi the normal CDF: the exact image of a
// sharp sphere blurred by a Gaussian of width s, up to the curvature of the surface (a
// partial-volume box filter adds voxel^2/12 to s^2). A normalised scan reads
// b - (b - g) M(p) (b the fluid level, g the grain level).
struct HoledSphere {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 1;
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double hole = 0.3;  // hole radius over grain radius; 0: no hole
  double blur = 0.5;  // s, same unit as the radius

  // M and its derivatives with respect to centre, radius, blur and axis (the axis
  // derivative is the full 3-vector gradient; callers project it on their parameters).
  struct Fraction {
    double value = 0;
    Eigen::Vector3d d_centre = Eigen::Vector3d::Zero();
    double d_radius = 0, d_blur = 0;
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
