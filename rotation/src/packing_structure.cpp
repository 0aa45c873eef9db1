#include "granmem/rotation/packing_structure.hpp"

#include <algorithm>
#include <cmath>

#include "granmem/core/point_index.hpp"
#include "granmem/core/statistics.hpp"

namespace granmem {
namespace {

// Points filling the unit ball evenly (the centres of a cubic grid's cells inside it):
// the share of them inside a region is the share of a sphere's volume, to ~0.1 % for a
// plane cut, symmetric so that a cut through the centre gives exactly one half.
const std::vector<Eigen::Vector3d>& unit_ball_points() {
  static const std::vector<Eigen::Vector3d> points = [] {
    constexpr int kCells = 24;  // across the diameter
    std::vector<Eigen::Vector3d> p;
    const double h = 2.0 / kCells;
    for (int i = 0; i < kCells; ++i)
      for (int j = 0; j < kCells; ++j)
        for (int k = 0; k < kCells; ++k) {
          const Eigen::Vector3d x(-1 + (i + 0.5) * h, -1 + (j + 0.5) * h, -1 + (k + 0.5) * h);
          if (x.squaredNorm() < 1) p.push_back(x);
        }
    return p;
  }();
  return points;
}

bool inside(const Box& b, const Eigen::Vector3d& x) {
  return (x.array() >= b.lower.array()).all() && (x.array() <= (b.lower + b.edges).array()).all();
}

// The share of the sphere (centre c, radius r) inside the box.
double share_inside(const Box& b, const Eigen::Vector3d& c, double r) {
  const Eigen::Vector3d lo = b.lower, hi = b.lower + b.edges;
  if (((c.array() - r) >= lo.array()).all() && ((c.array() + r) <= hi.array()).all()) return 1;
  if (((c.array() + r) < lo.array()).any() || ((c.array() - r) > hi.array()).any()) return 0;
  const auto& points = unit_ball_points();
  std::size_t in = 0;
  for (const Eigen::Vector3d& p : points)
    in += inside(b, c + r * p);
  return double(in) / double(points.size());
}

// The box of the centres' extent, shrunk by `margin` on every side.
Box inner_region(const std::vector<Eigen::Vector3d>& centre, double margin) {
  Eigen::Vector3d lo = centre.front(), hi = lo;
  for (const Eigen::Vector3d& c : centre) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  Box b;
  b.lower = lo.array() + margin;
  b.edges = ((hi.array() - margin) - b.lower.array()).max(0.0);
  return b;
}

}  // namespace

PackingStructure packing_structure(const Vectors3& position, const std::vector<double>& radius,
                                   const StructureOptions& options) {
  PackingStructure s;
  std::vector<Eigen::Vector3d> centre;
  std::vector<double> r, known;
  for (Eigen::Index i = 0; i < position.rows(); ++i) {
    if (!position.row(i).allFinite()) continue;
    centre.push_back(position.row(i).transpose());
    r.push_back(std::size_t(i) < radius.size() ? radius[std::size_t(i)] : std::nan(""));
    if (std::isfinite(r.back()) && r.back() > 0) known.push_back(r.back());
  }
  if (centre.empty() || known.empty()) return s;
  const double typical = median(known);
  for (double& x : r)
    if (!(std::isfinite(x) && x > 0)) x = typical;

  s.region = options.region ? *options.region : inner_region(centre, options.margin * 2 * typical);
  const double volume = s.region.edges.prod();
  if (!(volume > 0)) return s;

  // Solid volume in the region, and the contacts of the grains centred in it.
  Vectors3 points(Eigen::Index(centre.size()), 3);
  for (std::size_t i = 0; i < centre.size(); ++i)
    points.row(Eigen::Index(i)) = centre[i].transpose();
  const PointIndex index(std::move(points));
  const double r_max = *std::max_element(r.begin(), r.end());
  const double stretch = 1 + options.contact_gap;
  double solid = 0, contacts = 0;
  PointIndex::Hits hits;
  for (std::size_t i = 0; i < centre.size(); ++i) {
    solid += share_inside(s.region, centre[i], r[i]) * 4.0 / 3.0 * M_PI * std::pow(r[i], 3);
    if (!inside(s.region, centre[i])) continue;
    ++s.grains;
    index.within(centre[i], (r[i] + r_max) * stretch, hits);
    for (const auto& [j, d2] : hits) {
      const double reach = (r[i] + r[j]) * stretch;
      if (j != i && d2 < reach * reach) ++contacts;
    }
  }
  s.packing_fraction = solid / volume;
  if (s.grains > 0) s.coordination = contacts / double(s.grains);
  return s;
}

double height_packing_fraction(const Vectors3& position, const std::vector<double>& radius,
                               double cross_section, std::optional<std::size_t> grains) {
  std::vector<double> known;
  for (double r : radius)
    if (std::isfinite(r)) known.push_back(r);
  if (known.empty() || !(cross_section > 0)) return std::nan("");
  const double typical = median(known);
  std::vector<double> bottoms, tops;
  double volume = 0;
  for (Eigen::Index i = 0; i < position.rows() && std::size_t(i) < radius.size(); ++i) {
    if (!position.row(i).allFinite()) continue;
    const double r = std::isfinite(radius[std::size_t(i)]) ? radius[std::size_t(i)] : typical;
    bottoms.push_back(position(i, 2) - r);
    tops.push_back(-(position(i, 2) + r));  // negated: the highest first below
    volume += 4.0 / 3.0 * M_PI * r * r * r;
  }
  if (bottoms.empty()) return std::nan("");
  if (grains) volume *= double(*grains) / double(bottoms.size());
  const double bottom = end_layer_mean(std::move(bottoms), cross_section, typical);
  const double top = -end_layer_mean(std::move(tops), cross_section, typical);
  return top > bottom ? volume / (cross_section * (top - bottom)) : std::nan("");
}

}  // namespace granmem
