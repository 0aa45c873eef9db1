#include "granmem/tracking/illumination.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/statistics.hpp"

namespace granmem {
namespace {

// Voxels a slice needs of a phase for its level to be measured there.
constexpr std::size_t kMinVoxels = 32;
// Voxels of deep fluid a line needs for its own scale.
constexpr std::size_t kMinLineVoxels = 8;

double median_in_place(std::vector<double>& v) {
  return quantile_in_place(v, 0.5);
}

// Each slice's value replaced by the median over the slices within `reach` of it that
// have one (NaN: none); `fallback` where none of them has.
std::vector<double> pooled_median(const std::vector<double>& per_slice, std::int64_t reach,
                                  const std::vector<double>& fallback) {
  const auto n = std::int64_t(per_slice.size());
  std::vector<double> out(per_slice.size()), window;
  for (std::int64_t z = 0; z < n; ++z) {
    window.clear();
    for (std::int64_t w = std::max<std::int64_t>(0, z - reach); w < std::min(n, z + reach + 1); ++w)
      if (!std::isnan(per_slice[std::size_t(w)])) window.push_back(per_slice[std::size_t(w)]);
    out[std::size_t(z)] = window.empty() ? fallback[std::size_t(z)] : median_in_place(window);
  }
  return out;
}

// A slice's voxels by line along the beam (l) and position along it (s).
struct BeamLayout {
  std::int64_t nx = 0, length = 0, lines = 0;
  int beam_axis = 0;
  BeamLayout(const Stack& stack, int axis)
      : nx(stack.nx),
        length(axis == 0 ? stack.nx : stack.ny),
        lines(axis == 0 ? stack.ny : stack.nx),
        beam_axis(axis) {}
  std::size_t index(std::int64_t l, std::int64_t s) const {
    return std::size_t(beam_axis == 0 ? l * nx + s : s * nx + l);
  }
};

// Each slice's split between fluid and grain, halfway between its fluid level and its
// grain level. The fluid level is the slice's own (a percentile on the fluid's side: the
// light may change from one slice to the next); the grain level is its ratio to the fluid
// level pooled over the slices within `reach`: a slice between two layers of grains, or
// above the packing, is nearly all fluid, and its own grain percentile would sit in the
// fluid. Also that grain level: the dark level where no grain voxel is deep enough to
// measure it.
void fluid_grain_split(const Stack& stack, const IlluminationOptions& o, std::int64_t reach,
                       std::vector<double>* split, std::vector<double>* grain_level) {
  const auto nz = std::size_t(stack.nz);
  std::vector<double> fluid(nz), ratio(nz);
#pragma omp parallel
  {
    std::vector<double> sample;
#pragma omp for schedule(dynamic, 2)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const std::uint16_t* slice = stack.slice(z);
      sample.assign(slice, slice + stack.nx * stack.ny);
      const auto q = [&](double p) { return quantile_in_place(sample, p); };
      const double high = q(o.fluid_percentile), low = q(o.grain_percentile);
      const auto zi = std::size_t(z);
      fluid[zi] = o.dark_grains ? high : low;
      const double grain = o.dark_grains ? low : high;
      ratio[zi] = fluid[zi] > 0 ? grain / fluid[zi] : std::nan("");
    }
  }
  const std::vector<double> pooled = pooled_median(ratio, reach, std::vector<double>(nz, 0.0));
  split->resize(nz);
  grain_level->resize(nz);
  for (std::size_t zi = 0; zi < nz; ++zi) {
    (*grain_level)[zi] = pooled[zi] * fluid[zi];
    (*split)[zi] = 0.5 * (fluid[zi] + (*grain_level)[zi]);
  }
}

// Where each slice holds fluid away from every grain: voxels on the fluid's side of the
// slice's split whose neighbours within two voxels in the slice and one slice either side
// are too. A blurred grain edge reaches under 0.3 % of the contrast that far (PSF sigma
// 0.7 voxel in the slice, 1 across): the levels measured there are the fluid's own,
// whatever grains the packing puts near them.
std::vector<std::vector<std::uint8_t>> deep_fluid(const Stack& stack,
                                                  const std::vector<double>& split, double sign) {
  const std::int64_t nx = stack.nx, ny = stack.ny, reach = 2;
  std::vector<std::vector<std::uint8_t>> in_slice(std::size_t(stack.nz));
#pragma omp parallel
  {
    std::vector<std::uint8_t> fluid, along_x;
#pragma omp for schedule(dynamic, 2)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const std::uint16_t* slice = stack.slice(z);
      fluid.resize(std::size_t(nx * ny));
      for (std::int64_t i = 0; i < nx * ny; ++i)
        fluid[std::size_t(i)] = sign * (double(slice[i]) - split[std::size_t(z)]) > 0;
      // Eroded along x, then along y (a voxel at the slice's border keeps the neighbours
      // it has).
      along_x.assign(fluid.size(), 0);
      for (std::int64_t y = 0; y < ny; ++y)
        for (std::int64_t x = 0; x < nx; ++x) {
          bool all = true;
          for (std::int64_t k = std::max<std::int64_t>(0, x - reach);
               k <= std::min(nx - 1, x + reach) && all; ++k)
            all = fluid[std::size_t(y * nx + k)];
          along_x[std::size_t(y * nx + x)] = all;
        }
      std::vector<std::uint8_t>& out = in_slice[std::size_t(z)];
      out.assign(fluid.size(), 0);
      for (std::int64_t y = 0; y < ny; ++y)
        for (std::int64_t x = 0; x < nx; ++x) {
          bool all = true;
          for (std::int64_t k = std::max<std::int64_t>(0, y - reach);
               k <= std::min(ny - 1, y + reach) && all; ++k)
            all = along_x[std::size_t(k * nx + x)];
          out[std::size_t(y * nx + x)] = all;
        }
    }
  }
  std::vector<std::vector<std::uint8_t>> deep(in_slice.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t z = 0; z < stack.nz; ++z) {
    deep[std::size_t(z)] = in_slice[std::size_t(z)];
    for (std::int64_t w : {z - 1, z + 1}) {
      if (w < 0 || w >= stack.nz) continue;
      for (std::size_t i = 0; i < deep[std::size_t(z)].size(); ++i)
        deep[std::size_t(z)][i] &= in_slice[std::size_t(w)][i];
    }
  }
  return deep;
}

