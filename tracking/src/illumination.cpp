#include "granmem/tracking/illumination.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "granmem/core/error.hpp"

namespace granmem {
namespace {

// Voxels a slice needs of a phase for its level to be measured there.
constexpr std::size_t kMinVoxels = 32;

// Each slice's value replaced by the median over the slices within `reach` of it.
std::vector<double> pooled_median(const std::vector<double>& per_slice, std::int64_t reach) {
  const auto n = std::int64_t(per_slice.size());
  std::vector<double> out(per_slice.size()), window;
  for (std::int64_t z = 0; z < n; ++z) {
    window.assign(per_slice.begin() + std::max<std::int64_t>(0, z - reach),
                  per_slice.begin() + std::min(n, z + reach + 1));
    std::nth_element(window.begin(), window.begin() + std::ptrdiff_t(window.size() / 2),
                     window.end());
    out[std::size_t(z)] = window[window.size() / 2];
  }
  return out;
}

}  // namespace

void normalize_illumination(Stack& stack, const IlluminationOptions& o) {
  if (!(o.diameter > 0)) throw Error("illumination: the grain diameter must be positive");
  const std::int64_t length = o.beam_axis == 0 ? stack.nx : stack.ny;  // along the beam
  const std::int64_t lines = o.beam_axis == 0 ? stack.ny : stack.nx;
  const double sign = o.dark_grains ? 1 : -1;  // fluid above the grains, or below
  const auto nz = std::size_t(stack.nz), len = std::size_t(length);
  auto voxel_of = [&](std::uint16_t* slice, std::int64_t l, std::int64_t s) -> std::uint16_t& {
    return o.beam_axis == 0 ? slice[l * stack.nx + s] : slice[s * stack.nx + l];
  };

  // Pass 1, per slice: the slice's low and high levels (grain and fluid percentiles), then
  // the split between fluid and grain halfway between them, each pooled over the slices
  // within two diameters: a slice between two layers of grains, or above the packing, is
  // nearly all fluid, and its own percentiles would put the split inside the fluid.
  const auto reach = std::int64_t(std::ceil(2 * o.diameter));
  std::vector<double> low(nz), high(nz);
#pragma omp parallel
  {
    std::vector<double> sample;
#pragma omp for schedule(dynamic, 2)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const std::uint16_t* slice = stack.slice(z);
      sample.assign(slice, slice + stack.nx * stack.ny);
      const auto q = [&](double p) {
        const auto i = std::size_t(p * double(sample.size() - 1));
        std::nth_element(sample.begin(), sample.begin() + std::ptrdiff_t(i), sample.end());
        return sample[i];
      };
      high[std::size_t(z)] = q(o.fluid_percentile);
      low[std::size_t(z)] = q(o.grain_percentile);
    }
  }
  const std::vector<double> pooled_low = pooled_median(low, reach),
                            pooled_high = pooled_median(high, reach);

  // Then the fluid's sum and count at each position along the beam, and the median grain
  // voxel.
  std::vector<double> middle(nz), grain_median(nz), fallback(nz);
  std::vector<std::vector<double>> fluid_sum(nz, std::vector<double>(len)),
      fluid_count(nz, std::vector<double>(len));
#pragma omp parallel
  {
    std::vector<double> grains;
#pragma omp for schedule(dynamic, 2)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      std::uint16_t* slice = stack.slice(z);
      const auto zi = std::size_t(z);
      middle[zi] = 0.5 * (pooled_high[zi] + pooled_low[zi]);
      fallback[zi] = o.dark_grains ? pooled_low[zi] : pooled_high[zi];
      // The dark level from voxels well inside grains: a slice through the caps of a layer
      // holds mostly the partial volumes of grain surfaces, above the grains' level.
      const double deep_grain = middle[zi] - 0.5 * (middle[zi] - fallback[zi]);
      grains.clear();
      for (std::int64_t l = 0; l < lines; ++l) {
        for (std::int64_t s = 0; s < length; ++s) {
          const double v = voxel_of(slice, l, s);
          if (sign * (v - middle[zi]) > 0) {
            fluid_sum[zi][std::size_t(s)] += v;
            fluid_count[zi][std::size_t(s)] += 1;
          } else if (sign * (v - deep_grain) < 0) {
            grains.push_back(v);
          }
        }
      }
      grain_median[zi] = std::nan("");
      if (grains.size() >= kMinVoxels) {
        std::nth_element(grains.begin(), grains.begin() + std::ptrdiff_t(grains.size() / 2),
                         grains.end());
        grain_median[zi] = grains[grains.size() / 2];
      }
    }
  }

  // The fall-off along the beam changes slowly from slice to slice, and so does the dark
  // level: both are pooled over the slices within two diameters (and the fall-off over a
  // diameter along the beam), which takes the packing's structure out of them. Flicker
  // and streaks, which do change from one slice or line to the next, go into the line
  // scales below.
  const auto half = std::int64_t(std::ceil(0.5 * o.diameter));
  std::vector<std::vector<double>> shape(nz, std::vector<double>(len, 1.0));
  std::vector<double> grain_level(nz);
