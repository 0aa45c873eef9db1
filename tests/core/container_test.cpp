#include <gtest/gtest.h>

#include <limits>
#include <random>

#include "granmem/core/trajectories.hpp"

namespace granmem {
namespace {

// Grains of diameter 1 stacked in a 10 x 10 column on the floor of a container whose lower
// corner is at `lower` in the scan's frame: each row touches both walls.
Trajectories column_in_container(const Eigen::Vector3d& lower, double located_radius, double noise,
                                 unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> error(0.0, noise);
  Trajectories run;
  Frame frame;
  frame.position.resize(500, 3);
  Eigen::Index k = 0;
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 10; ++j) {
      for (int l = 0; l < 5; ++l, ++k) {
        frame.position.row(k) = (lower + Eigen::Vector3d(0.5 + i, 0.5 + j, 0.5 + l)).transpose();
        if (noise > 0)
          frame.position.row(k) += Eigen::RowVector3d(error(rng), error(rng), error(rng));
      }
    }
  }
  run.header.radius.assign(500, located_radius);
  run.frames.push_back(frame);
  return run;
}

TEST(ContainerFromExtent, AnExactPackingFindsItsContainer) {
  const Eigen::Vector3d lower(3, -2, 1), edges(10, 10, 12);
  const Box found = container_from_extent(column_in_container(lower, 0.5, 0, 1), edges);
  EXPECT_TRUE(found.lower.isApprox(lower, 1e-12)) << found.lower.transpose();
  EXPECT_EQ(found.edges, edges);
}

// A coarse scan locates radii too small (here by 8 %) and pushes the extreme grains outward
// with its noise: both move the lowest surface, alike on both sides of the container, so
// the extent centred between the walls still finds it across x and y.
TEST(ContainerFromExtent, SmallLocatedRadiiAndNoiseCancelBetweenTheWalls) {
  const Eigen::Vector3d lower(3, -2, 1), edges(10, 10, 12);
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Trajectories scan = column_in_container(lower, 0.42, 0.01, seed);
    const Box found = container_from_extent(scan, edges);
    EXPECT_NEAR(found.lower.x(), lower.x(), 0.01);
    EXPECT_NEAR(found.lower.y(), lower.y(), 0.01);
    // The lowest surface alone would sit ~0.05 (the radii's 0.08 less the noise's reach)
    // inside the wall.
    const double lowest_x = scan.frames[0].position.col(0).minCoeff() - 0.42;
    EXPECT_GT(lowest_x - lower.x(), 0.04);
  }
}

// Along z only the floor is a wall. A scan's noise (here a tenth of a radius, with the
// located radii's own) pushes the lowest grain ~2.5 sigma below the floor, where the
// container used to be registered; the bottom layer's median rests on it, and a stray
// detection a diameter below the floor does not move it.
TEST(ContainerFromExtent, TheFloorIsWhereTheBottomLayerRestsNotItsLowestGrain) {
  const Eigen::Vector3d lower(3, -2, 1), edges(10, 10, 12);
  const double noise = 0.02;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    Trajectories scan = column_in_container(lower, 0.5, noise, seed);
    std::mt19937 rng(seed + 100);
    std::normal_distribution<double> radius_error(0.0, noise);
    for (double& r : scan.header.radius)
      r += radius_error(rng);
    scan.frames[0].position(0, 2) = lower.z() - 0.5;  // the stray: its bottom a diameter down
    const Box found = container_from_extent(scan, edges);
    // The median of 100 bottoms, each off by hypot(noise, noise): ~0.0035 standard error.
    EXPECT_NEAR(found.lower.z(), lower.z(), 0.011) << "seed " << seed;
    double lowest_real = std::numeric_limits<double>::infinity();
    for (Eigen::Index k = 1; k < scan.frames[0].position.rows(); ++k)
      lowest_real =
          std::min(lowest_real, scan.frames[0].position(k, 2) - scan.header.radius[std::size_t(k)]);
    EXPECT_LT(lowest_real - lower.z(), -0.04) << "the lowest surface would be well below";
  }
}

}  // namespace
}  // namespace granmem
