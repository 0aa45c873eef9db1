#include "granmem/tracking/hole_axis.hpp"

#include <ceres/jet.h>
#include <ceres/tiny_solver.h>
#include <ceres/tiny_solver_autodiff_function.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <vector>

#include "blurred_disk.hpp"
#include "fit_covariance.hpp"

#include "granmem/tracking/illumination.hpp"

namespace granmem {
namespace {

// Quadrature rules by Golub-Welsch: Gauss-Legendre on [-1, 1] (weights sum 2) or
// Gauss-Hermite for a unit normal (weights sum 1).
struct Rule {
  std::vector<double> x, w;
};
Rule golub_welsch(int n, bool hermite) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k < n; ++k)
    J(k, k - 1) = J(k - 1, k) = hermite ? std::sqrt(double(k)) : k / std::sqrt(4.0 * k * k - 1);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(J);
  Rule r;
  for (int k = 0; k < n; ++k) {
    r.x.push_back(eig.eigenvalues()[k]);
    r.w.push_back((hermite ? 1.0 : 2.0) * std::pow(eig.eigenvectors()(0, k), 2));
  }
  return r;
}
// The exact image's rules: 8 Gauss-Legendre nodes along the axis within 4 widths (a
// noiseless grain's axis within 0.04 deg of the 12-node rule within 6), 7 Gauss-Hermite
// nodes across (5 tilt axes across z by 0.6 deg).
struct Rules {
  int n = 8, k = 7;
  Rule legendre = golub_welsch(8, false), hermite = golub_welsch(7, true);
  double reach = 4;
};
const Rules& rules() {
  static const Rules r;
  return r;
}
// The annulus' cross-section at one axial offset, blurred: the Gauss-Hermite average over
// the excess blur of the outer disk's blurred fraction less the hole's, at offset (p1, q2)
// across the axis (p1 along u), radii and offsets in widths `iso` (out_iso, rh_iso already
// so); the excess along u when `u_wider`, across it otherwise.
double annulus(double p1, double q2, double excess, double iso, double out_iso, double rh_iso,
               bool u_wider) {
  const Rules& q = rules();
  const BlurredDisk outer_disk(out_iso), hole_disk(rh_iso);
  double f = 0;
  for (int g = 0; g < q.k; ++g) {
    const double e = excess * q.hermite.x[std::size_t(g)];
    const double x1 = u_wider ? p1 + e : p1, x2 = u_wider ? q2 : q2 + e;
    const double rr = std::sqrt(x1 * x1 + x2 * x2 + 1e-24) / iso;
    f += q.hermite.w[std::size_t(g)] * (outer_disk.at(rr).value - hole_disk.at(rr).value);
  }
  return f;
}
// With Jets: the same sum in plain numbers with its partial derivatives in the six inputs,
// carried to the Jet once, not through each node's arithmetic (56 of these per voxel; the
// Jets' own share of locate's profile 13 -> 6 %).
template <int N>
ceres::Jet<double, N> annulus(const ceres::Jet<double, N>& p1, const ceres::Jet<double, N>& q2,
                              const ceres::Jet<double, N>& excess, const ceres::Jet<double, N>& iso,
                              const ceres::Jet<double, N>& out_iso,
                              const ceres::Jet<double, N>& rh_iso, bool u_wider) {
  const Rules& q = rules();
  const BlurredDisk outer_disk(out_iso.a), hole_disk(rh_iso.a);
  double f = 0, d_p1 = 0, d_q2 = 0, d_excess = 0, d_iso = 0, d_out = 0, d_rh = 0;
  for (int g = 0; g < q.k; ++g) {
    const double node = q.hermite.x[std::size_t(g)], weight = q.hermite.w[std::size_t(g)];
    const double e = excess.a * node;
    const double x1 = u_wider ? p1.a + e : p1.a, x2 = u_wider ? q2.a : q2.a + e;
    const double r = std::sqrt(x1 * x1 + x2 * x2 + 1e-24), rr = r / iso.a;
    const DiskFraction outer = outer_disk.at(rr), hole = hole_disk.at(rr);
    f += weight * (outer.value - hole.value);
    const double d_rr = weight * (outer.d_x - hole.d_x) / (r * iso.a);  // times d r
    d_p1 += d_rr * x1;
    d_q2 += d_rr * x2;
    d_excess += d_rr * (u_wider ? x1 : x2) * node;
    d_iso -= d_rr * r * rr;
    d_out += weight * outer.d_y;
    d_rh -= weight * hole.d_y;
  }
  return ceres::Jet<double, N>(f, d_p1 * p1.v + d_q2 * q2.v + d_excess * excess.v + d_iso * iso.v +
                                      d_out * out_iso.v + d_rh * rh_iso.v);
}

// sqrt(v + tiny): the same number for plain numbers, a finite slope for Jets at 0.
template <class T>
T soft_sqrt(const T& v) {
  using std::sqrt;
  return sqrt(v + T(1e-24));
}

