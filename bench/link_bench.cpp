// Accuracy and speed of the linker on a dense random packing (20,000 grains of diameter 1
// at packing fraction 0.6 by default): two scans, the second after a uniform compression
// and shear (the wall side moves in by 1 diameter, slides by 0.5) plus a random
// displacement of each grain uniform in a ball of radius a = 0.1, 0.3, 0.5 diameter, with
// detection noise, missing and spurious detections; then the same with the random part
// only. Prints a table and writes it as CSV.
//
//   link_bench [--grains N] [--seed S] [--repeat R] [--out link_bench.csv]

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <string>

#include "granmem/tracking/link.hpp"
#include "link_packing.hpp"

namespace {

using namespace granmem;
using namespace granmem::testing;

struct Case {
  std::string name;
  bool field;
  double random;
};

}  // namespace

int main(int argc, char** argv) {
  std::size_t grains = 20000;
  std::uint32_t seed = 1;
  int repeat = 3;
  std::string out = "link_bench.csv";
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--grains")
      grains = std::size_t(std::stoul(v));
    else if (a == "--seed")
      seed = std::uint32_t(std::stoul(v));
    else if (a == "--repeat")
      repeat = std::stoi(v);
    else if (a == "--out")
      out = v;
    else {
      std::cerr << "link_bench: unknown option " << a << "\n";
      return 2;
    }
  }
  using clock = std::chrono::steady_clock;
  const auto t0 = clock::now();
  double L = 0;
  const std::vector<Eigen::Vector3d> x = random_packing(grains, 0.6, seed, &L);
  std::cout << "packing: " << grains << " grains, edge " << L << " diameters, phi 0.6, closest "
            << "pair " << closest_pair(x) << ", made in "
            << std::chrono::duration<double>(clock::now() - t0).count() << " s\n";

  const double noise = 0.02, missing = 0.005;
  const std::size_t extra = grains / 200;
  std::ofstream csv(out);
  csv << "case,random,grains,links,correct,possible,fraction_correct,fraction_found,seconds\n";
  std::cout << std::left << std::setw(22) << "case" << std::right << std::setw(8) << "random"
            << std::setw(9) << "links" << std::setw(9) << "wrong" << std::setw(12) << "correct"
            << std::setw(10) << "found" << std::setw(10) << "time [s]\n";
  for (const Case& c : {Case{"compression+shear", true, 0.1}, Case{"compression+shear", true, 0.3},
                        Case{"compression+shear", true, 0.5}, Case{"random only", false, 0.1},
                        Case{"random only", false, 0.3}, Case{"random only", false, 0.5}}) {
    std::mt19937 rng(seed + 1000);
    std::vector<Eigen::Vector3d> y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      y[i] = x[i] + in_ball(rng, c.random);
      if (c.field) y[i] += Eigen::Vector3d(0.5 * x[i].y() / L, -1.0 * x[i].y() / L, 0);
    }
    const Scan a = scan_of(x, 0, rng, noise, missing, extra);
    const Scan b = scan_of(y, 1, rng, noise, missing, extra);
    double best = 1e300;
    LinkScore score;
    for (int r = 0; r < repeat; ++r) {
      const auto start = clock::now();
      const Trajectories run = link_scans({a.detections, b.detections}, LinkOptions{});
      best = std::min(best, std::chrono::duration<double>(clock::now() - start).count());
      score = score_links(run, 0, 1, a, b);
    }
    std::cout << std::left << std::setw(22) << c.name << std::right << std::setw(8) << c.random
              << std::setw(9) << score.links << std::setw(9) << score.links - score.correct
              << std::setw(11) << std::fixed << std::setprecision(4)
              << 100 * score.fraction_correct() << "%" << std::setw(9)
              << 100 * score.fraction_found() << "%" << std::setw(10) << std::setprecision(3)
              << best << "\n"
              << std::defaultfloat;
    csv << c.name << "," << c.random << "," << grains << "," << score.links << "," << score.correct
        << "," << score.possible << "," << score.fraction_correct() << "," << score.fraction_found()
        << "," << best << "\n";
  }
  std::cout << "wrote " << out << "\n";
  return 0;
}
