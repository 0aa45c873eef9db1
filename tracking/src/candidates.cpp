#include "granmem/tracking/candidates.hpp"

#include <algorithm>
#include <cmath>

#include "granmem/core/cell_grid.hpp"
#include "granmem/core/point_index.hpp"
#include "granmem/tracking/illumination.hpp"

namespace granmem {
namespace {

// A float volume, x fastest.
struct Volume {
  std::int64_t nx = 0, ny = 0, nz = 0;
  std::vector<float> v;
  float& at(std::int64_t x, std::int64_t y, std::int64_t z) {
    return v[std::size_t((z * ny + y) * nx + x)];
  }
  float at(std::int64_t x, std::int64_t y, std::int64_t z) const {
    return v[std::size_t((z * ny + y) * nx + x)];
  }
};

// The mean of `vol` over a ball (an ellipsoid of semi-axes `semi`, in bins) around every
// bin, the part of the ball outside the volume left out: each row of the ball is a
// difference of two prefix sums along x.
Volume ball_mean(const Volume& vol, const Eigen::Array3d& semi) {
  const std::int64_t nx = vol.nx, ny = vol.ny, nz = vol.nz;
  std::vector<double> prefix(std::size_t((nx + 1) * ny * nz));
  const auto row = [&](std::int64_t y, std::int64_t z) {
    return prefix.data() + (z * ny + y) * (nx + 1);
  };
#pragma omp parallel for schedule(static)
  for (std::int64_t z = 0; z < nz; ++z) {
    for (std::int64_t y = 0; y < ny; ++y) {
      double* p = row(y, z);
      p[0] = 0;
      for (std::int64_t x = 0; x < nx; ++x)
        p[x + 1] = p[x] + vol.at(x, y, z);
    }
  }
  // The ball's rows: offsets (dy, dz) and half-lengths along x.
  struct Row {
    int dy, dz, half;
  };
  std::vector<Row> rows;
  const int hz = int(semi.z()), hy = int(semi.y());
  for (int dz = -hz; dz <= hz; ++dz) {
    for (int dy = -hy; dy <= hy; ++dy) {
      const double across = std::pow(dy / semi.y(), 2) + std::pow(dz / semi.z(), 2);
      if (across <= 1) rows.push_back({dy, dz, int(semi.x() * std::sqrt(1 - across))});
    }
  }
  Volume out = vol;
#pragma omp parallel for schedule(static)
  for (std::int64_t z = 0; z < nz; ++z) {
    for (std::int64_t y = 0; y < ny; ++y) {
      for (std::int64_t x = 0; x < nx; ++x) {
        double sum = 0;
        std::int64_t count = 0;
        for (const Row& r : rows) {
          const std::int64_t Y = y + r.dy, Z = z + r.dz;
          if (Y < 0 || Y >= ny || Z < 0 || Z >= nz) continue;
          const std::int64_t lo = std::max<std::int64_t>(0, x - r.half);
          const std::int64_t hi = std::min<std::int64_t>(nx, x + r.half + 1);
          const double* p = row(Y, Z);
          sum += p[hi] - p[lo];
          count += hi - lo;
        }
        out.at(x, y, z) = float(sum / double(count));
      }
    }
  }
  return out;
}

// Bins of b voxels along each axis, b keeping six or more bins per diameter: less memory
// and work, and neighbours still apart.
Eigen::Array3i bin_sizes(const Eigen::Vector3d& diameter) {
  Eigen::Array3i bin;
  for (int k = 0; k < 3; ++k)
    bin[k] = std::clamp(int(std::lround(diameter[k] / 6)), 1, 4);
  return bin;
}

// The grain fraction (1 - fluid fraction, clamped to [0, 1]) averaged over each bin.
Volume binned_grain_fraction(const Stack& stack, const Eigen::Array3i& bin) {
  Volume vol;
  vol.nx = (stack.nx + bin[0] - 1) / bin[0];
  vol.ny = (stack.ny + bin[1] - 1) / bin[1];
  vol.nz = (stack.nz + bin[2] - 1) / bin[2];
  vol.v.assign(std::size_t(vol.nx * vol.ny * vol.nz), 0.f);
#pragma omp parallel for schedule(static)
  for (std::int64_t z = 0; z < vol.nz; ++z) {
    for (std::int64_t y = 0; y < vol.ny; ++y) {
      for (std::int64_t x = 0; x < vol.nx; ++x) {
        double sum = 0;
        int count = 0;
        for (std::int64_t Z = z * bin[2]; Z < std::min(stack.nz, (z + 1) * bin[2]); ++Z) {
          for (std::int64_t Y = y * bin[1]; Y < std::min(stack.ny, (y + 1) * bin[1]); ++Y) {
            for (std::int64_t X = x * bin[0]; X < std::min(stack.nx, (x + 1) * bin[0]); ++X) {
              sum += std::clamp(1.0 - fluid_fraction(stack.at(X, Y, Z)), 0.0, 1.0);
              ++count;
            }
          }
        }
        vol.at(x, y, z) = float(sum / count);
      }
    }
  }
  return vol;
}

// Grains already found taken out of the binned grain fraction (their model, binned alike),
// so that only what they do not explain is left.
void subtract_found(Volume& vol, const Stack& stack, const Eigen::Array3i& bin,
                    const std::vector<HoledSphere>& found, const Eigen::Vector3d& voxel_size) {
  const double per_bin = 1.0 / (bin[0] * bin[1] * bin[2]);
  for (const HoledSphere& g : found) {
    const Eigen::Vector3d c = g.centre.cwiseQuotient(voxel_size);
    const Eigen::Vector3d reach =
        Eigen::Vector3d(g.radius + 3 * g.blur, g.radius + 3 * g.blur, g.radius + 3 * g.along_z())
            .cwiseQuotient(voxel_size);
    const Eigen::Vector3d lo = (c - reach).array().ceil().max(0.0);
    const Eigen::Vector3d hi = (c + reach).array().floor().min(
        Eigen::Array3d(double(stack.nx - 1), double(stack.ny - 1), double(stack.nz - 1)));
    const auto subtract = [per_bin](float* binned, double m) { *binned -= float(per_bin * m); };
    FractionsInTurn<float*, decltype(subtract)> in_turn(g, subtract);
    for (auto Z = std::int64_t(lo.z()); Z <= std::int64_t(hi.z()); ++Z) {
      for (auto Y = std::int64_t(lo.y()); Y <= std::int64_t(hi.y()); ++Y) {
        for (auto X = std::int64_t(lo.x()); X <= std::int64_t(hi.x()); ++X) {
          const Eigen::Vector3d p =
              Eigen::Vector3d(double(X), double(Y), double(Z)).cwiseProduct(voxel_size);
          in_turn.add(p, &vol.at(X / bin[0], Y / bin[1], Z / bin[2]));
        }
      }
    }
    in_turn.finish();
  }
}

struct Peak {
  Eigen::Vector3d x;  // voxel coordinates of the full grid
  float response;
};

// Whether bin (x, y, z) is above each of its 26 neighbours; ties go to the first in memory
// order, so that a plateau gives one peak.
bool is_local_maximum(const Volume& vol, std::int64_t x, std::int64_t y, std::int64_t z) {
  const float c = vol.at(x, y, z);
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (!dx && !dy && !dz) continue;
        const std::int64_t X = x + dx, Y = y + dy, Z = z + dz;
        if (X < 0 || Y < 0 || Z < 0 || X >= vol.nx || Y >= vol.ny || Z >= vol.nz) continue;
        const float n = vol.at(X, Y, Z);
        if (n > c || (n == c && (Z * vol.ny + Y) * vol.nx + X < (z * vol.ny + y) * vol.nx + x)) {
          return false;
        }
      }
    }
  }
  return true;
}