#pragma omp parallel
  {
    std::vector<double> levels;
#pragma omp for schedule(static)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const auto zi = std::size_t(z);
      const std::int64_t z0 = std::max<std::int64_t>(0, z - reach);
      const std::int64_t z1 = std::min(stack.nz - 1, z + reach);
      levels.clear();
      for (std::int64_t w = z0; w <= z1; ++w) {
        if (!std::isnan(grain_median[std::size_t(w)]))
          levels.push_back(grain_median[std::size_t(w)]);
      }
      grain_level[zi] = fallback[zi];
      if (!levels.empty()) {
        std::nth_element(levels.begin(), levels.begin() + std::ptrdiff_t(levels.size() / 2),
                         levels.end());
        grain_level[zi] = levels[levels.size() / 2];
      }
      double mean = 0;
      for (std::int64_t s = 0; s < length; ++s) {
        double sum = 0, count = 0;
        for (std::int64_t w = z0; w <= z1; ++w) {
          for (std::int64_t t = std::max<std::int64_t>(0, s - half);
               t <= std::min(length - 1, s + half); ++t) {
            sum += fluid_sum[std::size_t(w)][std::size_t(t)];
            count += fluid_count[std::size_t(w)][std::size_t(t)];
          }
        }
        shape[zi][std::size_t(s)] = count > 0 ? sum / count : 0;
        mean += shape[zi][std::size_t(s)];
      }
      mean /= double(length);
      for (double& v : shape[zi])
        v = mean > 0 && v > 0 ? v / mean : 1.0;
    }
  }

  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  // Fluid scaled by the fall-off and cleared of the dark level: 1 where lit evenly.
  auto scaled = [&](std::uint16_t* slice, std::size_t zi, std::int64_t l, std::int64_t s) {
    return (double(voxel_of(slice, l, s)) - grain_level[zi]) / shape[zi][std::size_t(s)];
  };
  auto fluid_at = [&](std::uint16_t* slice, std::size_t zi, std::int64_t l, std::int64_t s) {
    return sign * (double(voxel_of(slice, l, s)) - middle[zi]) > 0;
  };

  // Pass 2, per slice: each line's scale (streaks), relative to the slice's (flicker).
  // A line's median fluid value depends on which grains it crosses (blurred edges lie above
  // halfway too, in numbers that vary from line to line): smoothed over a diameter of
  // lines it keeps the slow changes and loses that. The sharp changes (streaks) come back
  // as the line's ratio to its neighbours where all of them see fluid: adjacent lines cross
  // the same grains, so that ratio is 1 but for a streak.
  std::vector<std::vector<double>> line_factor(nz, std::vector<double>(std::size_t(lines), 1.0));
  std::vector<double> slice_scale(nz, 1.0);
