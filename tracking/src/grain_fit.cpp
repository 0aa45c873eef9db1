#include "granmem/tracking/grain_fit.hpp"

#include <ceres/tiny_solver.h>

#include <algorithm>
#include <cmath>

#include "fit_covariance.hpp"

namespace granmem {
namespace {

// Residuals model - data of every voxel, with their Jacobian, for TinySolver. Parameters:
// centre (3, from `origin`: the step tolerance is relative to the parameters, which must
// not depend on where the grain lies in the stack), radius, log blur across the slices (the
// log keeps it positive), fluid level, grain level, log blur along z, and with a hole two
// tangent coordinates of the axis around `axis0` (no pole to trip on).
template <int kParameters>
struct GrainResiduals {
  using Scalar = double;
  enum { NUM_RESIDUALS = Eigen::Dynamic, NUM_PARAMETERS = kParameters };
  static constexpr bool kAxis = kParameters == 10;

  const GrainWindow* window;
  Eigen::Vector3d origin;
  double hole;
  Eigen::Vector3d axis0, e1, e2;

  int NumResiduals() const { return int(window->points.size()); }

  Eigen::Vector3d axis_of(const double* x, Eigen::Vector3d* v = nullptr) const {
    if (!kAxis) return axis0;
    const Eigen::Vector3d raw = axis0 + x[8] * e1 + x[9] * e2;
    if (v) *v = raw;
    return raw.normalized();
  }

  bool operator()(const double* x, double* residuals, double* jacobian) const {
    HoledSphere s;
    s.centre = origin + Eigen::Vector3d(x[0], x[1], x[2]);
    s.radius = x[3];
    s.blur = std::exp(x[4]);
    s.blur_z = std::exp(x[7]);
    s.hole = hole;
    Eigen::Vector3d raw;
    s.axis = axis_of(x, &raw);
    const double b = x[5], g = x[6];
    const int n = NumResiduals();
    const bool clear = !window->clear.empty();
    // d axis / d tangent coordinates: the part of e1, e2 across the axis, over |raw|.
    Eigen::Vector3d da1 = Eigen::Vector3d::Zero(), da2 = Eigen::Vector3d::Zero();
    if (kAxis && jacobian) {
      const double len = raw.norm();
      da1 = (e1 - s.axis * s.axis.dot(e1)) / len;
      da2 = (e2 - s.axis * s.axis.dot(e2)) / len;
    }
    HoledSphere::Lanes lanes;
    for (int first = 0; first < n; first += HoledSphere::Lanes::kCapacity) {
      const int count = std::min(HoledSphere::Lanes::kCapacity, n - first);
      for (int l = 0; l < count; ++l)
        lanes.set_point(l, window->points[std::size_t(first + l)]);
      s.fractions(lanes, count, jacobian != nullptr);
      for (int l = 0; l < count; ++l) {
        const auto k = std::size_t(first + l);
        const double keep = clear ? window->clear[k] : 1.0;
        // Grain, ours or a neighbour's.
        const double dark =
            window->additive ? lanes.value[l] + 1 - keep : 1 - (1 - lanes.value[l]) * keep;
        residuals[k] = b - (b - g) * dark - window->intensity[k];
        if (!jacobian) continue;
        const double scale = -(b - g) * (window->additive ? 1.0 : keep);  // d residual / d M
        auto J = [&](int p) -> double& { return jacobian[std::size_t(p) * std::size_t(n) + k]; };
        J(0) = scale * lanes.d_centre[0][l];
        J(1) = scale * lanes.d_centre[1][l];
        J(2) = scale * lanes.d_centre[2][l];
        J(3) = scale * lanes.d_radius[l];
        J(4) = scale * lanes.d_blur[l] * s.blur;  // d/d log s
        J(5) = 1 - dark;
        J(6) = dark;
        J(7) = scale * lanes.d_blur_z[l] * s.blur_z;
        if (kAxis) {
          const Eigen::Vector3d d_axis(lanes.d_axis[0][l], lanes.d_axis[1][l], lanes.d_axis[2][l]);
          J(8) = scale * d_axis.dot(da1);
          J(9) = scale * d_axis.dot(da2);
        }
      }
    }
    return true;
  }
};

template <int kParameters>
GrainFit solve(const GrainWindow& window, const HoledSphere& start,
               const GrainFitOptions& options) {
  GrainResiduals<kParameters> f{&window, start.centre, start.hole, start.axis.normalized(), {}, {}};
  // Two unit vectors across the starting axis.
  f.e1 = f.axis0.unitOrthogonal();
  f.e2 = f.axis0.cross(f.e1);
  Eigen::Matrix<double, kParameters, 1> x;
  x.setZero();
  x[3] = start.radius;
  x[4] = std::log(start.blur);
  x[5] = 1;  // normalised levels
  x[6] = 0;
  x[7] = std::log(start.along_z());
  ceres::TinySolver<GrainResiduals<kParameters>> solver;
  solver.options.max_num_iterations = options.max_iterations;
  // Steps under 1e-4 x |parameters| (~6e-4 voxel for a 12-voxel grain) change nothing.
  solver.options.parameter_tolerance = 1e-4;
  solver.options.function_tolerance = 1e-9;
  const auto& summary = solver.Solve(f, &x);

  GrainFit fit;
  fit.sphere.centre = start.centre + x.template head<3>();
  fit.sphere.radius = x[3];
  fit.sphere.blur = std::exp(x[4]);
  fit.sphere.blur_z = std::exp(x[7]);
  fit.sphere.hole = start.hole;
  fit.sphere.axis = f.axis_of(x.data());
  fit.fluid = x[5];
  fit.grain = x[6];
  fit.iterations = summary.iterations;
  fit.converged =
      summary.status != ceres::TinySolver<GrainResiduals<kParameters>>::HIT_MAX_ITERATIONS &&
      x.allFinite();
  fit.rms = std::sqrt(2 * summary.final_cost / std::max<double>(1, double(window.points.size())));
  if (!fit.converged || !options.standard_errors) return fit;
  const auto covariance = parameter_covariance(f, x);
  if (!covariance) return fit;
  fit.centre_sigma = covariance->diagonal().template head<3>().cwiseMax(0).cwiseSqrt();
  if constexpr (GrainResiduals<kParameters>::kAxis) {
    fit.axis_sigma =
        axis_standard_error(*covariance, 8, (f.axis0 + x[8] * f.e1 + x[9] * f.e2).norm());
  }
  return fit;
}

}  // namespace

GrainFit fit_grain(const GrainWindow& window, const HoledSphere& start,
                   const GrainFitOptions& options) {
  if (start.hole > 0 && options.fit_axis) return solve<10>(window, start, options);
  return solve<8>(window, start, options);
}

}  // namespace granmem
