// locate on rendered dense packings (packing fraction 0.58, RenderOptions' default
// artefacts; tests/tracking/locate_score.hpp's packings and scores, as the tests use them)
// at seeds the tests do not use: one line per scan with the interior grains found, the
// spurious detections, the RMS error per axis (voxels of that axis) and the median
// hole-axis error. docs/BENCHMARKS.md, "Illumination from deep fluid".
//
//   locate_seeds [--seeds 101,102,103]

#include <cstdio>
#include <string>
#include <vector>

#include "bench_options.hpp"
#include "granmem/tracking/locate.hpp"
#include "locate_score.hpp"

int main(int argc, char** argv) {
  using namespace granmem;
  std::vector<std::uint32_t> seeds{101, 102, 103};
  const bool ok =
      bench::parse_options(argc, argv, "locate_seeds", {{"--seeds", [&](const std::string& v) {
                                                           seeds.clear();
                                                           for (double s : bench::number_list(v))
                                                             seeds.push_back(std::uint32_t(s));
                                                         }}});
  if (!ok) return 2;
  struct Case {
    std::size_t grains;
    double diameter, z_ratio;
  };
  for (const Case c : {Case{500, 8, 1}, Case{1000, 8, 1.5}, Case{220, 12, 1}, Case{220, 12, 1.5},
                       Case{300, 10, 1.2}}) {
    for (std::uint32_t seed : seeds) {
      const testing::PackingScan scan =
          testing::packing_scan(c.grains, 0.58, c.diameter, c.z_ratio, seed);
      Table truth;
      const Stack stack = render_scan(scan.grains, scan.options, &truth);
      LocateOptions o;
      o.diameter = c.diameter;
      const testing::LocateScore s =
          testing::score_locate(locate(stack, o), truth, *scan.options.voxel_size);
      std::printf(
          "d %.0f, slices %.1fx, seed %u: %zu/%zu found, %zu spurious, RMS %.4f %.4f %.4f, "
          "axis median %.3f deg\n",
          c.diameter, c.z_ratio, seed, s.interior_found, s.interior, s.spurious, s.rms.x(),
          s.rms.y(), s.rms.z(), s.axis_percentile(0.5));
    }
  }
}