#pragma omp parallel
  {
    std::vector<double> values, raw(static_cast<std::size_t>(lines)), smooth_lines, window;
#pragma omp for schedule(dynamic, 2)
    for (std::int64_t z = 0; z < stack.nz; ++z) {
      const auto zi = std::size_t(z);
      std::uint16_t* slice = stack.slice(z);
      std::vector<double> known;
      for (std::int64_t l = 0; l < lines; ++l) {
        values.clear();
        for (std::int64_t s = 0; s < length; ++s) {
          if (fluid_at(slice, zi, l, s)) values.push_back(scaled(slice, zi, l, s));
        }
        raw[std::size_t(l)] = 0;
        if (values.size() >= std::size_t(0.1 * double(length))) {
          raw[std::size_t(l)] = median(values);
          known.push_back(raw[std::size_t(l)]);
        }
      }
      const double typical = known.empty() ? 1.0 : median(known);
      for (double& r : raw) {
        if (r == 0) r = typical;
      }
      const auto across = std::int64_t(std::ceil(0.5 * o.diameter));
      smooth_lines.resize(raw.size());
      for (std::int64_t l = 0; l < lines; ++l) {
        window.assign(raw.begin() + std::max<std::int64_t>(0, l - across),
                      raw.begin() + std::min(lines, l + across + 1));
        smooth_lines[std::size_t(l)] = median(window);
      }
      window = smooth_lines;
      slice_scale[zi] = median(window);
      for (std::int64_t l = 0; l < lines; ++l) {
        values.clear();
        for (std::int64_t s = 0; s < length; ++s) {
          bool fluid = fluid_at(slice, zi, l, s);
          double neighbours = 0;
          int count = 0;
          for (std::int64_t k = l - 2; k <= l + 2 && fluid; ++k) {
            if (k == l || k < 0 || k >= lines) continue;
            fluid = fluid_at(slice, zi, k, s);
            neighbours += scaled(slice, zi, k, s) / smooth_lines[std::size_t(k)];
            ++count;
          }
          if (fluid && count > 0 && neighbours > 0) {
            values.push_back(scaled(slice, zi, l, s) * count / neighbours);
          }
        }
        const double scale = values.size() >= 16 ? median(values) : smooth_lines[std::size_t(l)];
        line_factor[zi][std::size_t(l)] = scale / slice_scale[zi];
      }
    }
  }

  // Pass 3: the slices' scales (flicker) the same way, as each slice's ratio to its
  // neighbours where all of them see fluid, starting from the scales pooled over two
  // diameters of slices; twice, the second time against the neighbours' first estimates.
  std::vector<double> flicker(nz);
  for (std::int64_t z = 0; z < stack.nz; ++z) {
    std::vector<double> window(slice_scale.begin() + std::max<std::int64_t>(0, z - reach),
                               slice_scale.begin() + std::min(stack.nz, z + reach + 1));
    flicker[std::size_t(z)] = median(window);
  }
  for (int round = 0; round < 2; ++round) {
    std::vector<double> next(nz);
#pragma omp parallel
    {
      std::vector<double> values;
#pragma omp for schedule(dynamic, 2)
      for (std::int64_t z = 0; z < stack.nz; ++z) {
        const auto zi = std::size_t(z);
        values.clear();
        for (std::int64_t l = 0; l < lines; ++l) {
          for (std::int64_t s = l % 4; s < length; s += 4) {  // a quarter is plenty
            if (!fluid_at(stack.slice(z), zi, l, s)) continue;
            double neighbours = 0;
            int count = 0;
            bool fluid = true;
            for (std::int64_t k = z - 2; k <= z + 2 && fluid; ++k) {
              if (k == z || k < 0 || k >= stack.nz) continue;
              const auto ki = std::size_t(k);
              fluid = fluid_at(stack.slice(k), ki, l, s);
              neighbours += scaled(stack.slice(k), ki, l, s) /
                            (line_factor[ki][std::size_t(l)] * flicker[ki]);
              ++count;
            }
            if (fluid && count > 0 && neighbours > 0) {
              values.push_back(scaled(stack.slice(z), zi, l, s) / line_factor[zi][std::size_t(l)] *
                               count / neighbours);
            }
          }
        }
        next[zi] = values.size() >= 64 ? median(values) : flicker[zi];
      }
    }
    flicker = next;
  }

  // Pass 4: f = (I - dark level) / (fall-off x line factor x slice scale), in place.
#pragma omp parallel for schedule(dynamic, 2)
  for (std::int64_t z = 0; z < stack.nz; ++z) {
    const auto zi = std::size_t(z);
    std::uint16_t* slice = stack.slice(z);
    for (std::int64_t l = 0; l < lines; ++l) {
      const double scale = line_factor[zi][std::size_t(l)] * flicker[zi];
      for (std::int64_t s = 0; s < length; ++s) {
        const double f = std::abs(scale) > 1e-12 ? scaled(slice, zi, l, s) / scale : 0.0;
        voxel_of(slice, l, s) =
            std::uint16_t(std::clamp(kNormalZero + f * kNormalScale, 0.0, 65535.0));
      }
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
  const auto at = [&](double q) {
    const auto i = std::size_t(q * double(sample.size() - 1));
    std::nth_element(sample.begin(), sample.begin() + std::ptrdiff_t(i), sample.end());
    return sample[i];
  };
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
