// Diagnostic: what a further locating error does to the structure a run's frames measure
// (structure_noise_effect, as calibrate's scan-noise check moves them; docs/CALIBRATION.md,
// "Measured with the contacts' error"): the window means of the bulk and height packing
// fractions and of the coordination, with every position moved by a normal error of the
// given RMS across the slices (x, y) and along z, minus as measured (printed after the
// value as measured). One draw per seed.
//
//   structure_noise RUN.h5 --window 1:3 --error 6.96,15.1 (um) --radius 2.5 (mm)
//                   --grains 3000 [--seed 1] [--gap 0.02 (the contact gap, d)]

#include <cstdio>
#include <string>

#include "bench_options.hpp"
#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/core/trajectory_store.hpp"

int main(int argc, char** argv) {
  using namespace granmem;
  if (argc < 2) {
    std::fprintf(stderr, "usage: structure_noise RUN.h5 --window F:L --error A,Z --radius R ...\n");
    return 2;
  }
  CycleRange window{0, 0};
  double across = 0, along_z = 0;
  KnownGrains known;
  std::uint64_t seed = 1;
  StructureOptions structure;
  const bool ok = bench::parse_options(
      argc - 1, argv + 1, "structure_noise",
      {{"--window",
        [&](const std::string& s) {
          window = {std::stoll(s.substr(0, s.find(':'))), std::stoll(s.substr(s.find(':') + 1))};
        }},
       {"--error",
        [&](const std::string& s) {
          const auto e = bench::number_list(s);
          across = e.at(0);
          along_z = e.at(e.size() - 1);
        }},
       {"--radius", [&](const std::string& s) { known.radius = std::stod(s) * 1e-3; }},
       {"--grains", [&](const std::string& s) { known.count = std::stoull(s); }},
       {"--seed", [&](const std::string& s) { seed = std::stoull(s); }},
       {"--gap", [&](const std::string& s) { structure.contact_gap = std::stod(s); }}});
  if (!ok || !known.radius) return 2;
  const TrajectoryReader run(argv[1]);
  const Eigen::Vector3d sigma =
      Eigen::Vector3d(across, across, along_z) * 1e-6 / metres_per_length(run);
  const SteadyState effect = structure_noise_effect(run, window, sigma, structure, known, seed);
  const SteadyState as_measured =
      window_means(observable_series(run, {}, structure, known, window), window);
  for (const char* name : {"bulk_packing_fraction", "coordination", "height_packing_fraction"})
    std::printf("%s %.6g %+.5g\n", name, as_measured[name], effect[name]);
}
