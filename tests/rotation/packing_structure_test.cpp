// The packing's structure from positions: known lattices give their packing fraction and
// coordination number exactly (to the quadrature of the spheres cut by the region).
#include "granmem/rotation/packing_structure.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace granmem {
namespace {

// Grains of radius 0.5 on a lattice of n^3 cells of side `a` with the given basis,
// shifted by `offset`.
Vectors3 lattice(int n, double a, const std::vector<Eigen::Vector3d>& basis,
                 const Eigen::Vector3d& offset) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k)
        for (const Eigen::Vector3d& b : basis)
          p.push_back(offset + a * (Eigen::Vector3d(i, j, k) + b));
  Vectors3 out(Eigen::Index(p.size()), 3);
  for (std::size_t i = 0; i < p.size(); ++i)
    out.row(Eigen::Index(i)) = p[i].transpose();
  return out;
}

TEST(PackingStructure, ASimpleCubicPackingIsPiOverSixWithSixNeighbours) {
  const Vectors3 x = lattice(10, 1.0, {Eigen::Vector3d::Zero()}, {0.3, -2.1, 5});
  const std::vector<double> r(std::size_t(x.rows()), 0.5);
  const PackingStructure s = packing_structure(x, r);
  EXPECT_NEAR(s.packing_fraction, M_PI / 6, 1e-12);  // planes through the centres: halves
  EXPECT_DOUBLE_EQ(s.coordination, 6);
  EXPECT_EQ(s.grains, 6u * 6u * 6u);  // 2 diameters in from each side of 0..9
  // A region of whole cells at any offset cuts spheres anywhere: pi/6 to the quadrature.
  StructureOptions o;
  o.region = Box{Eigen::Vector3d(2.37, -0.14, 7.61), Eigen::Vector3d(4, 5, 3)};
  EXPECT_NEAR(packing_structure(x, r, o).packing_fraction, M_PI / 6, 2e-3);
}

TEST(PackingStructure, FaceCentredCubicIsTheDensestWithTwelveNeighbours) {
  // Spheres of diameter 1 touch along the face diagonals: cell side sqrt(2).
  const std::vector<Eigen::Vector3d> fcc{{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  const Vectors3 x = lattice(9, std::sqrt(2.0), fcc, Eigen::Vector3d::Zero());
  std::vector<double> r(std::size_t(x.rows()), 0.5);
  r[7] = std::nan("");  // an unknown radius is the median's
  StructureOptions o;
  o.region = Box{Eigen::Vector3d(3.1, 2.9, 3.3), Eigen::Vector3d::Constant(4 * std::sqrt(2.0))};
  const PackingStructure s = packing_structure(x, r, o);
  EXPECT_NEAR(s.packing_fraction, M_PI / (3 * std::sqrt(2.0)), 2e-3);
  EXPECT_DOUBLE_EQ(s.coordination, 12);
}

TEST(PackingStructure, NeighboursBeyondTheGapAndUnknownPositionsDoNotCount) {
  // Simple cubic at spacing 1.03: beyond a 2 % gap, within a 5 % one.
  Vectors3 x = lattice(8, 1.03, {Eigen::Vector3d::Zero()}, Eigen::Vector3d::Zero());
  x.row(0).setConstant(std::nan(""));
  const std::vector<double> r(std::size_t(x.rows()), 0.5);
  EXPECT_DOUBLE_EQ(packing_structure(x, r).coordination, 0);
  StructureOptions loose;
  loose.contact_gap = 0.05;
  EXPECT_DOUBLE_EQ(packing_structure(x, r, loose).coordination, 6);
  EXPECT_TRUE(std::isnan(
      packing_structure(x, std::vector<double>(r.size(), std::nan(""))).packing_fraction));
}

// The whole packing from its height: a simple cubic stack of 10 x 10 x 10 unit cells
// filling a 10 x 10 cross-section is pi/6 wherever it sits (no floor to register); a
// grain not located leaves out its volume, 1/N of the fraction; a cubic stack twice as
// tall in a cross-section twice as wide, in the same unit, is the same.
TEST(PackingStructure, TheHeightPackingFractionOfACubicStackIsPiOverSix) {
  Vectors3 x = lattice(10, 1.0, {Eigen::Vector3d::Zero()}, {0.5, 0.5, 31.7});
  const std::vector<double> r(std::size_t(x.rows()), 0.5);
  EXPECT_NEAR(height_packing_fraction(x, r, 100.0), M_PI / 6, 1e-12);
  x.row(17).setConstant(std::nan(""));
  EXPECT_NEAR(height_packing_fraction(x, r, 100.0), M_PI / 6 * 999 / 1000, 1e-12);
  const Vectors3 big = lattice(10, 2.0, {Eigen::Vector3d::Zero()}, {0, 0, 0});
  const std::vector<double> r_big(std::size_t(big.rows()), 1.0);
  EXPECT_NEAR(height_packing_fraction(big, r_big, 400.0), M_PI / 6, 1e-12);
  EXPECT_TRUE(std::isnan(height_packing_fraction(x, r, 0.0)));
}

// The packing's ends are the means over a quarter of a layer (here 25 of the 100 grains a
// layer holds) of the lowest bottoms and the highest tops: one grain located 0.3 d too
// high moves the top by 0.3 / 25, where the highest grain's top would move 0.3 (a scan's
// noise pushes the extreme grains outward).
TEST(PackingStructure, TheHeightIsMeasuredBetweenTheEndLayersNotTheExtremeGrains) {
  Vectors3 x = lattice(10, 1.0, {Eigen::Vector3d::Zero()}, {0.5, 0.5, 31.7});
  const std::vector<double> r(std::size_t(x.rows()), 0.5);
  Eigen::Index highest = 0;
  x.col(2).maxCoeff(&highest);
  x(highest, 2) += 0.3;
  EXPECT_NEAR(height_packing_fraction(x, r, 100.0), M_PI / 6 * 10 / (10 + 0.3 / 25), 1e-12);
  // Smaller than a quarter of a layer: the ends are the extreme grains.
  EXPECT_NEAR(height_packing_fraction(x, r, 2.0), M_PI / 6 * 50 * 10 / (10.3), 1e-12);
}

}  // namespace
}  // namespace granmem
