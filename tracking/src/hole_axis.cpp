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

// The blurred disk's fraction for plain numbers and for Jets (its table's slopes carried).
double disk_fraction(double x, double y) {
  return blurred_disk(x, y).value;
}
template <class T, int N>
ceres::Jet<T, N> disk_fraction(const ceres::Jet<T, N>& x, const ceres::Jet<T, N>& y) {
  const DiskFraction f = blurred_disk(x.a, y.a);
  return ceres::Jet<T, N>(f.value, f.d_x * x.v + f.d_y * y.v);
}

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
// The approximate model's rule for the ball's offset along z.
const Rule& ball_rule() {
  static const Rule r = golub_welsch(6, false);
  return r;
}

double normal_cdf(double u) {
  return 0.5 * std::erfc(-u * M_SQRT1_2);
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
// axial offset by Gauss-Legendre between the mouths. Set up once per parameter vector.
struct BlurredGrain {
  using V = Eigen::Vector3d;
  V a, u, w;
  double across, along_z, sigma_t, shift, iso, excess, R, rh, mouth, rh_iso;
  bool u_wider = false;

  BlurredGrain(const V& axis, double across_, double along_z_, double radius, double hole)
      : a(axis), across(across_), along_z(along_z_) {
    const double D = along_z * along_z - across * across;
    V up = V::UnitZ() - a.z() * a;
    const double c2 = up.squaredNorm();
    if (c2 < 1e-12) up = a.unitOrthogonal();  // along z: any direction across
    u = up.normalized();
    w = a.cross(u);
    const double c = std::sqrt(c2);
    const double stt = across * across + D * a.z() * a.z();
    sigma_t = std::sqrt(stt);
    shift = D * a.z() * c / sigma_t;
    const double vu = across * across * along_z * along_z / stt, vw = across * across;
    u_wider = vu > vw;
    iso = std::sqrt(u_wider ? vw : vu);
    excess = std::sqrt(std::abs(vu - vw));
    R = radius;
    rh = hole * radius;
    mouth = std::sqrt(R * R - rh * rh);
    rh_iso = rh / iso;
  }

  // The grain fraction at offset d from the centre.
  double value(const V& d) const {
    const Rules& q = rules();
    const double t = d.dot(a);
    const V across_axis = d - t * a;
    const double q1 = across_axis.dot(u), q2 = across_axis.dot(w);
    const double lo = std::max(-q.reach, (-mouth - t) / sigma_t);
    const double hi = std::min(q.reach, (mouth - t) / sigma_t);
    double m = 0;
    if (!(lo < hi)) return m;
    const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
    for (int i = 0; i < q.n; ++i) {
      const double xi = mid + half * q.legendre.x[std::size_t(i)];
      const double weight =
          half * q.legendre.w[std::size_t(i)] * 0.3989422804014327 * std::exp(-0.5 * xi * xi);
      const double tau = t + sigma_t * xi;
      const double out_iso = std::sqrt(std::max(R * R - tau * tau, rh * rh)) / iso;
      const double p1 = q1 + shift * xi;
      double f = 0;
      for (int g = 0; g < q.k; ++g) {
        const double e = excess * q.hermite.x[std::size_t(g)];
        const double x1 = u_wider ? p1 + e : p1, x2 = u_wider ? q2 : q2 + e;
        const double rr = std::sqrt(x1 * x1 + x2 * x2) / iso;
        f += q.hermite.w[std::size_t(g)] *
             (blurred_disk(rr, out_iso).value - blurred_disk(rr, rh_iso).value);
      }
      m += weight * f;
    }
    return m;
  }

  // Cheaper, for the neighbours (points outside the grain): the ball exactly (the
  // in-plane disk of radius sqrt(R^2 - z'^2) integrated over the offset z' along z), less
  // the hole's plug as an infinite cylinder (blurred by the covariance across the axis)
  // times its axial extent.
  double outside_value(const V& d) const {
    const Rules& q = rules();
    const double rho = std::hypot(d.x(), d.y()) / across;
    const double lo = std::max(-q.reach, (-R - d.z()) / along_z);
    const double hi = std::min(q.reach, (R - d.z()) / along_z);
    double ball = 0;
    if (lo < hi) {
      const double mid = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
      for (int i = 0; i < q.n; ++i) {
        const double zeta = mid + half * q.legendre.x[std::size_t(i)];
        const double z = d.z() + along_z * zeta;
        ball += half * q.legendre.w[std::size_t(i)] * 0.3989422804014327 *
                std::exp(-0.5 * zeta * zeta) *
                blurred_disk(rho, std::sqrt(std::max(R * R - z * z, 0.0)) / across).value;
      }
    }
    const double t = d.dot(a);
    const V across_axis = d - t * a;
    // The plug's cross-section: blurred by v_u + shift^2 along u, v_w across.
    const double vu = iso * iso + (u_wider ? excess * excess : 0) + shift * shift;
    const double vw = across * across;
    const double iso2 = std::sqrt(std::min(vu, vw)), excess2 = std::sqrt(std::abs(vu - vw));
    const double q1 = across_axis.dot(u), q2 = across_axis.dot(w);
    double cylinder = 0;
    for (int g = 0; g < q.k; ++g) {
      const double e = excess2 * q.hermite.x[std::size_t(g)];
      const double x1 = vu > vw ? q1 + e : q1, x2 = vu > vw ? q2 : q2 + e;
      cylinder +=
          q.hermite.w[std::size_t(g)] * blurred_disk(std::hypot(x1, x2) / iso2, rh / iso2).value;
    }
    // The plug's ends, flat at its mean length.
    const double h2 = (rh / R) * (rh / R);
    const double end = R * 2 / (3 * h2) * (1 - std::pow(1 - h2, 1.5));
    return ball - cylinder * (normal_cdf((end - t) / sigma_t) - normal_cdf((-end - t) / sigma_t));
  }
};

// 7-node Gauss-Hermite rule for a unit normal.
constexpr double kNode[7] = {-3.7504397177257425, -2.3667594107345413, -1.1544053947399682, 0,
                             1.1544053947399682,  2.3667594107345413,  3.7504397177257425};
constexpr double kWeight[7] = {0.0005482688559722184, 0.030757123967586496, 0.2401231786050127,
                               0.45714285714285713,   0.2401231786050127,   0.030757123967586496,
                               0.0005482688559722184};

// The fit's parameters: log blur across (x, y), log blur along z, fluid and grain levels,
// two tangent coordinates of the axis around axis0, the radius' relative change; in
// Parameters, as they are.
struct Parameters {
  Eigen::Vector3d axis;
  double across, along_z, fluid, grain, radius;
};

// The grain's inner voxels as the model sees them. The approximate image M, for the
// Jacobian (Jets): the ball blurred exactly, times 1 - the hole as an infinite cylinder
// whose cross-section is a disk blurred by the covariance across the axis (no mouths, and
// the product, not the difference); the exact image (BlurredGrain) for the residuals. The
// neighbours add their grain fractions (the blur is linear and the grains do not overlap;
// a product, 1 - (1 - M) clear, tilted axes by a degree where the blur along z is wide):
// the scan reads b - (b - g) (M + 1 - clear).
struct InnerHoleResiduals {
  const GrainWindow* window;
  Eigen::Vector3d centre, axis0, e1, e2;
  double radius0 = 1, hole = 0.3;

  int NumResiduals() const { return int(window->points.size()); }

  template <class T>
  Eigen::Matrix<T, 3, 1> axis(const T* x) const {
    using std::sqrt;
    const Eigen::Matrix<T, 3, 1> raw = axis0.cast<T>() + x[4] * e1.cast<T>() + x[5] * e2.cast<T>();
    return raw / sqrt(raw.squaredNorm());
  }
  Parameters parameters(const double* x) const {
    return {axis(x), std::exp(x[0]), std::exp(x[1]), x[2], x[3], radius0 * (1 + x[6])};
  }

  template <class T>
  bool operator()(const T* x, T* residuals) const {
    using std::exp;
    using std::sqrt;
    const T across = exp(x[0]), along_z = exp(x[1]), b = x[2], g = x[3];
    const Eigen::Matrix<T, 3, 1> a = axis(x);
    // The hole's cross-section: a disk blurred by the blur's covariance in the plane
    // across the axis, across^2 I + (along_z^2 - across^2) (1 - a_z^2) u u^T, u the
    // plane's direction nearest z: the isotropic part by the disk's table, the excess
    // along u (or across it, when the blur along z is the smaller) by Gauss-Hermite.
    Eigen::Matrix<T, 3, 1> u = Eigen::Matrix<T, 3, 1>(T(0), T(0), T(1)) - a.z() * a;
    u = u / sqrt(u.squaredNorm() + T(1e-18));
    const Eigen::Matrix<T, 3, 1> w = a.cross(u);
    const T v_u = across * across + (along_z * along_z - across * across) * (T(1) - a.z() * a.z());
    const T v_w = across * across;
    const bool wider_along_u = v_u > v_w;
    const T iso = sqrt(wider_along_u ? v_w : v_u);
    const T excess = sqrt((wider_along_u ? v_u - v_w : v_w - v_u) + T(1e-18));
    const T radius = T(radius0) * (T(1) + x[6]);
    const T hole_radius = T(hole) * radius / iso;
    const bool clear = !window->clear.empty();
    for (int k = 0; k < NumResiduals(); ++k) {
      const Eigen::Vector3d d = window->points[std::size_t(k)] - centre;
      // The ball, exactly: the disk of radius sqrt(R^2 - z'^2) blurred in-plane, over the
      // blur's offset z' along z (Gauss-Legendre within 4 widths).
      const Rule& gl = ball_rule();
      const T rho = T(std::hypot(d.x(), d.y())) / across;
      T lo = (-radius - T(d.z())) / along_z, hi = (radius - T(d.z())) / along_z;
      if (lo < T(-4)) lo = T(-4);
      if (hi > T(4)) hi = T(4);
      T sphere = T(0);
      if (lo < hi) {
        const T mid = T(0.5) * (lo + hi), half = T(0.5) * (hi - lo);
        for (std::size_t i = 0; i < gl.x.size(); ++i) {
          const T zeta = mid + half * gl.x[i];
          const T z = T(d.z()) + along_z * zeta;
          T r2 = radius * radius - z * z;
          if (r2 < T(1e-12)) r2 = T(1e-12);
          sphere += half * gl.w[i] * T(0.3989422804014327) * exp(T(-0.5) * zeta * zeta) *
                    disk_fraction(rho, sqrt(r2) / across);
        }
      }
      const T t = d.cast<T>().dot(a);
      const Eigen::Matrix<T, 3, 1> q = d.cast<T>() - t * a;  // across the axis
      const T q1 = q.dot(u), q2 = q.dot(w);
      T hole_value = T(0);
      for (int n = 0; n < 7; ++n) {
        const T p1 = wider_along_u ? q1 + excess * kNode[n] : q1;
        const T p2 = wider_along_u ? q2 : q2 + excess * kNode[n];
        hole_value +=
            kWeight[n] * disk_fraction(sqrt(p1 * p1 + p2 * p2 + T(1e-24)) / iso, hole_radius);
      }
      const T m = sphere * (T(1) - hole_value);
      const double others = clear ? 1 - window->clear[std::size_t(k)] : 0.0;
      residuals[k] = b - (b - g) * (m + T(others)) - T(window->intensity[std::size_t(k)]);
    }
    return true;
  }

  // The exact model's residuals at x.
  void exact_residuals(const double* x, double* r) const {
    const Parameters p = parameters(x);
    const BlurredGrain exact(p.axis, p.across, p.along_z, p.radius, hole);
    for (std::size_t k = 0; k < window->points.size(); ++k) {
      const double others = window->clear.empty() ? 0.0 : 1 - window->clear[k];
      const double m = exact.value(window->points[k] - centre);
      r[k] = p.fluid - (p.fluid - p.grain) * (m + others) - window->intensity[k];
    }
  }
};

}  // namespace

