// The driven wall's motion over a cycle of period T and amplitude A:
//   asymmetric cosine  y = A/2 (1 - cos 2 pi s/T)      0 -> A -> 0
//   symmetric cosine   y = A/2 sin 2 pi s/T            0 -> A/2 -> -A/2 -> 0
//   asymmetric linear  y = 2A s/T, then 2A (T - s)/T   (triangle, speed 2A/T)
//   symmetric linear   0 -> A/2 -> -A/2 -> 0 at speed 2A/T
// Peak speeds: pi A / T (cosine), 2 A / T (linear). The quasi-static wall speed for inertial
// number I is v = I L sqrt(P / rho) / d.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "checks.hpp"
#include "granmem/sim/wall_drive.hpp"

namespace granmem {
namespace {

using testing::error_message;

std::vector<WallDrive> all_drives() {
  std::vector<WallDrive> out;
  for (DriveSymmetry s : {DriveSymmetry::asymmetric, DriveSymmetry::symmetric}) {
    for (DriveShape h : {DriveShape::cosine, DriveShape::linear}) {
      WallDrive d;
      d.amplitude = 1.5e-3;
      d.period = 0.2;
      d.symmetry = s;
      d.shape = h;
      out.push_back(d);
    }
  }
  return out;
}

double expected_position(const WallDrive& d, double s) {
  const double a = d.amplitude, t = d.period;
  if (d.shape == DriveShape::cosine) {
    return d.symmetry == DriveSymmetry::asymmetric ? 0.5 * a * (1 - std::cos(2 * M_PI * s / t))
                                                   : 0.5 * a * std::sin(2 * M_PI * s / t);
  }
  if (d.symmetry == DriveSymmetry::asymmetric)
    return s < t / 2 ? 2 * a * s / t : 2 * a * (t - s) / t;
  if (s < t / 4) return 2 * a * s / t;
  if (s < 3 * t / 4) return a / 2 - 2 * a * (s - t / 4) / t;
  return -a / 2 + 2 * a * (s - 3 * t / 4) / t;
}

std::string name(const WallDrive& d) {
  return std::string(d.symmetry == DriveSymmetry::asymmetric ? "asymmetric " : "symmetric ") +
         (d.shape == DriveShape::cosine ? "cosine" : "linear");
}

TEST(WallDrive, PositionAndVelocityFollowTheirFormulas) {
  for (const WallDrive& d : all_drives()) {
    SCOPED_TRACE(name(d));
    const double a = d.amplitude, t = d.period, h = 1e-7 * t;
    for (int k = 0; k <= 1000; ++k) {
      const double s = t * k / 1000.0;
      const auto [y, v] = d.at(s);
      EXPECT_NEAR(y, expected_position(d, s), 1e-12 * a) << "s " << s;
      // The velocity is the position's derivative (away from the linear drive's corners).
      const double phase = std::fmod(4 * s / t, 1.0);
      if (d.shape == DriveShape::linear && (phase < 1e-3 || phase > 1 - 1e-3)) continue;
      if (s < h || s > t - h) continue;
      const double slope = (d.at(s + h).first - d.at(s - h).first) / (2 * h);
      EXPECT_NEAR(v, slope, 1e-5 * d.peak_speed()) << "s " << s;
    }
  }
}

TEST(WallDrive, CycleStartsAndEndsAtRestPositionAndPeaksAtFullCompression) {
  for (const WallDrive& d : all_drives()) {
    SCOPED_TRACE(name(d));
    EXPECT_EQ(d.at(0).first, 0);
    EXPECT_NEAR(d.at(d.period).first, 0, 1e-15);
    const bool asymmetric = d.symmetry == DriveSymmetry::asymmetric;
    EXPECT_DOUBLE_EQ(d.full_compression_time(), (asymmetric ? 0.5 : 0.25) * d.period);
    const double full = asymmetric ? d.amplitude : 0.5 * d.amplitude;
    EXPECT_NEAR(d.at(d.full_compression_time()).first, full, 1e-15);
    // Strongest compression, and (symmetric) strongest extension by as much.
    double highest = -1, lowest = 1;
    for (int k = 0; k <= 4000; ++k) {
      highest = std::max(highest, d.at(d.period * k / 4000.0).first);
      lowest = std::min(lowest, d.at(d.period * k / 4000.0).first);
    }
    EXPECT_NEAR(highest, full, 1e-15);
    EXPECT_NEAR(lowest, asymmetric ? 0.0 : -full, 1e-15);
  }
}

TEST(WallDrive, PeakSpeedAndPeriodForSpeedAreInverse) {
  for (const WallDrive& d : all_drives()) {
    SCOPED_TRACE(name(d));
    double fastest = 0;
    for (int k = 0; k <= 4000; ++k)
      fastest = std::max(fastest, std::abs(d.at(d.period * k / 4000.0).second));
    EXPECT_NEAR(d.peak_speed(), fastest, 1e-9 * fastest);
    const double expected =
        d.shape == DriveShape::cosine ? M_PI * d.amplitude / d.period : 2 * d.amplitude / d.period;
    EXPECT_DOUBLE_EQ(d.peak_speed(), expected);
    const double period =
        WallDrive::period_for_speed(d.amplitude, d.peak_speed(), d.symmetry, d.shape);
    EXPECT_NEAR(period, d.period, 1e-14 * d.period);
    WallDrive other = d;
    other.period = WallDrive::period_for_speed(d.amplitude, 0.02, d.symmetry, d.shape);
    EXPECT_NEAR(other.peak_speed(), 0.02, 1e-15);
  }
}

TEST(WallDrive, NamesParseAndUnknownNamesAreRefused) {
  EXPECT_EQ(parse_drive_symmetry("asymmetric"), DriveSymmetry::asymmetric);
  EXPECT_EQ(parse_drive_symmetry("symmetric"), DriveSymmetry::symmetric);
  EXPECT_EQ(parse_drive_shape("cosine"), DriveShape::cosine);
  EXPECT_EQ(parse_drive_shape("linear"), DriveShape::linear);
  EXPECT_NE(error_message([] { parse_drive_symmetry("sideways"); }).find("sideways"),
            std::string::npos);
  EXPECT_NE(error_message([] { parse_drive_shape("square"); }).find("square"), std::string::npos);
}

}  // namespace
}  // namespace granmem
