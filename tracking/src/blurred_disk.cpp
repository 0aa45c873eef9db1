#include "blurred_disk.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "granmem/tracking/holed_sphere.hpp"

namespace granmem {
namespace {

constexpr double kStep = 1.0 / 32, kMaxY = 16, kMaxX = kMaxY + 8;
constexpr int kNy = int(kMaxY / kStep) + 1, kNx = int(kMaxX / kStep) + 1;

// e^-z I0(z), the exponentially scaled modified Bessel function.
double bessel_i_scaled(double z) {
  if (z < 500) return std::cyl_bessel_i(0.0, z) * std::exp(-z);
  return (1 + 1 / (8 * z) + 9 / (128 * z * z)) / std::sqrt(2 * M_PI * z);  // A&S 9.7.1
}

// dP/dy = y exp(-(x^2 + y^2)/2) I0(x y): the Gaussian's density on the rim.
double dp_dy(double x, double y) {
  return y * std::exp(-0.5 * (x - y) * (x - y)) * bessel_i_scaled(x * y);
}

struct Table {
  std::vector<float> value;  // [ix * kNy + iy]
  Table() : value(std::size_t(kNx * kNy)) {
    for (int ix = 0; ix < kNx; ++ix) {
      const double x = ix * kStep;
      double p = 0;  // P(x, 0) = 0; then dP/dy integrated by Simpson's rule, 4 panels a step
      for (int iy = 1; iy < kNy; ++iy) {
        const double h = kStep / 4, y0 = (iy - 1) * kStep;
        double sum = dp_dy(x, y0) + dp_dy(x, y0 + kStep);
        for (int k = 1; k < 4; ++k)
          sum += (k % 2 ? 4 : 2) * dp_dy(x, y0 + k * h);
        p += sum * h / 3;
        value[std::size_t(ix * kNy + iy)] = float(p);
      }
    }
  }
};

}  // namespace

DiskFraction blurred_disk(double x, double y) {
  x = std::abs(x);
  if (!(x < kMaxX + kMaxY) || !(y > 0)) return {0, 0, 0};  // far, no hole, or not a number
  // Eight widths outside or inside the rim: Phi(-8) ~ 6e-16 from 0 or 1.
  if (x - y > 8) return {0, 0, 0};
  if (y - x > 8) return {1, 0, 0};
  if (y >= kMaxY) {
    // A wide disk: the step's profile and its curvature's first correction (half the
    // curvature times the Gaussian's spread along the edge), P ~ Phi(w) - phi(w) / (2 y).
    const double w = y - x;
    const NormalCdfPdf s = normal_cdf_pdf(w);
    const double c = 1 / (2 * y);
    // d/dw [Phi - c phi] = phi (1 + c w); dc/dy = -c / y.
    const double dw = s.pdf * (1 + c * w);
    return {s.cdf - c * s.pdf, -dw, dw + s.pdf * c / y};
  }
  if (x >= kMaxX - kStep) return {0, 0, 0};
  static const Table table;
  const double fx = x / kStep, fy = y / kStep;
  const int ix = std::min(int(fx), kNx - 2), iy = std::min(int(fy), kNy - 2);
  const double tx = fx - ix, ty = fy - iy;
  const std::size_t a = std::size_t(ix * kNy + iy), b = a + std::size_t(kNy);
  const double v00 = table.value[a], v01 = table.value[a + 1];
  const double v10 = table.value[b], v11 = table.value[b + 1];
  // Bilinear, and its own slopes: the fit's Jacobian is then that of the values it fits.
  return {(1 - tx) * ((1 - ty) * v00 + ty * v01) + tx * ((1 - ty) * v10 + ty * v11),
          ((1 - ty) * (v10 - v00) + ty * (v11 - v01)) / kStep,
          ((1 - tx) * (v01 - v00) + tx * (v11 - v10)) / kStep};
}

}  // namespace granmem
