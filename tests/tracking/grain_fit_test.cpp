#include "granmem/tracking/grain_fit.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "granmem/rotation/single_axis_rotation.hpp"

namespace granmem {
namespace {

// A grain drawn from the model itself on a unit voxel grid, with white noise of `noise`:
// the model is exact, so the fit's errors are the noise's alone.
GrainWindow model_window(const HoledSphere& g, double noise, std::mt19937& rng) {
  std::normal_distribution<double> gauss(0, noise);
  GrainWindow w;
  const double reach = g.radius + 3 * g.widest_blur() + 0.5;
  for (int z = -10; z <= 10; ++z) {
    for (int y = -10; y <= 10; ++y) {
      for (int x = -10; x <= 10; ++x) {
        const Eigen::Vector3d p = g.centre + Eigen::Vector3d(x, y, z);
        if ((p - g.centre).norm() > reach) continue;
        w.points.push_back(p);
        w.intensity.push_back(1 - g.value(p) + gauss(rng));
      }
    }
  }
  return w;
}

TEST(GrainFit, AxisStandardErrorMatchesTheScatterOverNoise) {
  // Gauss-Newton covariance at the minimum: with white noise and an exact model, the
  // angle between fitted and true axis has mean square sigma_1^2 + sigma_2^2 (the error
  // ellipse's semi-axes), between axis_sigma^2 (its larger one) and twice that.
  HoledSphere truth;
  truth.centre = Eigen::Vector3d(0.31, -0.17, 0.42);
  truth.radius = 6;
  truth.blur = 0.8;
  truth.hole = 0.3;
  truth.axis = Eigen::Vector3d(0.3, -0.5, 0.8).normalized();
  std::mt19937 rng(7);
  double square = 0, sigma = 0;
  const int trials = 200;
  for (int t = 0; t < trials; ++t) {
    const GrainWindow w = model_window(truth, 0.15, rng);
    HoledSphere start = truth;
    start.axis = (truth.axis + Eigen::Vector3d(0.05, 0.03, -0.04)).normalized();
    start.centre += Eigen::Vector3d(0.2, -0.1, 0.1);
    const GrainFit f = fit_grain(w, start);
    ASSERT_TRUE(f.converged);
    ASSERT_TRUE(std::isfinite(f.axis_sigma));
    square += std::pow(single_axis_angle(f.sphere.axis, truth.axis), 2);
    sigma += f.axis_sigma;
  }
  const double rms = std::sqrt(square / trials), mean_sigma = sigma / trials;
  std::cout << "axis error rms " << rms * 180 / M_PI << " deg, mean standard error "
            << mean_sigma * 180 / M_PI << " deg\n";
  // 200 trials: the rms is known to ~5 %.
  EXPECT_GT(rms, 0.85 * mean_sigma);
  EXPECT_LT(rms, 1.15 * std::sqrt(2.0) * mean_sigma);
}

TEST(GrainFit, NoAxisNoStandardError) {
  HoledSphere truth;
  truth.radius = 6;
  truth.blur = 0.8;
  truth.hole = 0;
  std::mt19937 rng(3);
  const GrainFit f = fit_grain(model_window(truth, 0.05, rng), truth);
  EXPECT_TRUE(f.converged);
  EXPECT_TRUE(std::isnan(f.axis_sigma));
}

TEST(GrainFit, TheBlursAcrossAndAlongZAreFittedApart) {
  // A grain seen through a blur twice as wide along z as across (coarse slices, a thick
  // sheet), the fit started from one blur alike everywhere: it finds both, and the centre.
  HoledSphere truth;
  truth.centre = Eigen::Vector3d(0.21, -0.37, 0.12);
  truth.radius = 6;
  truth.hole = 0.3;
  truth.axis = Eigen::Vector3d(0.6, 0.2, 0.7).normalized();
  truth.blur = 0.8;
  truth.blur_z = 1.6;
  std::mt19937 rng(11);
  HoledSphere start = truth;
  start.blur_z = 0;
  start.centre += Eigen::Vector3d(0.3, -0.2, 0.3);
  const GrainFit f = fit_grain(model_window(truth, 0.02, rng), start);
  ASSERT_TRUE(f.converged);
  EXPECT_NEAR(f.sphere.blur, 0.8, 0.02);
  EXPECT_NEAR(f.sphere.blur_z, 1.6, 0.04);
  EXPECT_NEAR(f.sphere.radius, 6, 0.02);
  EXPECT_LT((f.sphere.centre - truth.centre).norm(), 0.01);
}

}  // namespace
}  // namespace granmem
