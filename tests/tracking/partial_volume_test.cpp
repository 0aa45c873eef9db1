#include "granmem/tracking/partial_volume.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace granmem {
namespace {

// Inclusion-exclusion over the cube's corners: fine where no component of m is small.
double corner_sum(const Eigen::Vector3d& m, double d) {
  const Eigen::Vector3d a = m.cwiseAbs();
  const double alpha = d + 0.5 * a.sum();
  double v = 0;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1) ? 1 : 0, (k & 2) ? 1 : 0, (k & 4) ? 1 : 0);
    const double t = std::max(0.0, alpha - a.dot(corner));
    v += ((k & 1) ^ ((k >> 1) & 1) ^ ((k >> 2) & 1) ? -1 : 1) * t * t * t;
  }
  return v / (6 * a.x() * a.y() * a.z());
}

TEST(RenderPartialVolume, CubeUnderPlaneIsExact) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> component(0.2, 1.0), sign(-1, 1);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3d m(component(rng) * (sign(rng) < 0 ? -1 : 1), component(rng),
                            -component(rng));
    const double d = 0.6 * m.cwiseAbs().sum() * sign(rng);
    EXPECT_NEAR(unit_cube_fraction_below_plane(m, d), corner_sum(m, d), 1e-12);
    // Complement: the other side of the plane.
    EXPECT_NEAR(unit_cube_fraction_below_plane(m, d) + unit_cube_fraction_below_plane(-m, -d), 1.0,
                1e-12);
  }
  // Planes along the faces and edges, where corner sums divide by zero.
  EXPECT_DOUBLE_EQ(unit_cube_fraction_below_plane({1, 0, 0}, 0.2), 0.7);
  EXPECT_DOUBLE_EQ(unit_cube_fraction_below_plane({0, 0, -2}, 0.2), 0.6);
  EXPECT_NEAR(unit_cube_fraction_below_plane({1, 1, 0}, 0.0), 0.5, 1e-15);
  EXPECT_NEAR(unit_cube_fraction_below_plane({1, 1, 0}, -0.5), 0.125, 1e-15);
  EXPECT_NEAR(unit_cube_fraction_below_plane({1, 1e-9, 0}, 0.25), 0.75, 1e-8);
  EXPECT_EQ(unit_cube_fraction_below_plane({0, 0, 0}, 0.0), 1.0);
  EXPECT_EQ(unit_cube_fraction_below_plane({1, 1, 1}, 1.5), 1.0);
  EXPECT_EQ(unit_cube_fraction_below_plane({1, 1, 1}, -1.5), 0.0);
}

TEST(RenderPartialVolume, FractionsOfAGridAddUpToTheGrainsVolume) {
  // A grid of boxes (anisotropic) covering a holed sphere: their fractions sum to its volume.
  GrainShape grain;
  grain.centre = {0.31, -0.17, 0.42};
  grain.radius = 4.2;
  grain.axis = Eigen::Vector3d(1, 2, 3).normalized();
  grain.hole_radius = 0.3 * grain.radius;
  const Eigen::Vector3d voxel(1.0, 1.0, 1.5);
  const int levels = refinement_levels(grain, voxel, 0.002);
  EXPECT_GE(levels, 1);
  double volume = 0;
  for (int z = -4; z <= 4; ++z) {
    for (int y = -6; y <= 6; ++y) {
      for (int x = -6; x <= 6; ++x) {
        const Eigen::Vector3d at = Eigen::Vector3d(x, y, z).cwiseProduct(voxel);
        volume += occupied_fraction(grain, at, voxel / 2, levels) * voxel.prod();
      }
    }
  }
  const double h2 = grain.radius * grain.radius - grain.hole_radius * grain.hole_radius;
  const double exact = 4.0 / 3 * M_PI * h2 * std::sqrt(h2);  // sphere less its bored hole
  EXPECT_NEAR(volume / exact, 1.0, 2e-3);
}

TEST(RenderPartialVolume, LevelsFollowTheTolerance) {
  GrainShape big{Eigen::Vector3d::Zero(), 20, Eigen::Vector3d::UnitZ(), 0};
  GrainShape holed{Eigen::Vector3d::Zero(), 5, Eigen::Vector3d::UnitZ(), 1.5};
  const Eigen::Vector3d voxel = Eigen::Vector3d::Ones();
  EXPECT_LT(refinement_levels(big, voxel, 0.002), refinement_levels(holed, voxel, 0.002));
  EXPECT_LE(refinement_levels(holed, voxel, 0.002), 2 + 1);
  EXPECT_EQ(refinement_levels(holed, voxel, 1e-12, 4), 4);  // capped
}

TEST(RenderPartialVolume, TentSharesKeepTheVolumeAndTheCentre) {
  // The same holed grain sampled two ways on anisotropic voxels: each voxel its occupied
  // fraction (box), or its corner shares from the eight cells around it (tent). Both keep the
  // volume; only the tent keeps the centre, for every sub-voxel position.
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> offset(-0.5, 0.5), component(-1, 1);
  const Eigen::Vector3d voxel(1.0, 1.0, 1.5);
  double box_worst = 0, tent_worst = 0;
  for (int trial = 0; trial < 6; ++trial) {
    GrainShape grain;
    grain.centre = Eigen::Vector3d(offset(rng), offset(rng), offset(rng)).cwiseProduct(voxel);
    grain.radius = 5;
    grain.axis = Eigen::Vector3d(component(rng), component(rng), component(rng)).normalized();
    grain.hole_radius = 1.5;
    const int levels = refinement_levels(grain, voxel, 0.002);
    const Eigen::Vector3d truth = grain.centre.cwiseQuotient(voxel);
    Eigen::Vector3d box_sum = Eigen::Vector3d::Zero(), tent_sum = Eigen::Vector3d::Zero();
    double box_total = 0, tent_total = 0;
    for (int z = -6; z <= 6; ++z) {
      for (int y = -8; y <= 8; ++y) {
        for (int x = -8; x <= 8; ++x) {
          const Eigen::Vector3d at(x, y, z);
          const double f = occupied_fraction(grain, at.cwiseProduct(voxel), voxel / 2, levels);
          box_sum += f * at;
          box_total += f;
          // The cell from voxel (x, y, z) to (x + 1, y + 1, z + 1).
          const std::array<double, 8> shares =
              cell_corner_shares(grain, at.cwiseProduct(voxel), voxel, levels);
          for (int k = 0; k < 8; ++k) {
            tent_sum += shares[k] * (at + Eigen::Vector3d(k & 1, (k >> 1) & 1, k >> 2));
            tent_total += shares[k];
          }
        }
      }
    }
    EXPECT_NEAR(tent_total / box_total, 1.0, 1e-12);  // the same splitting, shared out
    box_worst = std::max(box_worst, (box_sum / box_total - truth).cwiseAbs().maxCoeff());
    tent_worst = std::max(tent_worst, (tent_sum / tent_total - truth).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(box_worst, 5e-4);  // the box's pixel locking, which the tent removes
  EXPECT_LT(tent_worst, 1e-4);
  // A cell wholly inside: exactly an eighth to each corner.
  const GrainShape big{Eigen::Vector3d::Zero(), 10, Eigen::Vector3d::UnitZ(), 2};
  for (double share : cell_corner_shares(big, Eigen::Vector3d(3, 3, 1.5), voxel, 3)) {
    EXPECT_EQ(share, 0.125);
  }
}

}  // namespace
}  // namespace granmem
