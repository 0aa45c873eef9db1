#include "granmem/core/point_index.hpp"

#include <algorithm>
#include <nanoflann.hpp>

namespace granmem {
namespace {

// nanoflann's view of an N x 3 row-major point set.
struct Cloud {
  const Vectors3* points = nullptr;
  std::size_t kdtree_get_point_count() const { return std::size_t(points->rows()); }
  double kdtree_get_pt(std::size_t i, std::size_t d) const {
    return (*points)(Eigen::Index(i), Eigen::Index(d));
  }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};
using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>,
                                                   Cloud, 3, std::uint32_t>;

}  // namespace

struct PointIndex::Tree {
  Cloud cloud;
  std::unique_ptr<KdTree> kd;
};

PointIndex::PointIndex(Vectors3 points) : points_(std::move(points)) {
  if (points_.rows() == 0) return;
  tree_ = std::make_unique<Tree>();
  tree_->cloud.points = &points_;
  tree_->kd =
      std::make_unique<KdTree>(3, tree_->cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
}

PointIndex::~PointIndex() = default;

void PointIndex::within(const Eigen::Vector3d& q, double radius, Hits& out) const {
  out.clear();
  if (!tree_) return;
  tree_->kd->radiusSearch(q.data(), radius * radius, out, nanoflann::SearchParams(32, 0, true));
}

void PointIndex::nearest(const Eigen::Vector3d& q, std::size_t k, Hits& out) const {
  out.clear();
  if (!tree_) return;
  k = std::min(k, size());
  std::vector<std::uint32_t> index(k);
  std::vector<double> d2(k);
  k = tree_->kd->knnSearch(q.data(), k, index.data(), d2.data());
  for (std::size_t i = 0; i < k; ++i)
    out.emplace_back(index[i], d2[i]);
}

Vectors3 finite_rows(const Vectors3& points) {
  Vectors3 finite(points.rows(), 3);
  Eigen::Index n = 0;
  for (Eigen::Index i = 0; i < points.rows(); ++i)
    if (points.row(i).allFinite()) finite.row(n++) = points.row(i);
  finite.conservativeResize(n, 3);
  return finite;
}

}  // namespace granmem
