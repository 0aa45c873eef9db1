// Hole axes on rendered dense packings: how many interior grains get an axis, the fitted
// axis' angular error side by side with the lab's classical estimate (the largest-
// eigenvalue axis of the bright hole voxels within 0.8 R, hole_axis.hpp) on the same
// centres, how well the fit's standard error predicts its error, and the hole-contact
// flag's precision and recall against the contacts of the true packing; then, on a second
// scan of the same packing with every grain turned by a known random rotation (0-20 deg
// about a random axis; the packing shifted by a fraction of a voxel, fresh noise), the
// measured single-axis rotation angles against the true ones.
//
//   axis_bench [--grains N] [--phi F] [--diameters 8,12,16] [--z-ratios 1,1.5] [--bits 8]
//              [--psf 0.7,0.7,1.0] [--threads T] [--seed S] [--out axis_bench.csv]
//              [--clean]     (no noise, flicker, streaks or fall-off)
//              [--dump grains.csv]   (per grain of the first scan: true and fitted axes...)
//
// Prints locate's time per grain (all grains, wall clock) on stderr.
//
// Figures and how they were measured: docs/BENCHMARKS.md, "Hole axes".
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <string>

#include "bench_options.hpp"
#include "granmem/rotation/hole_contacts.hpp"
#include "granmem/rotation/single_axis_rotation.hpp"
#include "granmem/tracking/hole_axis.hpp"
#include "granmem/tracking/locate.hpp"
#include "locate_score.hpp"

namespace {

using namespace granmem;
using namespace granmem::testing;

constexpr double kDegree = 3.14159265358979323846 / 180;

}  // namespace