// The image of a holed sphere (radius R, hole radius h R along unit axis a) through a
// Gaussian blur of width `across` in x and y and `along_z` in z, exactly (to quadrature):
// in the axis' frame the blur's offset along the axis is N(0, s_t^2), and given it, its
// part across the axis is Gaussian with mean (shift xi) u and covariance diag(v_u, v_w), u
// the direction across the axis nearest z. A point's offset image lies in the grain where
// its cross-section at axial position tau (an annulus h R <= rho <= sqrt(R^2 - tau^2),
// empty beyond the mouths |tau| > sqrt(R^2 - h^2 R^2)) holds it: the blurred disk of the
// outer radius less that of the hole's, each a disk blurred by that covariance (the
// isotropic part by the disk's table, the excess by Gauss-Hermite), integrated over the
// axial offset by Gauss-Legendre between the mouths. Set up once per parameter vector;
// with Jets (T), its exact derivatives, the refit's Jacobian.
template <class T>
struct BlurredGrain {
  using V = Eigen::Matrix<T, 3, 1>;
  V a, u, w;
  T across, along_z, sigma_t, shift, iso, excess, R, rh, mouth, rh_iso;
  bool u_wider = false;

  BlurredGrain(const V& axis, const T& across_, const T& along_z_, const T& radius, double hole)
      : a(axis), across(across_), along_z(along_z_) {
    const T D = along_z * along_z - across * across;
    V up = V(T(0), T(0), T(1)) - a.z() * a;
    // Along z: any direction across (the blur is then alike all around the axis).
    if (up.squaredNorm() < T(1e-12)) up = V(T(1), T(0), T(0)) - a.x() * a;
    u = up / soft_sqrt(up.squaredNorm());
    w = a.cross(u);
    const T c = soft_sqrt(T(1) - a.z() * a.z());
    const T stt = across * across + D * a.z() * a.z();
    sigma_t = soft_sqrt(stt);
    shift = D * a.z() * c / sigma_t;
    const T vu = across * across * along_z * along_z / stt, vw = across * across;
    u_wider = vu > vw;
    iso = soft_sqrt(u_wider ? vw : vu);
    excess = soft_sqrt(u_wider ? vu - vw : vw - vu);
    R = radius;
    rh = hole * radius;
    mouth = soft_sqrt(R * R - rh * rh);
    rh_iso = rh / iso;
  }

  // The grain fraction at offset d from the centre.
  T value(const Eigen::Vector3d& offset) const {
    using std::exp;
    const Rules& q = rules();
    const V d = offset.cast<T>();
    const T t = d.dot(a);
    const V across_axis = d - t * a;
    const T q1 = across_axis.dot(u), q2 = across_axis.dot(w);
    T lo = (-mouth - t) / sigma_t, hi = (mouth - t) / sigma_t;
    if (lo < T(-q.reach)) lo = T(-q.reach);
    if (hi > T(q.reach)) hi = T(q.reach);
    T m = T(0);
    if (!(lo < hi)) return m;
    const T mid = T(0.5) * (lo + hi), half = T(0.5) * (hi - lo);
    for (int i = 0; i < q.n; ++i) {
      const T xi = mid + half * q.legendre.x[std::size_t(i)];
      const T weight =
          half * q.legendre.w[std::size_t(i)] * 0.3989422804014327 * exp(T(-0.5) * xi * xi);
      const T tau = t + sigma_t * xi;
      T outer2 = R * R - tau * tau;
      if (outer2 < rh * rh) outer2 = rh * rh;
      const T out_iso = soft_sqrt(outer2) / iso;
      const T p1 = q1 + shift * xi;
      m += weight * annulus(p1, q2, excess, iso, out_iso, rh_iso, u_wider);
    }
    return m;
  }
};

// The fit's parameters: log blur across (x, y), log blur along z, fluid and grain levels,
// two tangent coordinates of the axis around axis0, the radius' relative change; in
// Parameters, as they are.
struct Parameters {
  Eigen::Vector3d axis;
  double across, along_z, fluid, grain, radius;
};

// The grain's inner voxels as the exact image (BlurredGrain) sees them, with its own
// Jacobian (Jets). The Jacobian of a cheaper model (the ball blurred exactly times an
// infinite cylinder) converged linearly, in ~14 Levenberg-Marquardt iterations, to where
// that Jacobian, not the exact one, was orthogonal to the residuals; this one takes ~10
// from the model fit and ~5 from a sample's blurs and radius (locate). The neighbours add
// their grain fractions (the blur is linear and the grains do not overlap; a product,
// 1 - (1 - M) clear, tilted axes by a degree where the blur along z is wide): the scan
// reads b - (b - g) (M + 1 - clear).
struct InnerHoleResiduals {
  const GrainWindow* window;
  Eigen::Vector3d centre, axis0, e1, e2;
  double radius0 = 1, hole = 0.3;

  int NumResiduals() const { return int(window->points.size()); }

  template <class T>
  Eigen::Matrix<T, 3, 1> axis(const T* x) const {
    const Eigen::Matrix<T, 3, 1> raw = axis0.cast<T>() + x[4] * e1.cast<T>() + x[5] * e2.cast<T>();
    return raw / soft_sqrt(raw.squaredNorm());
  }
  Parameters parameters(const double* x) const {
    return {axis(x), std::exp(x[0]), std::exp(x[1]), x[2], x[3], radius0 * (1 + x[6])};
  }

