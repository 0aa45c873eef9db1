#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "granmem/core/trajectories.hpp"

namespace granmem {

// The points within a radius of a query, or its k nearest: a kd-tree (nanoflann) over its
// own copy of an N x 3 point set. An empty set answers nothing.
class PointIndex {
 public:
  using Hits = std::vector<std::pair<std::uint32_t, double>>;  // index, squared distance

  explicit PointIndex(Vectors3 points);
  ~PointIndex();
  PointIndex(const PointIndex&) = delete;
  PointIndex& operator=(const PointIndex&) = delete;

  std::size_t size() const { return std::size_t(points_.rows()); }
  const Vectors3& points() const { return points_; }

  // The points within `radius` of q, nearest first.
  void within(const Eigen::Vector3d& q, double radius, Hits& out) const;
  // The k nearest points of q, nearest first.
  void nearest(const Eigen::Vector3d& q, std::size_t k, Hits& out) const;

 private:
  struct Tree;
  Vectors3 points_;
  std::unique_ptr<Tree> tree_;
};

// The rows of `points` whose coordinates are all finite, in order (a scan's grains that
// were located).
Vectors3 finite_rows(const Vectors3& points);

}  // namespace granmem