// Each slice's dark level: the median of the voxels well inside grains (a slice through
// the caps of a layer holds mostly the partial volumes of grain surfaces, above the
// grains' level), pooled over the slices within `reach`.
std::vector<double> dark_levels(const Stack& stack, const std::vector<double>& split,
                                const std::vector<double>& fallback, double sign,
                                std::int64_t reach) {
  std::vector<double> grain_median(std::size_t(stack.nz));
#pragma omp parallel
  {
    std::vector<double> grains;
#pragma omp for schedule(dynamic, 2)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const auto zi = std::size_t(z);
      const double deep_grain = split[zi] - 0.5 * (split[zi] - fallback[zi]);
      const std::uint16_t* slice = stack.slice(z);
      grains.clear();
      for (std::int64_t i = 0; i < stack.nx * stack.ny; ++i)
        if (sign * (double(slice[i]) - deep_grain) < 0) grains.push_back(slice[i]);
      grain_median[zi] = grains.size() >= kMinVoxels ? median_in_place(grains) : std::nan("");
    }
  }
  return pooled_median(grain_median, reach, fallback);
}

// The fall-off along the beam: the deep fluid's mean at each position, pooled over the
// slices within `reach` and a diameter along the beam, over its mean (1 where there is
// none). It changes slowly from slice to slice; what changes from one slice or line to
// the next (flicker, streaks) goes into the line scales.
std::vector<std::vector<double>> fall_off(const Stack& stack, const BeamLayout& b,
                                          const std::vector<std::vector<std::uint8_t>>& deep,
                                          std::int64_t reach, std::int64_t half) {
  const auto nz = std::size_t(stack.nz), len = std::size_t(b.length);
  std::vector<std::vector<double>> sum(nz, std::vector<double>(len)),
      count(nz, std::vector<double>(len));
#pragma omp parallel for schedule(dynamic, 2)
  for (std::int64_t z = 0; z < stack.nz; ++z) {
    const auto zi = std::size_t(z);
    const std::uint16_t* slice = stack.slice(z);
    for (std::int64_t l = 0; l < b.lines; ++l)
      for (std::int64_t s = 0; s < b.length; ++s) {
        const std::size_t i = b.index(l, s);
        if (!deep[zi][i]) continue;
        sum[zi][std::size_t(s)] += slice[i];
        count[zi][std::size_t(s)] += 1;
      }
  }
  std::vector<std::vector<double>> shape(nz, std::vector<double>(len, 1.0));
#pragma omp parallel for schedule(static)
  for (std::int64_t z = 0; z < stack.nz; ++z) {
    const auto zi = std::size_t(z);
    const std::int64_t z0 = std::max<std::int64_t>(0, z - reach);
    const std::int64_t z1 = std::min(stack.nz - 1, z + reach);
    double mean = 0, known = 0;
    for (std::int64_t s = 0; s < b.length; ++s) {
      double total = 0, n = 0;
      for (std::int64_t w = z0; w <= z1; ++w)
        for (std::int64_t t = std::max<std::int64_t>(0, s - half);
             t <= std::min(b.length - 1, s + half); ++t) {
          total += sum[std::size_t(w)][std::size_t(t)];
          n += count[std::size_t(w)][std::size_t(t)];
        }
      shape[zi][std::size_t(s)] = n > 0 ? total / n : 0;
      if (n > 0) {
        mean += total / n;
        known += 1;
      }
    }
    mean = known > 0 ? mean / known : 0;
    for (double& v : shape[zi])
      v = mean > 0 && v > 0 ? v / mean : 1.0;
  }
  return shape;
}

