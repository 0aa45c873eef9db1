#include "granmem/tracking/partial_volume.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

namespace granmem {
namespace {

// Volume of {u in [0,1]^3 : m . u <= alpha} for m1 <= m2 <= m3, m1 + m2 + m3 = 1 and
// 0 <= alpha <= 1/2 (Scardovelli & Zaleski, J. Comput. Phys. 164, 2000). Each branch
// divides only by the components it needs, so that m1 (and m2) may be zero.
double corner_volume(double m1, double m2, double m3, double alpha) {
  const double m12 = m1 + m2;
  if (alpha < m1) return alpha * alpha * alpha / (6 * m1 * m2 * m3);
  if (alpha < m2) return alpha * (alpha - m1) / (2 * m2 * m3) + m1 * m1 / (6 * m2 * m3);
  if (alpha < std::min(m12, m3)) {
    return (alpha * alpha * (3 * m12 - alpha) + m1 * m1 * (m1 - 3 * alpha) +
            m2 * m2 * (m2 - 3 * alpha)) /
           (6 * m1 * m2 * m3);
  }
  if (m3 < m12) {
    return (alpha * alpha * (3 - 2 * alpha) + m1 * m1 * (m1 - 3 * alpha) +
            m2 * m2 * (m2 - 3 * alpha) + m3 * m3 * (m3 - 3 * alpha)) /
           (6 * m1 * m2 * m3);
  }
  return (2 * alpha - m12) / (2 * m3);
}

// A unit vector perpendicular to `a`, for a box centred on the axis or the centre (any
// direction is then as good as another).
Eigen::Vector3d any_perpendicular(const Eigen::Vector3d& a) {
  return a.unitOrthogonal();
}

}  // namespace

double unit_cube_fraction_below_plane(const Eigen::Vector3d& m, double d) {
  // The cube is symmetric under u_i -> -u_i, so only |m_i| matters.
  double m1 = std::abs(m.x()), m2 = std::abs(m.y()), m3 = std::abs(m.z());
  const double sum = m1 + m2 + m3;
  if (!(sum > 0)) return d >= 0 ? 1.0 : 0.0;
  m1 /= sum;
  m2 /= sum;
  m3 /= sum;
  if (m1 > m2) std::swap(m1, m2);
  if (m2 > m3) std::swap(m2, m3);
  if (m1 > m2) std::swap(m1, m2);
  // A component this small changes the volume by less than itself; as zero it avoids the
  // cancellation of dividing by it.
  constexpr double kNegligible = 1e-7;
  if (m1 < kNegligible) {
    m3 += m1;
    m1 = 0;
    if (m2 < kNegligible) {
      m3 += m2;
      m2 = 0;
    }
  }
  // Measured from the lowest corner, where m . u = -1/2.
  double alpha = d / sum + 0.5;
  if (alpha <= 0) return 0;
  if (alpha >= 1) return 1;
  const bool upper = alpha > 0.5;  // V(alpha) = 1 - V(1 - alpha): keep alpha <= 1/2
  if (upper) alpha = 1 - alpha;
  const double v = std::clamp(corner_volume(m1, m2, m3, alpha), 0.0, 1.0);
  return upper ? 1 - v : v;
}

namespace {

// Where a box lies against a grain's surfaces, and the box's grain fraction when it is cut
// by them and split no further (the tangent planes at the points nearest its centre).
struct Cut {
  bool empty = false;  // no grain material in the box
  bool full = false;   // the box is all grain material
  double to_sphere = 0, to_hole = 0, r = 0, rho = 0;
  Eigen::Vector3d p, radial;
};

Cut classify(const GrainShape& grain, const Eigen::Vector3d& box_centre, double reach) {
  // Distances to the sphere and to the hole's wall are 1-Lipschitz: a box whose centre is
  // farther than its half-diagonal (`reach`) from a surface lies wholly on one side of it.
  Cut c;
  c.p = box_centre - grain.centre;
  c.r = c.p.norm();
  c.to_sphere = c.r - grain.radius;
  if (c.to_sphere >= reach) {
    c.empty = true;
    return c;
  }
  c.to_hole = reach;  // outside the hole (or no hole)
  if (grain.hole_radius > 0) {
    c.radial = c.p - c.p.dot(grain.axis) * grain.axis;
    c.rho = c.radial.norm();
    c.to_hole = c.rho - grain.hole_radius;
    if (c.to_hole <= -reach) {
      c.empty = true;
      return c;
    }
  }
  c.full = c.to_sphere <= -reach && c.to_hole >= reach;
  return c;
}

double leaf_fraction(const GrainShape& grain, const Cut& c, const Eigen::Vector3d& half_size,
                     double reach) {
  // The box maps to the unit cube by x = box_centre + 2 half_size * u. Boxes crossed by
  // both surfaces (the hole's rims) multiply the two fractions.
  double fraction = 1;
  if (c.to_sphere > -reach) {
    const Eigen::Vector3d n = c.r > 0 ? Eigen::Vector3d(c.p / c.r) : any_perpendicular(grain.axis);
    fraction = unit_cube_fraction_below_plane(2 * half_size.cwiseProduct(n), -c.to_sphere);
  }
  if (c.to_hole < reach) {
    const Eigen::Vector3d e =
        c.rho > 0 ? Eigen::Vector3d(c.radial / c.rho) : any_perpendicular(grain.axis);
    fraction *= unit_cube_fraction_below_plane(-2 * half_size.cwiseProduct(e), c.to_hole);
  }
  return fraction;
}

// Adds to `shares` the trilinear shares of the sub-box of a cell centred at `u` (cell
// coordinates, [0, 1] per axis) with half-side `hu` (the same in every axis: the sub-boxes
// are the cell's dyadic divisions, so u, hu and the weights of a full sub-box are exact).
void add_shares(const GrainShape& grain, const Eigen::Vector3d& lo, const Eigen::Vector3d& size,
                const Eigen::Vector3d& u, double hu, int levels, double* shares) {
  const Eigen::Vector3d half = hu * size;
  const double reach = half.norm();
  const Cut c = classify(grain, lo + u.cwiseProduct(size), reach);
  if (c.empty) return;
  if (!c.full && levels > 0) {
    const double h = 0.5 * hu;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d child(u.x() + ((k & 1) ? h : -h), u.y() + ((k & 2) ? h : -h),
                                  u.z() + ((k & 4) ? h : -h));
      add_shares(grain, lo, size, child, h, levels - 1, shares);
    }
    return;
  }
  // Over a box, a product of linear weights in x, y and z integrates to its value at the
  // box's centre; for a cut box, its material is taken to have its centre there too.
  const double volume = 8 * hu * hu * hu * (c.full ? 1.0 : leaf_fraction(grain, c, half, reach));
  const double wx[2] = {1 - u.x(), u.x()}, wy[2] = {1 - u.y(), u.y()}, wz[2] = {1 - u.z(), u.z()};
  for (int k = 0; k < 8; ++k)
    shares[k] += volume * wx[k & 1] * wy[(k >> 1) & 1] * wz[k >> 2];
}

}  // namespace

