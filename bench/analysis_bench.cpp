// Throughput of the trajectory store and of `granmem analyze` on a paper-sized run:
// 20,000 grains with positions, cavity axes and orientations (a simulation's output).
//   cmake -S . -B build -DGRANMEM_BUILD_BENCH=ON && cmake --build build -j2
//   build/bench/analysis_bench
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <Eigen/Geometry>
#include <filesystem>
#include <random>

#include "granmem/core/trajectory_store.hpp"
#include "granmem/rotation/motion_analysis.hpp"

namespace {

namespace fs = std::filesystem;
using granmem::Frame;
using granmem::RunHeader;

RunHeader header(std::size_t n) {
  RunHeader h;
  h.length_unit = "m";
  h.has_axis = true;
  h.has_orientation = true;
  h.box = granmem::Box{Eigen::Vector3d::Zero(), Eigen::Vector3d(0.15, 0.15, 0.1)};
  for (std::size_t i = 0; i < n; ++i)
    h.id.push_back(std::int64_t(i));
  h.radius.assign(n, 0.0025);
  return h;
}

// Grains random-walking by ~1e-5 m and turning by ~1e-2 rad per cycle.
std::vector<Frame> frames(const RunHeader& h, std::size_t count) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0, 1);
  std::uniform_real_distribution<double> u(0, 1);
  const auto n = Eigen::Index(h.grain_count());
  Frame f = Frame::unknown(h);
  for (Eigen::Index i = 0; i < n; ++i) {
    f.position.row(i) = Eigen::Vector3d(0.15 * u(rng), 0.15 * u(rng), 0.1 * u(rng));
    f.orientation.row(i) << 1, 0, 0, 0;
  }
  std::vector<Frame> out;
  for (std::size_t t = 0; t < count; ++t) {
    f.step = std::int64_t(t);
    f.time = double(t);
    for (Eigen::Index i = 0; i < n; ++i) {
      f.position.row(i) += 1e-5 * Eigen::Vector3d(g(rng), g(rng), g(rng)).transpose();
      Eigen::Quaterniond q(f.orientation(i, 0), f.orientation(i, 1), f.orientation(i, 2),
                           f.orientation(i, 3));
      q = Eigen::AngleAxisd(1e-2 * g(rng), Eigen::Vector3d::Random().normalized()) * q;
      f.orientation.row(i) << q.w(), q.x(), q.y(), q.z();
      f.axis.row(i) = (q * Eigen::Vector3d::UnitZ()).transpose();
    }
    out.push_back(f);
  }
  return out;
}

fs::path bench_file() {
  return fs::temp_directory_path() / "granmem-bench-run.h5";
}

void report_memory(benchmark::State& state) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_MB"] = double(usage.ru_maxrss) / 1024.0;
}

void BM_WriteStore(benchmark::State& state) {
  const RunHeader h = header(std::size_t(state.range(0)));
  const std::vector<Frame> run = frames(h, std::size_t(state.range(1)));
  for (auto _ : state) {
    granmem::TrajectoryWriter writer(bench_file(), h);
    for (const Frame& f : run)
      writer.append(f);
    writer.commit();
  }
  state.SetItemsProcessed(state.iterations() * state.range(0) * state.range(1));
  state.counters["MB_per_s"] = benchmark::Counter(
      double(state.iterations() * state.range(0) * state.range(1)) * 10 * 8 / 1e6,
      benchmark::Counter::kIsRate);
  report_memory(state);
}

void BM_AnalyzeMotion(benchmark::State& state) {
  {
    const RunHeader h = header(std::size_t(state.range(0)));
    granmem::Trajectories run{h, frames(h, std::size_t(state.range(1))), {}};
    granmem::write_trajectories(bench_file(), run);
  }
  granmem::AnalysisOptions options;
  options.motion.subtract_drift = true;
  options.motion.wall_distance = 0.005;
  options.density.scale = granmem::BinScale::logarithmic;
  for (auto _ : state) {
    const granmem::TrajectoryReader reader(bench_file());
    benchmark::DoNotOptimize(granmem::analyze_motion(reader, options));
  }
  // Items: grain displacements computed (grains x frame pairs).
  state.SetItemsProcessed(state.iterations() * state.range(0) * (state.range(1) - 1));
  report_memory(state);
}

BENCHMARK(BM_WriteStore)->Args({20000, 11})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_AnalyzeMotion)
    ->Args({2000, 11})
    ->Args({20000, 11})
    ->Args({20000, 101})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
