#include "granmem/tracking/hole_axis.hpp"

#include <ceres/jet.h>
#include <ceres/tiny_solver.h>
#include <ceres/tiny_solver_autodiff_function.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

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

// 7-node Gauss-Hermite rule for a unit normal (5 nodes leave a noiseless grain's axis
// tilted 0.8 deg instead of 0.13).
constexpr double kNode[7] = {-3.7504397177257425, -2.3667594107345413, -1.1544053947399682, 0,
                             1.1544053947399682,  2.3667594107345413,  3.7504397177257425};
constexpr double kWeight[7] = {0.0005482688559722184, 0.030757123967586496, 0.2401231786050127,
                               0.45714285714285713,   0.2401231786050127,   0.030757123967586496,
                               0.0005482688559722184};

// The grain's inner voxels as the model sees them. Parameters: log blur across (x, y),
// log blur along z, fluid and grain levels, two tangent coordinates of the axis around
// axis0. Differentiated automatically (Jets).
struct InnerHoleResiduals {
  const GrainWindow* window;
  HoledSphere grain;  // centre, radius, hole fraction held
  Eigen::Vector3d axis0, e1, e2;

  int NumResiduals() const { return int(window->points.size()); }

  template <class T>
  static T normal_cdf(const T& u) {
    using std::erfc;
    return T(0.5) * erfc(-u * T(M_SQRT1_2));
  }
  // The blur along unit direction n (its z part n_z): the Gaussian's width along n.
  template <class T>
  static T blur_along(const T& across, const T& along_z, const T& n_z) {
    using std::sqrt;
    return sqrt(across * across + (along_z * along_z - across * across) * n_z * n_z);
  }

  template <class T>
  bool operator()(const T* x, T* residuals) const {
    using std::exp;
    using std::sqrt;
    const T across = exp(x[0]), along_z = exp(x[1]), b = x[2], g = x[3];
    const Eigen::Matrix<T, 3, 1> raw = axis0.cast<T>() + x[4] * e1.cast<T>() + x[5] * e2.cast<T>();
    const Eigen::Matrix<T, 3, 1> a = raw / sqrt(raw.squaredNorm());
    // The hole's cross-section: a disk blurred by the blur's covariance in the plane
    // across the axis, across^2 I + (along_z^2 - across^2) (1 - a_z^2) u u^T, u the
    // plane's direction nearest z: the isotropic part by the disk's table, the excess
    // along u (or across it, when the blur along z is the smaller) by Gauss-Hermite.
    // The same for every voxel.
    Eigen::Matrix<T, 3, 1> u = Eigen::Matrix<T, 3, 1>(T(0), T(0), T(1)) - a.z() * a;
    u = u / sqrt(u.squaredNorm() + T(1e-18));
    const Eigen::Matrix<T, 3, 1> w = a.cross(u);
    const T v_u = across * across + (along_z * along_z - across * across) * (T(1) - a.z() * a.z());
    const T v_w = across * across;
    const bool wider_along_u = v_u > v_w;
    const T iso = sqrt(wider_along_u ? v_w : v_u);
    const T excess = sqrt((wider_along_u ? v_u - v_w : v_w - v_u) + T(1e-18));
    const T hole_radius = T(grain.hole * grain.radius) / iso;
    const bool clear = !window->clear.empty();
    for (int k = 0; k < NumResiduals(); ++k) {
      const Eigen::Vector3d d = window->points[std::size_t(k)] - grain.centre;
      const double r = d.norm();
      const T sphere =
          normal_cdf(T(grain.radius - r) / blur_along(across, along_z, T(r > 0 ? d.z() / r : 0.0)));
      const T t = d.cast<T>().dot(a);
      const Eigen::Matrix<T, 3, 1> q = d.cast<T>() - t * a;  // across the axis
      const T q1 = q.dot(u), q2 = q.dot(w);
      T hole = T(0);
      for (int g = 0; g < 7; ++g) {
        const T p1 = wider_along_u ? q1 + excess * kNode[g] : q1;
        const T p2 = wider_along_u ? q2 : q2 + excess * kNode[g];
        hole += kWeight[g] * disk_fraction(sqrt(p1 * p1 + p2 * p2 + T(1e-24)) / iso, hole_radius);
      }
      const T m = sphere * (T(1) - hole);
      const double keep = clear ? window->clear[std::size_t(k)] : 1.0;
      const T dark = T(1) - (T(1) - m) * T(keep);
      residuals[k] = b - (b - g) * dark - T(window->intensity[std::size_t(k)]);
    }
    return true;
  }
};

}  // namespace

HoleAxisFit fit_hole_axis(const GrainWindow& inner, const GrainFit& grain,
                          const HoleAxisOptions& o) {
  InnerHoleResiduals model{&inner, grain.sphere, grain.sphere.axis.normalized(), {}, {}};
  model.e1 = model.axis0.unitOrthogonal();
  model.e2 = model.axis0.cross(model.e1);
  using Function = ceres::TinySolverAutoDiffFunction<InnerHoleResiduals, Eigen::Dynamic, 6>;
  const Function f(model);
  Eigen::Matrix<double, 6, 1> x;
  x << std::log(grain.sphere.blur), std::log(grain.sphere.blur), grain.fluid, grain.grain, 0, 0;
  ceres::TinySolver<Function> solver;
  solver.options.max_num_iterations = o.max_iterations;
  solver.options.parameter_tolerance = 1e-4;
  solver.options.function_tolerance = 1e-9;
  HoleAxisFit fit;
  if (int(inner.points.size()) <= 6) return fit;
  const auto& summary = solver.Solve(f, &x);
  if (!x.allFinite()) return fit;
  const Eigen::Vector3d raw = model.axis0 + x[4] * model.e1 + x[5] * model.e2;
  fit.axis = raw.normalized();
  fit.blur_across = std::exp(x[0]);
  fit.blur_along_z = std::exp(x[1]);
  fit.converged = summary.status != ceres::TinySolver<Function>::HIT_MAX_ITERATIONS;
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