// The maximum at bin (x, y, z) to sub-bin precision: along each axis, the vertex of the
// parabola through it and its two neighbours (within half a bin; none at the border).
Eigen::Vector3d refined_maximum(const Volume& vol, std::int64_t x, std::int64_t y, std::int64_t z) {
  const double c = vol.at(x, y, z);
  Eigen::Vector3d at = Eigen::Vector3d(double(x), double(y), double(z));
  const std::int64_t idx[3] = {x, y, z}, n[3] = {vol.nx, vol.ny, vol.nz};
  for (int k = 0; k < 3; ++k) {
    if (idx[k] == 0 || idx[k] == n[k] - 1) continue;
    std::int64_t lo[3] = {x, y, z}, hi[3] = {x, y, z};
    --lo[k];
    ++hi[k];
    const double m = vol.at(lo[0], lo[1], lo[2]), p = vol.at(hi[0], hi[1], hi[2]);
    const double curvature = m - 2 * c + p;
    if (curvature < 0) at[k] += std::clamp(0.5 * (m - p) / curvature, -0.5, 0.5);
  }
  return at;
}

// The local maxima of at least `min_response`, in the full grid's voxel coordinates (bin
// k covers voxels b k ... b k + b - 1), slice by slice.
std::vector<Peak> peaks_of(const Volume& vol, const Eigen::Array3i& bin, double min_response) {
  const Eigen::Array3d b = bin.cast<double>();
  std::vector<std::vector<Peak>> by_slice(std::size_t(vol.nz));
#pragma omp parallel for schedule(dynamic, 2)
  for (std::int64_t z = 0; z < vol.nz; ++z) {
    for (std::int64_t y = 0; y < vol.ny; ++y) {
      for (std::int64_t x = 0; x < vol.nx; ++x) {
        const float c = vol.at(x, y, z);
        if (c < min_response || !is_local_maximum(vol, x, y, z)) continue;
        const Eigen::Array3d at = refined_maximum(vol, x, y, z).array();
        by_slice[std::size_t(z)].push_back({(b * at + 0.5 * (b - 1)).matrix(), c});
      }
    }
  }
  std::vector<Peak> peaks;
  for (auto& f : by_slice)
    peaks.insert(peaks.end(), f.begin(), f.end());
  return peaks;
}