double blurred_grain_fraction(const Eigen::Vector3d& p, const HoledSphere& grain,
                              double blur_across, double blur_along_z, bool outside) {
  const BlurredGrain model(grain.axis.normalized(), blur_across, blur_along_z, grain.radius,
                           grain.hole);
  return outside ? model.outside_value(p - grain.centre) : model.value(p - grain.centre);
}

// The exact model's residuals with the approximate model's Jacobian (Jets): Gauss-Newton
// steps of the approximate model applied to the exact residuals, which converge where the
// approximate Jacobian is orthogonal to the exact residuals: the exact model's fit, up to
// the Jacobians' difference times the noise.
struct ExactResiduals {
  using Approximate = ceres::TinySolverAutoDiffFunction<InnerHoleResiduals, Eigen::Dynamic, 7>;
  typedef double Scalar;
  enum { NUM_RESIDUALS = Eigen::Dynamic, NUM_PARAMETERS = 7 };
  const InnerHoleResiduals* model;
  const Approximate* approximate;
  int NumResiduals() const { return model->NumResiduals(); }
  bool operator()(const double* x, double* residuals, double* jacobian) const {
    if (jacobian && !(*approximate)(x, residuals, jacobian)) return false;
    model->exact_residuals(x, residuals);
    return true;
  }
};

