// Accuracy and speed of `locate` on rendered scans of dense random packings (packing
// fraction 0.59 by default, every artefact of RenderOptions' defaults: holes, blur, shot and
// read noise, attenuation, flicker, streaks), for grain diameters of 8, 12 and 16 voxels,
// isotropic voxels and slices 1.5x coarser, 8- and 16-bit; scans cut to the packing's cube,
// so grains at the faces are cut by the stack's border. Prints one line per case and writes
// the table as CSV: interior grains found, spurious detections, RMS error per axis (voxels
// of that axis), pixel locking (Kolmogorov-Smirnov distance of the fractional parts of the
// positions from uniform, its p-value, and the first-harmonic amplitude of the error against
// the true fractional part), hole-axis error, time per grain and voxels per second.
// Peak memory (ru_maxrss) is that of the whole process: run the big case alone for it.
//
//   locate_bench [--grains N] [--phi F] [--diameters 8,12,16] [--z-ratios 1,1.5]
//                [--bits 8,16] [--threads T] [--seed S] [--out locate_bench.csv]
//   locate_bench --bright ...   (bright grains on a dark fluid, no holes)
//   locate_bench --big [--grains 20000] [--diameters 12] ...   (one scan, memory)
//   locate_bench --camera-only [--noise-variance F] ...   (no flicker, streaks or fall-off;
//                the camera's shot and read noise, their variance times F: what the
//                standard errors count, against the actual errors)

#include <omp.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

#include "bench_options.hpp"
#include "granmem/tracking/locate.hpp"
#include "locate_score.hpp"

namespace {

using namespace granmem;
using namespace granmem::testing;

double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;  // kB on Linux
}

}  // namespace