// Each line's fluid level over the fall-off (flicker and streaks together): the median of
// its deep fluid voxels; a line with too few of them takes the median of the lines within
// two of it that have them (a streak is a few lines wide), else its slice's. A slice
// without deep fluid takes the slices' within `reach`; `fallback` where none has any.
std::vector<std::vector<double>> line_scales(const Stack& stack, const BeamLayout& b,
                                             const std::vector<std::vector<std::uint8_t>>& deep,
                                             const std::vector<std::vector<double>>& shape,
                                             std::int64_t reach,
                                             const std::vector<double>& fallback) {
  const auto nz = std::size_t(stack.nz), nl = std::size_t(b.lines);
  std::vector<std::vector<double>> own(nz, std::vector<double>(nl, std::nan("")));
  std::vector<double> slice_scale(nz, std::nan(""));
#pragma omp parallel
  {
    std::vector<double> values, known;
#pragma omp for schedule(dynamic, 2)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const auto zi = std::size_t(z);
      const std::uint16_t* slice = stack.slice(z);
      known.clear();
      for (std::int64_t l = 0; l < b.lines; ++l) {
        values.clear();
        for (std::int64_t s = 0; s < b.length; ++s) {
          const std::size_t i = b.index(l, s);
          if (deep[zi][i]) values.push_back(double(slice[i]) / shape[zi][std::size_t(s)]);
        }
        if (values.size() < kMinLineVoxels) continue;
        own[zi][std::size_t(l)] = median_in_place(values);
        known.push_back(own[zi][std::size_t(l)]);
      }
      if (!known.empty()) slice_scale[zi] = median_in_place(known);
    }
  }
  const std::vector<double> slice_level = pooled_median(slice_scale, reach, fallback);
  std::vector<std::vector<double>> scale(nz, std::vector<double>(nl));
