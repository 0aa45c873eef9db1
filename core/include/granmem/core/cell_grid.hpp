#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <unordered_map>
#include <vector>

namespace granmem {

// Points binned in cells of a fixed size (one per axis), to visit those near a point:
// for sets that grow while they are searched (kd-trees, PointIndex, are built once).
class CellGrid {
 public:
  explicit CellGrid(const Eigen::Vector3d& cell) : cell_(cell) {}
  explicit CellGrid(double cell) : cell_(Eigen::Vector3d::Constant(cell)) {}
  // Every point of `points`, its index its id.
  CellGrid(const std::vector<Eigen::Vector3d>& points, double cell) : CellGrid(cell) {
    for (std::size_t i = 0; i < points.size(); ++i)
      insert(points[i], i);
  }

  void insert(const Eigen::Vector3d& p, std::size_t id) { cells_[key(index(p))].push_back(id); }

  // Calls visit(id) for the points in the cells within `reach` cells of p's, along each axis
  // (so every point closer to p than `reach` cells, and some further); stops early when
  // visit returns false (a void visit never stops).
  template <class Visit>
  void near(const Eigen::Vector3d& p, int reach, Visit&& visit) const {
    const Eigen::Vector3i c = index(p);
    for (int dz = -reach; dz <= reach; ++dz)
      for (int dy = -reach; dy <= reach; ++dy)
        for (int dx = -reach; dx <= reach; ++dx) {
          const auto it = cells_.find(key(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == cells_.end()) continue;
          for (std::size_t id : it->second) {
            if constexpr (std::is_same_v<decltype(visit(id)), bool>) {
              if (!visit(id)) return;
            } else {
              visit(id);
            }
          }
        }
  }

 private:
  Eigen::Vector3i index(const Eigen::Vector3d& p) const {
    return p.cwiseQuotient(cell_).array().floor().cast<int>();
  }
  static std::int64_t key(const Eigen::Vector3i& c) {
    return (std::int64_t(c.z()) * 100003 + c.y()) * 100019 + c.x();
  }
  Eigen::Vector3d cell_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
};

}  // namespace granmem
