#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

#include "granmem/core/inline.hpp"

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

  // M and its derivatives at up to kCapacity points at once, component by component so
  // that the loop over them vectorises (a model fit evaluates M ~10^9 times a scan): the
  // same numbers as fraction() at each point.
  struct Lanes {
    static constexpr int kCapacity = 64;
    double point[3][kCapacity];
    double value[kCapacity];
    double d_centre[3][kCapacity], d_radius[kCapacity], d_blur[kCapacity], d_blur_z[kCapacity];
    double d_axis[3][kCapacity];
    void set_point(int lane, const Eigen::Vector3d& p) {
      for (int a = 0; a < 3; ++a)
        point[a][lane] = p[a];
    }
  };
  // Fills the outputs of lanes 0 to count - 1 (the derivatives only with `derivatives`).
  void fractions(Lanes& lanes, int count, bool derivatives) const;
};

// M of one grain at points given one at a time, evaluated a batch of lanes at a time
// (HoledSphere::fractions): each point's value is handed on, as use(tag, M), in the order
// the points came, at the latest when finish() is called.
template <class Tag, class Use>
class FractionsInTurn {
 public:
  FractionsInTurn(const HoledSphere& grain, Use use) : grain_(grain), use_(std::move(use)) {}
  ~FractionsInTurn() { assert(count_ == 0 && "finish() hands on the last points"); }
  void add(const Eigen::Vector3d& p, Tag tag) {
    lanes_.set_point(count_, p);
    tags_[std::size_t(count_++)] = tag;
    if (count_ == HoledSphere::Lanes::kCapacity) finish();
  }
  void finish() {
    grain_.fractions(lanes_, count_, false);
    for (int l = 0; l < count_; ++l)
      use_(tags_[std::size_t(l)], lanes_.value[l]);
    count_ = 0;
  }

 private:
  const HoledSphere& grain_;
  Use use_;
  HoledSphere::Lanes lanes_;
  std::array<Tag, HoledSphere::Lanes::kCapacity> tags_{};
  int count_ = 0;
};

// e^x without branches or calls, so that loops over it vectorise: x = k ln 2 + r, |r| <=
// ln 2 / 2, e^r by its Taylor series to r^12 (relative error < 5e-16), 2^k from the bits;
// x is held to [-700, 709] (e^-700 ~ 1e-304: nothing the callers tell from 0).
GRANMEM_INLINE double exp_in_lanes(double x) {
  x = std::min(std::max(x, -700.0), 709.0);
  // Adding 1.5 2^52 rounds to an integer held in the low bits of the sum's mantissa.
  constexpr double kShifter = 6755399441055744.0, kLog2e = 1.4426950408889634;
  constexpr double kLn2High = 0.693147180369123816490, kLn2Low = 1.90821492927058770002e-10;
  const double shifted = x * kLog2e + kShifter;
  const double k = shifted - kShifter;
  const double r = (x - k * kLn2High) - k * kLn2Low;
  // Horner's scheme, written out: a loop here would keep the callers' loops from vectorising.
  const double p =
      1 +
      r * (1 + r * (1.0 / 2 +
                    r * (1.0 / 6 +
                         r * (1.0 / 24 +
                              r * (1.0 / 120 +
                                   r * (1.0 / 720 +
                                        r * (1.0 / 5040 +
                                             r * (1.0 / 40320 +
                                                  r * (1.0 / 362880 +
                                                       r * (1.0 / 3628800 +
                                                            r * (1.0 / 39916800 +
                                                                 r * (1.0 / 479001600))))))))))));
  std::uint64_t bits, shifter_bits;
  std::memcpy(&bits, &shifted, sizeof bits);
  std::memcpy(&shifter_bits, &kShifter, sizeof bits);
  bits = (bits - shifter_bits + 1023) << 52;  // the biased exponent of 2^k
  double two_to_k;
  std::memcpy(&two_to_k, &bits, sizeof bits);
  return p * two_to_k;
}

// The normal CDF Phi(u) and density phi(u) together, from one exponential: Phi by
// Abramowitz & Stegun 7.1.26 (|error| < 1e-7, far below any scan's noise), a few times
// cheaper than erfc; the model is evaluated some 10^9 times per scan.
struct NormalCdfPdf {
  double cdf, pdf;
};
GRANMEM_INLINE NormalCdfPdf normal_cdf_pdf(double u) {
  const double e = exp_in_lanes(-0.5 * u * u);
  const double t = 1 / (1 + 0.3275911 * M_SQRT1_2 * std::abs(u));
  const double lower_tail =  // Phi(-|u|) = erfc(|u| / sqrt 2) / 2
      0.5 * e * t *
      (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  return {u >= 0 ? 1 - lower_tail : lower_tail, 0.3989422804014327 * e};
}

}  // namespace granmem
