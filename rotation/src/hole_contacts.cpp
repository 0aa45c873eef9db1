#include "granmem/rotation/hole_contacts.hpp"

#include <algorithm>
#include <cmath>

#include "granmem/core/error.hpp"
#include "granmem/core/point_index.hpp"

namespace granmem {

std::vector<std::uint8_t> hole_contacts(const Vectors3& centre, const std::vector<double>& radius,
                                        const Vectors3& axis, const HoleContactOptions& o) {
  const auto n = std::size_t(centre.rows());
  if (radius.size() != n || std::size_t(axis.rows()) != n) {
    throw Error("hole contacts: centres, radii and axes differ in number");
  }
  if (!(o.hole_fraction > 0 && o.hole_fraction < 1) || !(o.gap >= 0)) {
    throw Error("hole contacts: the hole fraction must lie in (0, 1) and the gap be >= 0");
  }
  std::vector<std::uint8_t> flag(n, 0);
  if (n == 0) return flag;
  const double largest = *std::max_element(radius.begin(), radius.end());
  const double cos_mouth = std::sqrt(1 - o.hole_fraction * o.hole_fraction);
  const PointIndex index(centre);
  PointIndex::Hits hits;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d a = axis.row(Eigen::Index(i)).transpose();
    if (!a.allFinite() || a.norm() == 0) continue;
    const Eigen::Vector3d c = centre.row(Eigen::Index(i)).transpose();
    index.within(c, (radius[i] + largest) * (1 + o.gap), hits);
    for (const auto& [j, d2] : hits) {
      if (j == i) continue;
      const double touching = (radius[i] + radius[j]) * (1 + o.gap);
      if (d2 >= touching * touching) continue;
      const Eigen::Vector3d towards = centre.row(Eigen::Index(j)).transpose() - c;
      if (std::abs(towards.dot(a)) >= cos_mouth * towards.norm() * a.norm()) {
        flag[i] = 1;
        break;
      }
    }
  }
  return flag;
}

}  // namespace granmem
