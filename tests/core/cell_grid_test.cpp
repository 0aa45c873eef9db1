#include "granmem/core/cell_grid.hpp"

#include <gtest/gtest.h>

#include <random>
#include <set>

// CellGrid against a brute-force search: every point within `reach` cells of a query (per
// axis) is visited, for isotropic and anisotropic cells and negative coordinates.
namespace granmem {
namespace {

TEST(CellGrid, VisitsEveryPointWithinReachOfTheQuery) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  std::vector<Eigen::Vector3d> points(400);
  for (auto& p : points)
    p = Eigen::Vector3d(u(rng), u(rng), u(rng));
  for (const Eigen::Vector3d cell : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(0.7, 1.2, 2.0)}) {
    CellGrid grid(cell);
    for (std::size_t i = 0; i < points.size(); ++i)
      grid.insert(points[i], i);
    for (int reach : {1, 2}) {
      for (int q = 0; q < 50; ++q) {
        const Eigen::Vector3d x(u(rng), u(rng), u(rng));
        std::set<std::size_t> visited;
        grid.near(x, reach, [&](std::size_t id) { EXPECT_TRUE(visited.insert(id).second); });
        for (std::size_t i = 0; i < points.size(); ++i) {
          const Eigen::Vector3d d = (points[i] - x).cwiseQuotient(cell).cwiseAbs();
          if (d.maxCoeff() < reach) EXPECT_TRUE(visited.count(i)) << i;       // surely in range
          if (d.minCoeff() > reach + 1) EXPECT_FALSE(visited.count(i)) << i;  // surely not
        }
      }
    }
  }
}

TEST(CellGrid, AVisitReturningFalseStopsTheSearch) {
  CellGrid grid(std::vector<Eigen::Vector3d>(10, Eigen::Vector3d(0.5, 0.5, 0.5)), 1.0);
  int calls = 0;
  grid.near(Eigen::Vector3d::Zero(), 1, [&](std::size_t) { return ++calls < 3; });
  EXPECT_EQ(calls, 3);
}

}  // namespace
}  // namespace granmem
