#include "granmem/tracking/hole_axis.hpp"

#include <ceres/tiny_solver.h>
#include <ceres/tiny_solver_autodiff_function.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "fit_covariance.hpp"

#include "granmem/tracking/illumination.hpp"

namespace granmem {
namespace {

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
    const bool clear = !window->clear.empty();
    for (int k = 0; k < NumResiduals(); ++k) {
      const Eigen::Vector3d d = window->points[std::size_t(k)] - grain.centre;
      const double r = d.norm();
      const T sphere =
          normal_cdf(T(grain.radius - r) / blur_along(across, along_z, T(r > 0 ? d.z() / r : 0.0)));
      const T t = d.cast<T>().dot(a);
      const Eigen::Matrix<T, 3, 1> q = d.cast<T>() - t * a;  // across the axis
      const T rho = sqrt(q.squaredNorm() + T(1e-24));
      const T hole = normal_cdf((T(grain.hole * grain.radius) - rho) /
                                blur_along(across, along_z, q.z() / rho));
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