#pragma omp parallel
  {
    std::vector<double> near;
#pragma omp for schedule(static)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const auto zi = std::size_t(z);
      const double typical = std::isnan(slice_scale[zi]) ? slice_level[zi] : slice_scale[zi];
      for (std::int64_t l = 0; l < b.lines; ++l) {
        double& out = scale[zi][std::size_t(l)];
        out = own[zi][std::size_t(l)];
        if (!std::isnan(out)) continue;
        near.clear();
        for (std::int64_t k = std::max<std::int64_t>(0, l - 2); k <= std::min(b.lines - 1, l + 2);
             ++k)
          if (!std::isnan(own[zi][std::size_t(k)])) near.push_back(own[zi][std::size_t(k)]);
        out = near.empty() ? typical : median_in_place(near);
      }
    }
  }
  return scale;
}

}  // namespace

void normalize_illumination(Stack& stack, const IlluminationOptions& o) {
  if (!(o.diameter > 0)) throw Error("illumination: the grain diameter must be positive");
  const BeamLayout b(stack, o.beam_axis);
  const double sign = o.dark_grains ? 1 : -1;  // fluid above the grains, or below
  const auto reach = std::int64_t(std::ceil(2 * o.diameter));
  const auto half = std::int64_t(std::ceil(0.5 * o.diameter));

  std::vector<double> split, grain_fallback;
  fluid_grain_split(stack, o, reach, &split, &grain_fallback);
  const std::vector<std::vector<std::uint8_t>> deep = deep_fluid(stack, split, sign);
  const std::vector<double> dark = dark_levels(stack, split, grain_fallback, sign, reach);
  const std::vector<std::vector<double>> shape = fall_off(stack, b, deep, reach, half);
  std::vector<double> fluid_fallback(split.size());
  for (std::size_t zi = 0; zi < split.size(); ++zi)  // the split's far side: the fluid's level
    fluid_fallback[zi] = 2 * split[zi] - grain_fallback[zi];
  const std::vector<std::vector<double>> scale =
      line_scales(stack, b, deep, shape, reach, fluid_fallback);

  // f = (I - dark level) / (line scale x fall-off - dark level), in place.
#pragma omp parallel for schedule(dynamic, 2)
  for (std::int64_t z = 0; z < stack.nz; ++z) {
    const auto zi = std::size_t(z);
    std::uint16_t* slice = stack.slice(z);
    for (std::int64_t l = 0; l < b.lines; ++l)
      for (std::int64_t s = 0; s < b.length; ++s) {
        const double fluid = scale[zi][std::size_t(l)] * shape[zi][std::size_t(s)] - dark[zi];
        std::uint16_t& v = slice[b.index(l, s)];
        const double f = std::abs(fluid) > 1e-12 ? (double(v) - dark[zi]) / fluid : 0.0;
        v = std::uint16_t(std::clamp(kNormalZero + f * kNormalScale, 0.0, 65535.0));
      }
  }
  stack.bits = 16;
}

void normalize_levels(Stack& stack, const IlluminationOptions& o) {
  std::vector<double> sample;
  const std::size_t every = std::max<std::size_t>(1, stack.voxels.size() / 1000000);
  for (std::size_t k = 0; k < stack.voxels.size(); k += every)
    sample.push_back(stack.voxels[k]);
  if (sample.empty()) return;
  const auto at = [&](double q) { return quantile_in_place(sample, q); };
  const double high = at(o.fluid_percentile), low = at(o.grain_percentile);
  const double fluid = o.dark_grains ? high : low, grain = o.dark_grains ? low : high;
  const double span = std::abs(fluid - grain) > 1e-9 ? fluid - grain : 1.0;
#pragma omp parallel for schedule(static)
  for (std::size_t k = 0; k < stack.voxels.size(); ++k) {
    const double f = (double(stack.voxels[k]) - grain) / span;
    stack.voxels[k] = std::uint16_t(std::clamp(kNormalZero + f * kNormalScale, 0.0, 65535.0));
  }
  stack.bits = 16;
}

}  // namespace granmem