int main(int argc, char** argv) {
  bench::ScanBenchOptions o;
  o.out = "locate_bench.csv";
  bool big = false, verbose = false, bright = false, camera_only = false;
  double noise_variance = 1;
  bench::Setters setters = o.setters();
  setters["--noise-variance"] = [&](const std::string& v) { noise_variance = std::stod(v); };
  const bool parsed = bench::parse_options(argc, argv, "locate_bench", setters,
                                           {{"--big",
                                             [&] {
                                               big = true;
                                               o.grains = 20000;
                                               o.diameters = {12};
                                               o.z_ratios = {1};
                                               o.bits = {8};
                                             }},
                                            {"--bright", [&] { bright = true; }},
                                            {"--camera-only", [&] { camera_only = true; }},
                                            {"--verbose", [&] { verbose = true; }}});
  if (!parsed) return 2;
  omp_set_num_threads(o.threads);
  using clock = std::chrono::steady_clock;
  auto seconds = [](clock::time_point t) {
    return std::chrono::duration<double>(clock::now() - t).count();
  };

  std::ofstream csv(o.out);
  csv << "diameter,z_ratio,bits,grains,interior,interior_found,edge_found,spurious,"
         "interior_flagged_edge,edge_unflagged,rms_x,rms_y,rms_z,bias_x,bias_y,bias_z,"
         "max_x,max_y,max_z,ks_x,ks_y,ks_z,ks_p_x,ks_p_y,ks_p_z,lock_x,lock_y,lock_z,"
         "axis_median_deg,axis_p90_deg,voxels,render_s,locate_s,illumination_s,candidates_s,"
         "fits_s,locate_cpu_s,ms_per_grain,voxels_per_s,peak_rss_mb\n";
  std::cout << (bright ? "bright grains, no holes; " : "dark grains with holes; ") << "phi "
            << o.phi << ", " << o.threads << " threads, seed " << o.seed << "\n"
            << " d  z  bit  grains interior  found%  false%  rms x     y     z  [vox]"
            << "  KS x    y    z  (p min)  lock[vox]  axis med/p90 [deg]  ms/grain  Mvox/s\n";
  for (double dz : o.z_ratios) {
    for (double diameter : o.diameters) {
      const auto t_pack = clock::now();
      PackingScan scan = packing_scan(o.grains, o.phi, diameter, dz, o.seed);
      if (bright) {  // bright o.grains on a dark fluid, no hole seen
        scan.options.polarity = Polarity::bright_grains;
        scan.options.hole_fraction = 0;
        for (RenderedGrain& g : scan.grains)
          g.axis = Eigen::Vector3d::Constant(NAN);
      }
      if (camera_only) {
        scan.options.flicker = scan.options.attenuation = scan.options.streaks_per_slice = 0;
      }
      scan.options.gain *= noise_variance;  // shot noise variance: gain x signal
      scan.options.read_noise *= std::sqrt(noise_variance);
      const double pack_s = seconds(t_pack);
      for (double b : o.bits) {
        scan.options.bits = int(b);
        Table truth;
        const auto t_render = clock::now();
        Stack stack = render_scan(scan.grains, scan.options, &truth);
        const double render_s = seconds(t_render);
        const double voxels = double(stack.nx) * double(stack.ny) * double(stack.nz);
        LocateOptions lo;
        lo.diameter = diameter;
        lo.hole_fraction = scan.options.hole_fraction;
        lo.dark_grains = !bright;
        LocateSummary summary;
        const auto t_locate = clock::now();
        const double cpu0 = cpu_seconds();
        const Detections d = locate(stack, lo, &summary);
        const double locate_s = seconds(t_locate), locate_cpu = cpu_seconds() - cpu0;
        const LocateScore s = score_locate(d, truth, *scan.options.voxel_size);
        if (verbose) {
          for (const std::string& line : describe_misses(d, truth, *scan.options.voxel_size))
            std::cout << "    " << line << "\n";
        }
        const double ms_per_grain = 1e3 * locate_s / double(o.grains);
        std::cout << std::fixed << std::setw(2) << int(diameter) << std::setprecision(1)
                  << std::setw(4) << dz << std::setw(4) << int(b) << std::setw(8) << o.grains
                  << std::setw(8) << s.interior << std::setprecision(2) << std::setw(8)
                  << 100 * s.interior_fraction() << std::setw(8) << 100 * s.spurious_fraction()
                  << std::setprecision(3) << std::setw(8) << s.rms.x() << std::setw(6) << s.rms.y()
                  << std::setw(6) << s.rms.z() << "   " << std::setw(6) << s.ks.x() << std::setw(6)
                  << s.ks.y() << std::setw(6) << s.ks.z() << std::setprecision(2) << std::setw(6)
                  << s.ks_p.minCoeff() << std::setprecision(3) << std::setw(8)
                  << s.locking.maxCoeff() << std::setprecision(2) << std::setw(10)
                  << s.axis_percentile(0.5) << " / " << s.axis_percentile(0.9)
                  << std::setprecision(3) << std::setw(10) << ms_per_grain << std::setprecision(2)
                  << std::setw(8) << voxels / locate_s / 1e6 << "\n"
                  << std::defaultfloat;
        std::cout << "    stack " << stack.nx << " x " << stack.ny << " x " << stack.nz << " ("
                  << voxels / 1e6 << " Mvoxel, " << voxels * 2 / 1048576 << " MiB as 16-bit)"
                  << ", packing " << pack_s << " s, render " << render_s << " s, locate "
                  << locate_s << " s (CPU " << locate_cpu << " s; illumination "
                  << summary.seconds_illumination << ", candidates " << summary.seconds_candidates
                  << ", fits " << summary.seconds_fits << "), detections " << d.size() << " (edge "
                  << summary.on_edge << "), edge grains found " << s.edge_found << ", spurious "
                  << s.spurious << ", interior flagged edge " << s.interior_flagged
                  << ", edge unflagged " << s.edge_unflagged << ", bias " << s.bias.transpose()
                  << ", max |error| " << s.max_error.transpose() << ", standard error RMS "
                  << s.rms_standard_error.transpose() << " (axis median "
                  << granmem::testing::percentile(s.axis_standard_error, 0.5) << " deg), peak RSS "
                  << peak_rss_mb() << " MB\n";
        csv << diameter << "," << dz << "," << b << "," << o.grains << "," << s.interior << ","
            << s.interior_found << "," << s.edge_found << "," << s.spurious << ","
            << s.interior_flagged << "," << s.edge_unflagged;
        for (const Eigen::Vector3d* v :
             {&s.rms, &s.bias, &s.max_error, &s.ks, &s.ks_p, &s.locking}) {
          csv << "," << v->x() << "," << v->y() << "," << v->z();
        }
        csv << "," << s.axis_percentile(0.5) << "," << s.axis_percentile(0.9) << "," << voxels
            << "," << render_s << "," << locate_s << "," << summary.seconds_illumination << ","
            << summary.seconds_candidates << "," << summary.seconds_fits << "," << locate_cpu << ","
            << ms_per_grain << "," << voxels / locate_s << "," << peak_rss_mb() << "\n";
        csv.flush();
      }
    }
  }
  if (big) std::cout << "peak RSS " << peak_rss_mb() << " MB\n";
  std::cout << "wrote " << o.out << "\n";
  return 0;
}