int main(int argc, char** argv) {
  bench::ScanBenchOptions o;
  o.out = "axis_bench.csv";
  o.bits = {8};
  Eigen::Vector3d psf = RenderOptions{}.blur_sigma;  // voxels of each axis
  bench::Setters setters = o.setters();
  setters["--psf"] = [&](const std::string& v) {
    const std::vector<double> p = bench::number_list(v);
    if (p.size() == 3) psf = Eigen::Vector3d(p[0], p[1], p[2]);
  };
  bool clean = false;  // no noise, flicker, streaks or fall-off: what is left is the method's
  std::string dump;    // per grain: truth, found, axes, errors
  setters["--dump"] = [&](const std::string& v) { dump = v; };
  const bool parsed =
      bench::parse_options(argc, argv, "axis_bench", setters, {{"--clean", [&] { clean = true; }}});
  if (!parsed) return 2;
  omp_set_num_threads(o.threads);
  std::ofstream csv(o.out);
  std::ofstream grains_csv;
  if (!dump.empty()) {
    grains_csv.open(dump);
    grains_csv << "diameter,z_ratio,id,tx,ty,tz,ax,ay,az,cx,cy,cz,fx,fy,fz,radius,error_deg,"
                  "sigma_deg,contact,flagged,lab_deg\n";
  }
  csv << "diameter,z_ratio,bits,interior_found,with_axis,fit_median_deg,fit_p95_deg,"
         "lab_with_axis,lab_median_deg,lab_p95_deg,sigma_median_deg,within_2sigma,"
         "true_contacts,flagged,flag_precision,flag_recall,clear_median_deg,clear_p95_deg,"
         "rotations,rotation_error_median_deg,rotation_error_p95_deg,along_z_median_deg\n";
  std::cout << "psf " << psf.transpose() << " voxel, phi " << o.phi << ", " << o.threads
            << " threads, seed " << o.seed << "; angles in degrees, interior grains found\n"
            << " d  z  bit  found  axis%   fit med  p95    lab axis%  med   p95    sigma med "
               "<2sigma%  contacts flagged prec  recall  unflagged med p95   turned  err med p95  "
               "along z med\n";
  for (double dz : o.z_ratios) {
    for (double diameter : o.diameters) {
      PackingScan scan = packing_scan(o.grains, o.phi, diameter, dz, o.seed);
      const Eigen::Vector3d vs = *scan.options.voxel_size;
      for (double b : o.bits) {
        scan.options.bits = int(b);
        scan.options.blur_sigma = psf;
        if (clean) {
          scan.options.read_noise = scan.options.gain = scan.options.flicker = 0;
          scan.options.attenuation = scan.options.streaks_per_slice = 0;
        }
        Table truth;
        Stack stack = render_scan(scan.grains, scan.options, &truth);
        LocateOptions lo;
        lo.diameter = diameter;
        lo.hole_fraction = scan.options.hole_fraction;
        LocateSummary summary;
        const Detections d = locate(stack, lo, &summary);  // leaves `stack` normalised
        std::cerr << "locate " << 1000 * summary.seconds / double(d.size()) << " ms/grain ("
                  << d.size() << " grains, fits " << 1000 * summary.seconds_fits / double(d.size())
                  << ")\n";
        const LocateMatch m = match_locate(d, truth, vs);

        const std::size_t n = truth.rows();
        const std::vector<std::uint8_t> true_contact =
            true_hole_contacts(truth, m, vs, scan.options.hole_fraction);
        std::vector<double> fit_error, lab_error, sigma, clear_error, along_z_error;
        std::size_t found = 0, lab_found = 0, within = 0, contacts = 0, flagged = 0, hits = 0;
        for (std::size_t i = 0; i < n; ++i) {
          if (m.edge[i] || m.of_grain[i] < 0) continue;
          const auto k = Eigen::Index(m.of_grain[i]);
          ++found;
          const Eigen::Vector3d t(truth["ax"].values[i], truth["ay"].values[i],
                                  truth["az"].values[i]);
          const Eigen::Vector3d a = d.axis.row(k).transpose();
          const Eigen::Vector3d centre = d.position.row(k).transpose();
          contacts += true_contact[i];
          flagged += d.hole_contact[std::size_t(k)];
          hits += true_contact[i] && d.hole_contact[std::size_t(k)];
          if (a.allFinite()) {
            const double e = single_axis_angle(a, t) / kDegree;
            fit_error.push_back(e);
            if (std::abs(t.z()) > 0.9) along_z_error.push_back(e);  // along the coarse axis
            const double s = 1 / d.axis_quality[std::size_t(k)] - 1;
            sigma.push_back(s);
            within += e <= 2 * s;
            if (!d.hole_contact[std::size_t(k)]) clear_error.push_back(e);
          }
          const Eigen::Vector3d lab = lab_hole_axis(stack, centre, 0.5, vs);
          if (lab.allFinite()) {
            ++lab_found;
            lab_error.push_back(single_axis_angle(lab, t) / kDegree);
          }
          if (grains_csv.is_open()) {
            const Eigen::Vector3d c(truth["x"].values[i], truth["y"].values[i],
                                    truth["z"].values[i]);  // voxels
            const Eigen::Vector3d found_voxel = centre.cwiseQuotient(vs);
            grains_csv << diameter << "," << dz << "," << i << "," << t.x() << "," << t.y() << ","
                       << t.z() << "," << a.x() << "," << a.y() << "," << a.z() << "," << c.x()
                       << "," << c.y() << "," << c.z() << "," << found_voxel.x() << ","
                       << found_voxel.y() << "," << found_voxel.z() << ","
                       << d.radius[std::size_t(k)] / vs.x() << ","
                       << (a.allFinite() ? single_axis_angle(a, t) / kDegree : NAN) << ","
                       << 1 / d.axis_quality[std::size_t(k)] - 1 << "," << int(true_contact[i])
                       << "," << int(d.hole_contact[std::size_t(k)]) << ","
                       << (lab.allFinite() ? single_axis_angle(lab, t) / kDegree : NAN) << "\n";
          }
        }
        // The second scan: each grain turned, the packing shifted, new noise.
        std::vector<RenderedGrain> turned = scan.grains;
        std::mt19937 rng(o.seed * 104729u + 17);
        std::normal_distribution<double> gauss(0, 1);
        std::uniform_real_distribution<double> angle(0, 20 * kDegree);
        for (RenderedGrain& g : turned) {
          const Eigen::Vector3d about =
              Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
          g.axis = Eigen::AngleAxisd(angle(rng), about) * g.axis;
          g.centre += Eigen::Vector3d(0.37, 0.21, 0.13).cwiseProduct(vs);
        }
        RenderOptions second = scan.options;
        second.seed += 1000;
        Table truth2;
        Stack stack2 = render_scan(turned, second, &truth2);
        const Detections d2 = locate(stack2, lo);
        const LocateMatch m2 = match_locate(d2, truth2, vs);
        std::vector<double> rotation_error;
        for (std::size_t i = 0; i < n; ++i) {
          if (m.edge[i] || m2.edge[i] || m.of_grain[i] < 0 || m2.of_grain[i] < 0) continue;
          const Eigen::Vector3d a1 = d.axis.row(Eigen::Index(m.of_grain[i])).transpose();
          const Eigen::Vector3d a2 = d2.axis.row(Eigen::Index(m2.of_grain[i])).transpose();
          if (!a1.allFinite() || !a2.allFinite()) continue;
          const Eigen::Vector3d t1(truth["ax"].values[i], truth["ay"].values[i],
                                   truth["az"].values[i]);
          const Eigen::Vector3d t2(truth2["ax"].values[i], truth2["ay"].values[i],
                                   truth2["az"].values[i]);
          rotation_error.push_back(std::abs(single_axis_angle(a1, a2) - single_axis_angle(t1, t2)) /
                                   kDegree);
        }

        const double axis_pct =
            100.0 * double(fit_error.size()) / double(std::max<std::size_t>(found, 1));
        const double lab_pct = 100.0 * double(lab_found) / double(std::max<std::size_t>(found, 1));
        const double precision = flagged ? double(hits) / double(flagged) : NAN;
        const double recall = contacts ? double(hits) / double(contacts) : NAN;
        const double within_pct =
            100.0 * double(within) / double(std::max<std::size_t>(fit_error.size(), 1));
        std::cout << std::fixed << std::setw(2) << int(diameter) << std::setprecision(1)
                  << std::setw(4) << dz << std::setw(4) << int(b) << std::setw(7) << found
                  << std::setprecision(2) << std::setw(8) << axis_pct << std::setw(9)
                  << percentile(fit_error, 0.5) << std::setw(6) << percentile(fit_error, 0.95)
                  << std::setw(10) << lab_pct << std::setw(7) << percentile(lab_error, 0.5)
                  << std::setw(7) << percentile(lab_error, 0.95) << std::setw(10)
                  << percentile(sigma, 0.5) << std::setw(8) << within_pct << std::setw(10)
                  << contacts << std::setw(8) << flagged << std::setw(6) << precision
                  << std::setw(7) << recall << std::setw(10) << percentile(clear_error, 0.5)
                  << std::setw(6) << percentile(clear_error, 0.95) << std::setw(8)
                  << rotation_error.size() << std::setw(7) << percentile(rotation_error, 0.5)
                  << std::setw(6) << percentile(rotation_error, 0.95) << std::setw(9)
                  << percentile(along_z_error, 0.5) << "\n"
                  << std::defaultfloat;
        csv << diameter << "," << dz << "," << b << "," << found << "," << fit_error.size() << ","
            << percentile(fit_error, 0.5) << "," << percentile(fit_error, 0.95) << "," << lab_found
            << "," << percentile(lab_error, 0.5) << "," << percentile(lab_error, 0.95) << ","
            << percentile(sigma, 0.5) << "," << within_pct / 100 << "," << contacts << ","
            << flagged << "," << precision << "," << recall << "," << percentile(clear_error, 0.5)
            << "," << percentile(clear_error, 0.95) << "," << rotation_error.size() << ","
            << percentile(rotation_error, 0.5) << "," << percentile(rotation_error, 0.95) << ","
            << percentile(along_z_error, 0.5) << "\n";
        csv.flush();
      }
    }
  }
  return 0;
}
