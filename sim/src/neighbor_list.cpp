#include "granmem/sim/neighbor_list.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>

#include "granmem/core/error.hpp"

namespace granmem {

void NeighborList::build(const Grains& g) {
  const std::size_t n = g.size();
  built_at_ = g.x;
  offset_.assign(n + 1, 0);
  partner_.clear();
  owner_.clear();
  incoming_offset_.assign(n + 1, 0);
  incoming_.clear();
  if (n == 0) return;

  // Cell grid over the grains' bounding box, cells at least one interaction range wide.
  Eigen::Vector3d lo = g.x[0], hi = g.x[0];
  double r_max = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // A grain thrown out of the packing (a step too long for its contacts) has no cell.
    if (!g.x[i].allFinite()) {
      throw Error("neighbour list: grain " + std::to_string(g.id[i]) +
                  " has no finite position (a time step too long for the contacts?)");
    }
    lo = lo.cwiseMin(g.x[i]);
    hi = hi.cwiseMax(g.x[i]);
    r_max = std::max(r_max, g.radius[i]);
  }
  const double range = 2 * r_max + skin_;
  std::array<long, 3> dims{};
  for (int k = 0; k < 3; ++k) {
    dims[k] = std::clamp<long>(static_cast<long>((hi[k] - lo[k]) / range), 1, 1024);
  }
  const Eigen::Vector3d cell_size((hi - lo).array() / Eigen::Array3d(dims[0], dims[1], dims[2]) +
                                  1e-300);
  auto cell_of = [&](const Eigen::Vector3d& x, int k) {
    return std::clamp<long>(static_cast<long>((x[k] - lo[k]) / cell_size[k]), 0, dims[k] - 1);
  };
  const long cells = dims[0] * dims[1] * dims[2];
  std::vector<std::uint32_t> cell_start(static_cast<std::size_t>(cells) + 1, 0), in_cell(n);
  std::vector<std::array<long, 3>> where(n);
  for (std::size_t i = 0; i < n; ++i) {
    where[i] = {cell_of(g.x[i], 0), cell_of(g.x[i], 1), cell_of(g.x[i], 2)};
    ++cell_start[static_cast<std::size_t>((where[i][2] * dims[1] + where[i][1]) * dims[0] +
                                          where[i][0]) +
                 1];
  }
  std::partial_sum(cell_start.begin(), cell_start.end(), cell_start.begin());
  {
    std::vector<std::uint32_t> fill(cell_start.begin(), cell_start.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
      const auto c =
          static_cast<std::size_t>((where[i][2] * dims[1] + where[i][1]) * dims[0] + where[i][0]);
      in_cell[fill[c]++] = static_cast<std::uint32_t>(i);
    }
  }

  // Pairs of each owner: two passes (count, then fill), both in parallel.
  auto visit = [&](std::size_t i, auto&& emit) {
    const auto& c = where[i];
    for (long dz = -1; dz <= 1; ++dz) {
      const long z = c[2] + dz;
      if (z < 0 || z >= dims[2]) continue;
      for (long dy = -1; dy <= 1; ++dy) {
        const long y = c[1] + dy;
        if (y < 0 || y >= dims[1]) continue;
        for (long dx = -1; dx <= 1; ++dx) {
          const long x = c[0] + dx;
          if (x < 0 || x >= dims[0]) continue;
          const auto cell = static_cast<std::size_t>((z * dims[1] + y) * dims[0] + x);
          for (std::uint32_t s = cell_start[cell]; s < cell_start[cell + 1]; ++s) {
            const std::uint32_t j = in_cell[s];
            if (g.id[j] <= g.id[i]) continue;  // the grain of smaller id owns the pair
            const double reach = g.radius[i] + g.radius[j] + skin_;
            if ((g.x[i] - g.x[j]).squaredNorm() < reach * reach) emit(j);
          }
        }
      }
    }
  };
  std::vector<std::uint32_t> count(n, 0);
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads_)
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t c = 0;
    visit(i, [&](std::uint32_t) { ++c; });
    count[i] = c;
  }
  for (std::size_t i = 0; i < n; ++i)
    offset_[i + 1] = offset_[i] + count[i];
  partner_.resize(offset_[n]);
  owner_.resize(offset_[n]);
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads_)
  for (std::size_t i = 0; i < n; ++i) {
    std::uint32_t k = offset_[i];
    visit(i, [&](std::uint32_t j) {
      partner_[k] = j;
      owner_[k++] = static_cast<std::uint32_t>(i);
    });
    std::sort(partner_.begin() + offset_[i], partner_.begin() + offset_[i + 1],
              [&](std::uint32_t a, std::uint32_t b) { return g.id[a] < g.id[b]; });
  }

  // Incoming pairs of each grain, sorted by the owner's id.
  for (std::uint32_t j : partner_)
    ++incoming_offset_[j + 1];
  std::partial_sum(incoming_offset_.begin(), incoming_offset_.end(), incoming_offset_.begin());
  incoming_.resize(partner_.size());
  {
    std::vector<std::uint32_t> fill(incoming_offset_.begin(), incoming_offset_.end() - 1);
    for (std::uint32_t k = 0; k < partner_.size(); ++k)
      incoming_[fill[partner_[k]]++] = k;
  }
#pragma omp parallel for schedule(static) num_threads(threads_)
  for (std::size_t i = 0; i < n; ++i) {
    std::sort(incoming_.begin() + incoming_offset_[i], incoming_.begin() + incoming_offset_[i + 1],
              [&](std::uint32_t a, std::uint32_t b) { return g.id[owner_[a]] < g.id[owner_[b]]; });
  }
}

}  // namespace granmem
