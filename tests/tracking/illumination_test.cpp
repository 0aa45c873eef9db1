#include "granmem/tracking/illumination.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "granmem/tracking/render.hpp"
#include "locate_score.hpp"

// normalize_illumination against the light a scan was rendered with: one packing drawn
// under a strong fall-off along the beam, slice-to-slice flicker and streaks along the
// beam, and under even light (no noise either: what is left is the correction's). Its
// voxels of pure fluid (known from the evenly lit scan) must read alike wherever they are:
// along the beam, slice to slice and line to line.
namespace granmem {
namespace {

// How the normalised level of the pure fluid varies: across 8 blocks along the beam (x)
// the spread of their means, and the standard deviation of the slices' and of the lines'
// means (lines along the beam with 20 or more fluid voxels).
struct FluidLevels {
  double along_beam = 0, across_slices = 0, across_lines = 0;
};

double standard_deviation(const std::vector<double>& v) {
  double m = 0, s = 0;
  for (double x : v)
    m += x / double(v.size());
  for (double x : v)
    s += (x - m) * (x - m) / double(v.size() - 1);
  return std::sqrt(s);
}

FluidLevels fluid_levels(const Stack& normalised, const Stack& even, const RenderOptions& o) {
  const double full = even.max_value();
  std::vector<double> block_sum(8, 0), block_n(8, 0), slices, lines;
  for (std::int64_t z = 0; z < even.nz; ++z) {
    double slice_sum = 0, slice_n = 0;
    for (std::int64_t y = 0; y < even.ny; ++y) {
      double line_sum = 0, line_n = 0;
      for (std::int64_t x = 0; x < even.nx; ++x) {
        if (even.at(x, y, z) / full < o.fluid() - 0.005) continue;  // not pure fluid
        const double f = fluid_fraction(normalised.at(x, y, z));
        const std::size_t b = std::size_t(8 * x / even.nx);
        block_sum[b] += f;
        block_n[b] += 1;
        line_sum += f;
        line_n += 1;
      }
      if (line_n >= 20) lines.push_back(line_sum / line_n);
      slice_sum += line_sum;
      slice_n += line_n;
    }
    if (slice_n > 0) slices.push_back(slice_sum / slice_n);
  }
  std::vector<double> blocks;
  for (std::size_t b = 0; b < 8; ++b)
    blocks.push_back(block_sum[b] / block_n[b]);
  const auto [lo, hi] = std::minmax_element(blocks.begin(), blocks.end());
  return {*hi - *lo, standard_deviation(slices), standard_deviation(lines)};
}

// The scan's options without camera noise, 16-bit: what is left is the correction's own.
RenderOptions noiseless(RenderOptions o) {
  o.read_noise = 0;
  o.gain = 0;
  o.bits = 16;
  return o;
}

TEST(Illumination, RemovesTheFallOffTheFlickerAndTheStreaks) {
  const testing::PackingScan scan = testing::packing_scan(220, 0.58, 12, 1, 5);
  RenderOptions lit = noiseless(scan.options);
  lit.attenuation = 4e-3;  // a quarter of the light lost across the scan
  lit.flicker = 0.1;       // one slice in 70 a third darker than the next
  lit.streaks_per_slice = 2;
  lit.streak_strength = 0.15;
  RenderOptions even = lit;
  even.attenuation = 0;
  even.flicker = 0;
  even.streaks_per_slice = 0;
  const Stack scan_lit = render_scan(scan.grains, lit);
  const Stack scan_even = render_scan(scan.grains, even);
  IlluminationOptions o;
  o.diameter = 12;

  Stack corrected = scan_lit;
  normalize_illumination(corrected, o);
  const FluidLevels c = fluid_levels(corrected, scan_even, lit);
  // One fluid and grain level for the whole scan: the light's variations stay in.
  Stack levelled = scan_lit;
  normalize_levels(levelled, o);
  const FluidLevels l = fluid_levels(levelled, scan_even, lit);
  std::cout << "fluid level, corrected: along the beam " << c.along_beam << ", slices "
            << c.across_slices << ", lines " << c.across_lines << "; one level: " << l.along_beam
            << ", " << l.across_slices << ", " << l.across_lines << "\n";
  EXPECT_GT(l.along_beam, 0.15);  // the artefacts are there
  EXPECT_GT(l.across_slices, 0.05);
  EXPECT_GT(l.across_lines, 0.05);
  EXPECT_LT(c.along_beam, 0.05);
  EXPECT_LT(c.across_slices, 0.015);
  EXPECT_LT(c.across_lines, 0.01);
}

// Evenly lit, the fluid reads alike everywhere: the packing's structure (how many grain
// edges a line or a slice crosses) does not leak into the levels.
TEST(Illumination, LeavesTheEvenlyLitFluidEven) {
  const testing::PackingScan scan = testing::packing_scan(220, 0.58, 12, 1.5, 6);
  RenderOptions even = noiseless(scan.options);
  even.attenuation = 0;
  even.flicker = 0;
  even.streaks_per_slice = 0;
  Stack s = render_scan(scan.grains, even);
  const Stack original = s;
  IlluminationOptions o;
  o.diameter = 12;
  normalize_illumination(s, o);
  const FluidLevels c = fluid_levels(s, original, even);
  std::cout << "fluid level, evenly lit: along the beam " << c.along_beam << ", slices "
            << c.across_slices << ", lines " << c.across_lines << "\n";
  EXPECT_LT(c.along_beam, 0.01);
  EXPECT_LT(c.across_slices, 0.005);
  EXPECT_LT(c.across_lines, 0.005);
}

}  // namespace
}  // namespace granmem
