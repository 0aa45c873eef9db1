// Diagnostic: a placed twin's replicas right after settling (docs/CALIBRATION.md, "Twins of
// tracked scans", "The placed packing tapped by its own settle"): the grains of a run's frame
// (a simulation's, or tracked scans'; the first, or that of --cycle)
// placed as calibrate --deposit experiment places them, each replica moved by the jitter
// of its seed and settled at the run's friction; one line per replica with its packing
// fraction, lid height and contacts per grain, then their spread.
//
//   placed_replicas RUN.h5 --grains 2500 --box 5cm --mu-s 0.31 [--replicas 4]
//                          [--jitter 5e-7 (m; default 1e-4 grain diameters)] [--cycle 20]
//                          [--settling-damping 1000 (1/s; default the placed packing's)]

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "bench_options.hpp"
#include "granmem/calibration/cycle_observables.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/deposit.hpp"
#include "granmem/sim/placed_packing.hpp"
#include "granmem/sim/simulate_settings.hpp"

int main(int argc, char** argv) {
  using namespace granmem;
  if (argc < 2) {
    std::fprintf(stderr, "usage: placed_replicas RUN.h5 [--grains N --box L --mu-s M ...]\n");
    return 2;
  }
  RunSettings v = default_simulate_settings();
  int replicas = 4;
  std::int64_t cycle = -1;
  double damping = std::nan("");
  double jitter = std::nan("");
  const bool ok = bench::parse_options(
      argc - 1, argv + 1, "placed_replicas",
      {{"--grains", [&](const std::string& s) { v["grains"] = s; }},
       {"--box", [&](const std::string& s) { v["box"] = s; }},
       {"--mu-s", [&](const std::string& s) { v["mu-s"] = s; }},
       {"--replicas", [&](const std::string& s) { replicas = std::stoi(s); }},
       {"--jitter", [&](const std::string& s) { jitter = std::stod(s); }},
       {"--cycle", [&](const std::string& s) { cycle = std::stoll(s); }},
       {"--settling-damping", [&](const std::string& s) { damping = std::stod(s); }}});
  if (!ok || replicas < 2) return 2;
  const PhysicsOptions physics = physics_from(v);
  DepositOptions deposit = deposit_from(v);
  if (std::isfinite(damping)) deposit.placed_settling_damping = damping;
  if (!std::isfinite(jitter)) jitter = 1e-4 * 2 * deposit.radius;
  const TrajectoryReader run(argv[1]);
  const std::optional<std::size_t> frame = cycle < 0 ? 0 : frame_of_cycle(run, cycle);
  if (!frame) {
    std::fprintf(stderr, "placed_replicas: %s has no frame of cycle %lld\n", argv[1],
                 static_cast<long long>(cycle));
    return 2;
  }
  const Grains placed = grains_of_frame(run, *frame, deposit, physics);
  double sum = 0, sum2 = 0, lid = 0, lid2 = 0;
  for (int seed = 1; seed <= replicas; ++seed) {
    DepositSummary s;
    settled_packing(jittered(placed, jitter, std::uint64_t(seed), deposit), deposit, physics,
                    GrainPlacement::at_rest, &s);
    std::printf("seed %d: packing fraction %.6f, lid at %.5f cm, %.3f contacts per grain\n", seed,
                s.packing_fraction, s.lid_height * 100, s.contacts_per_grain);
    sum += s.packing_fraction;
    sum2 += s.packing_fraction * s.packing_fraction;
    lid += s.lid_height;
    lid2 += s.lid_height * s.lid_height;
  }
  const double n = replicas;
  auto sd = [n](double s, double s2) {
    return std::sqrt(std::max(0.0, (s2 - s * s / n) / (n - 1)));
  };
  std::printf("%d replicas: packing fraction %.6f +- %.2g, lid +- %.2g um\n", replicas, sum / n,
              sd(sum, sum2), sd(lid, lid2) * 1e6);
}