  template <class T>
  bool operator()(const T* x, T* residuals) const {
    using std::exp;
    const BlurredGrain<T> exact(axis(x), exp(x[0]), exp(x[1]), T(radius0) * (T(1) + x[6]), hole);
    const T b = x[2], g = x[3];
    for (std::size_t k = 0; k < window->points.size(); ++k) {
      const double others = window->clear.empty() ? 0.0 : 1 - window->clear[k];
      const T m = exact.value(window->points[k] - centre);
      residuals[k] = b - (b - g) * (m + T(others)) - T(window->intensity[k]);
    }
    return true;
  }
};

}  // namespace

double blurred_grain_fraction(const Eigen::Vector3d& p, const HoledSphere& grain,
                              double blur_across, double blur_along_z) {
  const BlurredGrain<double> model(grain.axis.normalized(), blur_across, blur_along_z, grain.radius,
                                   grain.hole);
  return model.value(p - grain.centre);
}

void add_blurred_grain_fraction(const std::vector<Eigen::Vector3d>& points, double reach,
                                const HoledSphere& grain, double blur_across, double blur_along_z,
                                std::vector<double>& sum) {
  const BlurredGrain<double> model(grain.axis.normalized(), blur_across, blur_along_z, grain.radius,
                                   grain.hole);
  for (std::size_t k = 0; k < points.size(); ++k) {
    if ((points[k] - grain.centre).norm() < reach) sum[k] += model.value(points[k] - grain.centre);
  }
}

HoleAxisFit fit_hole_axis(const GrainWindow& inner, const GrainFit& grain,
                          const HoleAxisOptions& o) {
  HoleAxisFit fit;
  if (int(inner.points.size()) <= 7) return fit;
  InnerHoleResiduals model{&inner,           grain.sphere.centre, {}, {}, {}, grain.sphere.radius,
                           grain.sphere.hole};
  model.axis0 = grain.sphere.axis.normalized();
  Eigen::Matrix<double, 7, 1> x;
  const HoleAxisStart& s = o.start;
  x << std::log(s.blur_across > 0 ? s.blur_across : grain.sphere.blur),
      std::log(s.blur_along_z > 0 ? s.blur_along_z : grain.sphere.along_z()),
      grain.fluid + s.fluid_change, grain.grain + s.grain_change, 0, 0,
      s.radius_change / grain.sphere.radius;
  model.e1 = model.axis0.unitOrthogonal();
  model.e2 = model.axis0.cross(model.e1);
  using Function = ceres::TinySolverAutoDiffFunction<InnerHoleResiduals, Eigen::Dynamic, 7>;
  const Function f(model);
  ceres::TinySolver<Function> solver;
  solver.options.max_num_iterations = o.max_iterations;
  solver.options.parameter_tolerance = 1e-4;
  // Stops once a step lowers the cost by under a thousandth of one voxel's residual
  // variance (the model fit's): the axis is then within ~0.05 of its standard error of the
  // minimum. Below that, the table's kinks kept steps bouncing for ~5 more iterations.
  solver.options.function_tolerance = 2e-3 * grain.rms * grain.rms;
  const auto& summary = solver.Solve(f, &x);
  if (!x.allFinite()) return fit;
  const Parameters p = model.parameters(x.data());
  fit.axis = p.axis;
  fit.blur_across = p.across;
  fit.blur_along_z = p.along_z;
  fit.radius = p.radius;
  fit.fluid = p.fluid;
  fit.grain = p.grain;
  fit.converged = summary.status != ceres::TinySolver<Function>::HIT_MAX_ITERATIONS;
  const Eigen::Vector3d raw = model.axis0 + x[4] * model.e1 + x[5] * model.e2;
  if (fit.converged) fit.sigma = axis_standard_error(f, x, 4, raw.norm());
  return fit;
}

Eigen::Vector3d lab_hole_axis(const Stack& stack, const Eigen::Vector3d& centre, double radius,
                              const Eigen::Vector3d& vs, double within) {
  const double reach = within * radius;
  const Eigen::Array3d last(double(stack.nx - 1), double(stack.ny - 1), double(stack.nz - 1));
  const Eigen::Array3d lo = ((centre.array() - reach) / vs.array()).ceil().max(0.0);
  const Eigen::Array3d hi = ((centre.array() + reach) / vs.array()).floor().min(last);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  int bright = 0;
  for (auto z = std::int64_t(lo.z()); z <= std::int64_t(hi.z()); ++z) {
    for (auto y = std::int64_t(lo.y()); y <= std::int64_t(hi.y()); ++y) {
      for (auto x = std::int64_t(lo.x()); x <= std::int64_t(hi.x()); ++x) {
        const Eigen::Vector3d d =
            Eigen::Vector3d(double(x), double(y), double(z)).cwiseProduct(vs) - centre;
        if (d.norm() > reach || fluid_fraction(stack.at(x, y, z)) < 0.5) continue;
        scatter += d * d.transpose();
        ++bright;
      }
    }
  }
  if (bright < 3) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(2);
}

}  // namespace granmem