// Drops the peaks within `reach` diameters (along each axis) of one of `centres` (physical).
void drop_near(std::vector<Peak>& peaks, const std::vector<Eigen::Vector3d>& centres, double reach,
               const Eigen::Vector3d& voxel_size, const Eigen::Vector3d& diameter) {
  if (centres.empty()) return;
  Vectors3 scaled(Eigen::Index(centres.size()), 3);
  for (std::size_t k = 0; k < centres.size(); ++k) {
    scaled.row(Eigen::Index(k)) =
        centres[k].cwiseQuotient(voxel_size).cwiseQuotient(diameter).transpose();
  }
  const PointIndex index(std::move(scaled));
  PointIndex::Hits hits;
  const auto near = [&](const Peak& p) {
    index.within(p.x.cwiseQuotient(diameter), reach, hits);
    return !hits.empty();
  };
  peaks.erase(std::remove_if(peaks.begin(), peaks.end(), near), peaks.end());
}

// The peaks kept strongest first, each at least `separation` (per axis, an ellipsoid) from
// every stronger one kept; a grid of cells one separation wide finds the close ones.
std::vector<Eigen::Vector3d> strongest_apart(std::vector<Peak> peaks,
                                             const Eigen::Vector3d& separation) {
  std::stable_sort(peaks.begin(), peaks.end(),
                   [](const Peak& a, const Peak& b) { return a.response > b.response; });
  CellGrid grid(separation);
  std::vector<Eigen::Vector3d> kept;
  for (const Peak& p : peaks) {
    bool close = false;
    grid.near(p.x, 1, [&](std::size_t k) {
      close = (kept[k] - p.x).cwiseQuotient(separation).squaredNorm() < 1;
      return !close;
    });
    if (close) continue;
    grid.insert(p.x, kept.size());
    kept.push_back(p.x);
  }
  return kept;
}

}  // namespace

std::vector<Eigen::Vector3d> find_candidates(const Stack& stack, const CandidateOptions& o,
                                             const std::vector<HoledSphere>* found,
                                             const Eigen::Vector3d& voxel_size,
                                             const std::vector<Eigen::Vector3d>* tried) {
  const Eigen::Array3i bin = bin_sizes(o.diameter);
  Volume vol = binned_grain_fraction(stack, bin);
  if (found) subtract_found(vol, stack, bin, *found, voxel_size);
  // A ball of 0.8 radius: at a grain's centre it holds only that grain (and its hole, the
  // same share wherever the ball sits on the axis); moved off, it loses grain in proportion
  // and gains a neighbour's only as the square. A Gaussian's tails reach the neighbours in
  // a packing and its weight on the centre feels the hole: its maxima wander.
  vol = ball_mean(vol, 0.4 * o.diameter.array() / bin.cast<double>());
  std::vector<Peak> peaks = peaks_of(vol, bin, o.min_response);
  if (found) {
    std::vector<Eigen::Vector3d> centres;
    for (const HoledSphere& g : *found)
      centres.push_back(g.centre);
    drop_near(peaks, centres, 0.5, voxel_size, o.diameter);
  }
  if (tried) drop_near(peaks, *tried, 0.25, voxel_size, o.diameter);
  return strongest_apart(std::move(peaks), o.min_separation * o.diameter);
}

}  // namespace granmem
