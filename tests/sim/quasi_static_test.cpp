// The protocol's time scale: the lid's pressure and the cycle period of the quasi-static
// limit, against the paper's numbers and the inertial number's definition.
#include <gtest/gtest.h>

#include <cmath>

#include "granmem/sim/quasi_static.hpp"

namespace granmem {
namespace {

constexpr double kG = 9.81, kRho = 1180, kD = 0.005;

TEST(QuasiStatic, ThePapersLidPressesWith436PaAndAReducedBoxKeepsIt) {
  EXPECT_NEAR(kPaperLidPressure, 436.0, 1e-12);
  EXPECT_NEAR(lid_mass_for_pressure(kPaperLidPressure, kG, 0.15, 0.15), 1.0, 1e-14);
  // The 5 cm box of the reduced-scale runs: 1 kg x (5/15)^2.
  EXPECT_NEAR(lid_mass_for_pressure(kPaperLidPressure, kG, 0.05, 0.05), 1.0 / 9, 1e-14);
  EXPECT_NEAR(lid_pressure(lid_mass_for_pressure(250, kG, 0.07, 0.05), kG, 0.07, 0.05), 250, 1e-12);
  // Half the lid's pressure confines the top; without a lid, half one layer's weight.
  EXPECT_NEAR(confining_stress(436, kRho, kG, kD), 218, 1e-12);
  EXPECT_NEAR(confining_stress(0, kRho, kG, kD), 0.5 * kRho * 0.6 * kG * kD, 1e-12);
}

TEST(QuasiStatic, WallSpeedGivesTheRequestedInertialNumber) {
  // The paper's setting: I = 1e-3, 15 cm box, 5 mm grains, 436 Pa, acrylic: ~1.8 cm/s.
  const double v = quasi_static_wall_speed(1e-3, 0.15, kD, 436, kRho);
  EXPECT_NEAR(v, 0.01824, 1e-5);
  // Back to the inertial number: (v / L) d / sqrt(P / rho).
  EXPECT_NEAR((v / 0.15) * kD / std::sqrt(436.0 / kRho), 1e-3, 1e-15);
  // Linear in I, inversely proportional to d.
  EXPECT_NEAR(quasi_static_wall_speed(2e-3, 0.15, 0.01, 436, kRho), v, 1e-15);
}

TEST(QuasiStatic, ThePapersCycleAndItsScaling) {
  WallDrive drive;  // asymmetric cosine, 1 % of the 15 cm box
  drive.amplitude = 0.0015;
  const double stress = confining_stress(kPaperLidPressure, kRho, kG, kD);
  const double period = quasi_static_period(1e-3, drive, 0.15, kD, stress, kRho);
  // pi A / v with v = I L sqrt(P/2 / rho) / d: 0.3655 s, 14,618 steps of 25 us.
  EXPECT_NEAR(period, M_PI * 0.0015 / (1e-3 * 0.15 * std::sqrt(218.0 / kRho) / kD), 1e-12);
  EXPECT_EQ(std::llround(period / 25e-6), 14618);
  // The peak strain rate, times d / sqrt(P / rho), is the inertial number.
  drive.period = period;
  EXPECT_NEAR(drive.peak_speed() / 0.15 * kD / std::sqrt(stress / kRho), 1e-3, 1e-15);
  // A box 3x smaller with the amplitude the same fraction of it, under the same pressure:
  // the same strain rate, the same period.
  WallDrive small = drive;
  small.amplitude = 0.0005;
  EXPECT_NEAR(quasi_static_period(1e-3, small, 0.05, kD, stress, kRho), period, 1e-12);
  // Four times the pressure relaxes twice as fast; ten times the inertial number, ten times
  // shorter.
  EXPECT_NEAR(quasi_static_period(1e-3, drive, 0.15, kD, 4 * stress, kRho), period / 2, 1e-12);
  EXPECT_NEAR(quasi_static_period(1e-2, drive, 0.15, kD, stress, kRho), period / 10, 1e-12);
}

}  // namespace
}  // namespace granmem
