#include "blurred_disk.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "granmem/tracking/holed_sphere.hpp"

namespace granmem {
namespace {

constexpr double kStep = BlurredDisk::kStep;
constexpr int kNy = BlurredDisk::kNy, kNx = BlurredDisk::kNx;

// e^-z I0(z), the exponentially scaled modified Bessel function.
double bessel_i_scaled(double z) {
  if (z < 500) return std::cyl_bessel_i(0.0, z) * std::exp(-z);
  return (1 + 1 / (8 * z) + 9 / (128 * z * z)) / std::sqrt(2 * M_PI * z);  // A&S 9.7.1
}

// dP/dy = y exp(-(x^2 + y^2)/2) I0(x y): the Gaussian's density on the rim.
double dp_dy(double x, double y) {
  return y * std::exp(-0.5 * (x - y) * (x - y)) * bessel_i_scaled(x * y);
}

// By columns of one disk radius (y): a grain's evaluations read a few columns at many
// offsets, which then stay in the cache (by rows, each read missed it: a third of the time).
struct Table {
  std::vector<float> value;  // [iy * kNx + ix]
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
        value[std::size_t(iy * kNx + ix)] = float(p);
      }
    }
  }
};

}  // namespace

BlurredDisk::BlurredDisk(double y) : y_(y) {
  if (!(y > 0 && y < kMaxY)) return;
  static const Table table;
  const double fy = y / kStep;
  const int iy = std::min(int(fy), kNy - 2);
  inside_table_ = true;
  ty_ = fy - iy;
  below_ = table.value.data() + std::size_t(iy) * std::size_t(kNx);
  above_ = below_ + kNx;
}

// A wide disk: the step's profile and its curvature's first correction (half the
// curvature times the Gaussian's spread along the edge), P ~ Phi(w) - phi(w) / (2 y).
DiskFraction BlurredDisk::wide(double x) const {
  const double w = y_ - x;
  const NormalCdfPdf s = normal_cdf_pdf(w);
  const double c = 1 / (2 * y_);
  // d/dw [Phi - c phi] = phi (1 + c w); dc/dy = -c / y.
  const double dw = s.pdf * (1 + c * w);
  return {s.cdf - c * s.pdf, -dw, dw + s.pdf * c / y_};
}

}  // namespace granmem