double occupied_fraction(const GrainShape& grain, const Eigen::Vector3d& box_centre,
                         const Eigen::Vector3d& half_size, int levels) {
  const double reach = half_size.norm();
  const Cut c = classify(grain, box_centre, reach);
  if (c.empty) return 0;
  if (c.full) return 1;
  if (levels > 0) {
    const Eigen::Vector3d h = 0.5 * half_size;
    double sum = 0;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d child(box_centre.x() + ((k & 1) ? h.x() : -h.x()),
                                  box_centre.y() + ((k & 2) ? h.y() : -h.y()),
                                  box_centre.z() + ((k & 4) ? h.z() : -h.z()));
      sum += occupied_fraction(grain, child, h, levels - 1);
    }
    return sum / 8;
  }
  return leaf_fraction(grain, c, half_size, reach);
}

std::array<double, 8> cell_corner_shares(const GrainShape& grain, const Eigen::Vector3d& lo,
                                         const Eigen::Vector3d& size, int levels) {
  std::array<double, 8> shares{};
  add_shares(grain, lo, size, Eigen::Vector3d::Constant(0.5), 0.5, levels, shares.data());
  return shares;
}

int refinement_levels(const GrainShape& grain, const Eigen::Vector3d& voxel_size, double tolerance,
                      int max_levels) {
  const double allowed = tolerance * voxel_size.minCoeff();
  if (!(grain.radius > 0) || !(allowed > 0)) return max_levels;
  Eigen::Vector3d sides = voxel_size;
  std::sort(sides.data(), sides.data() + 3);
  const auto shift = [&](double scale) {
    const double a1 = sides[1] * scale, a2 = sides[2] * scale;
    double worst = (a1 * a1 + a2 * a2) / (24 * grain.radius);  // the sphere
    if (grain.hole_radius > 0) worst = std::max(worst, a2 * a2 / (24 * grain.hole_radius));
    return worst;
  };
  int levels = 0;
  double scale = 1;
  while (levels < max_levels && shift(scale) > allowed) {
    scale /= 2;
    ++levels;
  }
  return levels;
}

}  // namespace granmem
