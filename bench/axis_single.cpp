// Diagnostic: noiseless single grains rendered by render_scan (the PSF only, 16 bit), at
// polar angles 5-85 deg from z (three azimuths each, sub-voxel offsets): the whole-grain
// model fit's axis error, then the hole-axis refit's error and its signed part in polar
// angle (+: away from z), the blurs and radius it finds (voxels).
//
//   axis_single [diameter 12] [z ratio 1.5] [psf across 1.0] [psf along z 1.5]
//               [1: the refit started from the true centre and radius]
#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <random>

#include "granmem/rotation/single_axis_rotation.hpp"
#include "granmem/tracking/grain_fit.hpp"
#include "granmem/tracking/hole_axis.hpp"
#include "granmem/tracking/render.hpp"

using namespace granmem;
constexpr double kDegree = M_PI / 180;

int main(int argc, char** argv) {
  const double diameter = argc > 1 ? std::atof(argv[1]) : 12;
  const double dz = argc > 2 ? std::atof(argv[2]) : 1.5;
  const Eigen::Vector3d psf(argc > 3 ? std::atof(argv[3]) : 1.0,
                            argc > 3 ? std::atof(argv[3]) : 1.0,
                            argc > 4 ? std::atof(argv[4]) : 1.5);
  const bool true_centre = argc > 5 && std::atoi(argv[5]) != 0;
  const double px = 1.0 / diameter;
  const Eigen::Vector3d vs(px, px, dz * px);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uni(0, 1);
  std::cout
      << "theta phi | whole tilt | refit err dpol | blur across along_z | centre err | radius\n";
  double sum_abs = 0;
  int n = 0;
  for (double theta : {5., 15., 25., 35., 45., 55., 65., 75., 85.}) {
    double mean_dpol = 0, mean_err = 0;
    for (double phi : {10., 50., 100.}) {
      RenderOptions o = RenderOptions{}.without_artefacts();
      o.blur_sigma = psf;
      o.bits = 16;
      o.voxel_size = vs;
      o.origin = Eigen::Vector3d::Zero();
      const int nxy = int(diameter * 2), nz = int(diameter * 2 / dz);
      o.size = std::array<std::int64_t, 3>{nxy, nxy, nz};
      RenderedGrain g;
      g.radius = 0.5;
      g.centre = Eigen::Vector3d((nxy / 2 + uni(rng)) * px, (nxy / 2 + uni(rng)) * px,
                                 (nz / 2 + uni(rng)) * dz * px);
      g.axis = Eigen::Vector3d(std::sin(theta * kDegree) * std::cos(phi * kDegree),
                               std::sin(theta * kDegree) * std::sin(phi * kDegree),
                               std::cos(theta * kDegree));
      const Stack s = render_scan({g}, o, nullptr);
      const double fluid = o.fluid(), grain = o.grain();
      auto window = [&](const Eigen::Vector3d& c, double reach) {
        GrainWindow w;
        for (std::int64_t z = 0; z < s.nz; ++z)
          for (std::int64_t y = 0; y < s.ny; ++y)
            for (std::int64_t x = 0; x < s.nx; ++x) {
              const Eigen::Vector3d p =
                  Eigen::Vector3d(double(x), double(y), double(z)).cwiseProduct(vs);
              if ((p - c).norm() > reach) continue;
              w.points.push_back(p);
              w.intensity.push_back((double(s.at(x, y, z)) / 65535 - grain) / (fluid - grain));
            }
        return w;
      };
      HoledSphere start;
      start.centre = g.centre + Eigen::Vector3d(0.02, -0.01, 0.015);
      start.radius = 0.5 * 0.97;
      start.hole = 0.3;
      start.axis = (g.axis + Eigen::Vector3d(0.03, -0.02, 0.01)).normalized();
      start.blur = 1.0 * px;
      const GrainFit whole = fit_grain(window(g.centre, 0.5 + 3 * psf.z() * vs.z()), start);
      GrainFit f = whole;
      if (true_centre) {
        f.sphere.centre = g.centre;
        f.sphere.radius = 0.5;
      }
      const HoleAxisFit r = fit_hole_axis(window(f.sphere.centre, 0.8 * f.sphere.radius), f);
      Eigen::Vector3d a = r.axis;
      if (a.dot(g.axis) < 0) a = -a;
      const double err = single_axis_angle(a, g.axis) / kDegree;
      const double dpol = std::acos(std::min(1.0, std::abs(a.z()))) / kDegree - theta;
      mean_dpol += dpol / 3;
      mean_err += err / 3;
      sum_abs += err;
      ++n;
      std::cout << theta << " " << phi << " | "
                << single_axis_angle(whole.sphere.axis, g.axis) / kDegree << " | " << err << " "
                << dpol << " | " << r.blur_across / px << " " << r.blur_along_z / px << " | "
                << (whole.sphere.centre - g.centre).norm() / px << " | " << whole.sphere.radius / px
                << " refit " << r.radius / px << "\n";
    }
    std::cout << "theta " << theta << " mean err " << mean_err << " mean dpol " << mean_dpol
              << "\n";
  }
  std::cout << "mean error " << sum_abs / n << "\n";
}
