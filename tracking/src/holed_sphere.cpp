#include "granmem/tracking/holed_sphere.hpp"

#include <cassert>

#include "granmem/core/inline.hpp"

#if defined(__clang__)
// Under the sanitizers clang cannot vectorise the lanes, and says so at every build.
#pragma clang diagnostic ignored "-Wpass-failed"
#endif

namespace granmem {
namespace {

// The blur across a surface whose unit normal has z component nz (s^2 = a^2 (1 - nz^2) +
// z^2 nz^2, from the squares of the blurs across and along z), and its derivatives with
// respect to the two blurs and nz.
struct SurfaceBlur {
  double s, ds_across, ds_along_z, ds_nz;
  GRANMEM_INLINE SurfaceBlur(double across, double along_z, double nz) {
    const double a2 = across * across, z2 = along_z * along_z, nz2 = nz * nz;
    s = std::sqrt(a2 + (z2 - a2) * nz2);
    const double inverse = 1 / s;
    ds_across = across * (1 - nz2) * inverse;
    ds_along_z = along_z * nz2 * inverse;
    ds_nz = (z2 - a2) * nz * inverse;
  }
};

struct Vec {
  double x, y, z;
};
GRANMEM_INLINE double dot(const Vec& a, const Vec& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// M and its derivatives at one point, in plain numbers, for one lane as for one call (the
// derivatives left out by the compiler where unused). A point on the centre (or the axis)
// takes the normal 0 there.
struct FractionAndSlopes {
  double value;
  Vec d_centre;
  double d_radius, d_blur, d_blur_z;
  Vec d_axis;
};

// The sphere's S and its slopes. With p - c = d, r = |d|, n = d / r: u = (R - r) / s(n_z),
// dr/dc = -n, dn_z/dc = -(e_z - n_z n) / r.
GRANMEM_INLINE FractionAndSlopes sphere_term(const HoledSphere& g, const Vec& d) {
  const double r = std::sqrt(dot(d, d));
  const double inverse_r = r > 0 ? 1 / r : 0;
  const Vec n{d.x * inverse_r, d.y * inverse_r, d.z * inverse_r};
  const SurfaceBlur sb(g.blur, g.along_z(), n.z);
  const double u = (g.radius - r) / sb.s;
  const NormalCdfPdf su = normal_cdf_pdf(u);
  const double ds = su.pdf / sb.s;
  const double bend = u * sb.ds_nz * inverse_r;  // n_z's part of du/dc
  FractionAndSlopes f;
  f.value = su.cdf;
  f.d_centre = {ds * (n.x - bend * n.z * n.x), ds * (n.y - bend * n.z * n.y),
                ds * (n.z + bend * (1 - n.z * n.z))};
  f.d_radius = ds;
  f.d_blur = -ds * u * sb.ds_across;
  f.d_blur_z = -ds * u * sb.ds_along_z;
  f.d_axis = {0, 0, 0};
  return f;
}

// S (1 - H) from the sphere's S: the hole's H taken out. With t = d.a, the part of d
// across the axis q = d - t a, rho = |q|, m = q / rho: w = (h R - rho) / s(m_z), drho/dc =
// -m, drho/da = -t m, dm_z/dc = -(e_z - a_z a - m_z m) / rho, dm_z/da = -(a_z d + t (e_z -
// m_z m)) / rho.
GRANMEM_INLINE void take_out_hole(const HoledSphere& g, const Vec& d, FractionAndSlopes& f) {
  const Vec a{g.axis.x(), g.axis.y(), g.axis.z()};
  const double t = dot(d, a);
  const Vec q{d.x - t * a.x, d.y - t * a.y, d.z - t * a.z};
  const double rho = std::sqrt(dot(q, q));
  const double inverse_rho = rho > 0 ? 1 / rho : 0;
  const Vec m{q.x * inverse_rho, q.y * inverse_rho, q.z * inverse_rho};
  const SurfaceBlur hb(g.blur, g.along_z(), m.z);
  const double w = (g.hole * g.radius - rho) / hb.s;
  const NormalCdfPdf hw = normal_cdf_pdf(w);
  const double sphere = f.value, open = 1 - hw.cdf;
  // dS times (1 - H), less S times dH.
  f.value = sphere * open;
  f.d_centre = {f.d_centre.x * open, f.d_centre.y * open, f.d_centre.z * open};
  f.d_radius *= open;
  f.d_blur *= open;
  f.d_blur_z *= open;
  const double dh = sphere * hw.pdf / hb.s;
  const double tilt = w * hb.ds_nz * inverse_rho;  // m_z's part of dw/dc and dw/da
  const Vec ez_across{-a.z * a.x - m.z * m.x, -a.z * a.y - m.z * m.y, 1 - a.z * a.z - m.z * m.z};
  f.d_centre.x -= dh * (m.x + tilt * ez_across.x);
  f.d_centre.y -= dh * (m.y + tilt * ez_across.y);
  f.d_centre.z -= dh * (m.z + tilt * ez_across.z);
  f.d_radius -= dh * g.hole;
  f.d_blur += dh * w * hb.ds_across;
  f.d_blur_z += dh * w * hb.ds_along_z;
  f.d_axis = {-dh * (t * m.x + tilt * (a.z * d.x - t * m.z * m.x)),
              -dh * (t * m.y + tilt * (a.z * d.y - t * m.z * m.y)),
              -dh * (t * m.z + tilt * (a.z * d.z + t * (1 - m.z * m.z)))};
}

template <bool kHole>
GRANMEM_INLINE FractionAndSlopes fraction_at(const HoledSphere& g, const Vec& p) {
  const Vec d{p.x - g.centre.x(), p.y - g.centre.y(), p.z - g.centre.z()};
  FractionAndSlopes f = sphere_term(g, d);
  if constexpr (kHole) take_out_hole(g, d, f);
  if (!(g.blur_z > 0)) {  // one blur, alike in every direction
    f.d_blur += f.d_blur_z;
    f.d_blur_z = 0;
  }
  return f;
}

// Unused outputs (the derivatives of a value-only call) are left out by the compiler.
template <bool kHole, bool kDerivatives>
GRANMEM_INLINE void fill_lanes(const HoledSphere& g, HoledSphere::Lanes& L, int count) {
#pragma omp simd
  for (int l = 0; l < count; ++l) {
    const FractionAndSlopes f =
        fraction_at<kHole>(g, {L.point[0][l], L.point[1][l], L.point[2][l]});
    L.value[l] = f.value;
    if constexpr (kDerivatives) {
      L.d_centre[0][l] = f.d_centre.x;
      L.d_centre[1][l] = f.d_centre.y;
      L.d_centre[2][l] = f.d_centre.z;
      L.d_radius[l] = f.d_radius;
      L.d_blur[l] = f.d_blur;
      L.d_blur_z[l] = f.d_blur_z;
      L.d_axis[0][l] = f.d_axis.x;
      L.d_axis[1][l] = f.d_axis.y;
      L.d_axis[2][l] = f.d_axis.z;
    }
  }
}

}  // namespace

HoledSphere::Fraction HoledSphere::fraction(const Eigen::Vector3d& p, bool derivatives) const {
  const Vec at{p.x(), p.y(), p.z()};
  Fraction out;
  if (!derivatives) {
    out.value = hole > 0 ? fraction_at<true>(*this, at).value : fraction_at<false>(*this, at).value;
    return out;
  }
  const FractionAndSlopes f =
      hole > 0 ? fraction_at<true>(*this, at) : fraction_at<false>(*this, at);
  out.value = f.value;
  out.d_centre = {f.d_centre.x, f.d_centre.y, f.d_centre.z};
  out.d_radius = f.d_radius;
  out.d_blur = f.d_blur;
  out.d_blur_z = f.d_blur_z;
  out.d_axis = {f.d_axis.x, f.d_axis.y, f.d_axis.z};
  return out;
}

GRANMEM_LANE_TARGETS void HoledSphere::fractions(Lanes& lanes, int count, bool derivatives) const {
  assert(count >= 0 && count <= Lanes::kCapacity);
  if (hole > 0) {
    derivatives ? fill_lanes<true, true>(*this, lanes, count)
                : fill_lanes<true, false>(*this, lanes, count);
  } else {
    derivatives ? fill_lanes<false, true>(*this, lanes, count)
                : fill_lanes<false, false>(*this, lanes, count);
  }
}

}  // namespace granmem