HoleAxisFit fit_hole_axis(const GrainWindow& inner, const GrainFit& grain,
                          const HoleAxisOptions& o) {
  HoleAxisFit fit;
  if (int(inner.points.size()) <= 7) return fit;
  InnerHoleResiduals model{&inner,           grain.sphere.centre, {}, {}, {}, grain.sphere.radius,
                           grain.sphere.hole};
  model.axis0 = grain.sphere.axis.normalized();
  Eigen::Matrix<double, 7, 1> x;
  x << std::log(grain.sphere.blur), std::log(grain.sphere.blur), grain.fluid, grain.grain, 0, 0, 0;
  model.e1 = model.axis0.unitOrthogonal();
  model.e2 = model.axis0.cross(model.e1);
  const ExactResiduals::Approximate approximate(model);
  const ExactResiduals f{&model, &approximate};
  ceres::TinySolver<ExactResiduals> solver;
  solver.options.max_num_iterations = o.max_iterations;
  solver.options.parameter_tolerance = 1e-4;
  solver.options.function_tolerance = 1e-9;
  const auto& summary = solver.Solve(f, &x);
  if (!x.allFinite()) return fit;
  const Parameters p = model.parameters(x.data());
  fit.axis = p.axis;
  fit.blur_across = p.across;
  fit.blur_along_z = p.along_z;
  fit.radius = p.radius;
  fit.fluid = p.fluid;
  fit.grain = p.grain;
  fit.converged = summary.status != ceres::TinySolver<ExactResiduals>::HIT_MAX_ITERATIONS;
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
