#include "granmem/tracking/locate.hpp"
#include "granmem/tracking/locate_scan.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "checks.hpp"
#include "granmem/core/error.hpp"
#include "granmem/rotation/single_axis_rotation.hpp"
#include "locate_score.hpp"

// locate against the truth of rendered dense packings (packing fraction 0.58, grains of 12
// voxels with their holes, RenderOptions' default artefacts: blur, shot and read noise,
// attenuation, flicker, streaks; 8-bit), cut by the stack's border as real scans are. The
// accuracy and speed on larger scans are measured by bench/locate_bench.cpp
// (docs/BENCHMARKS.md).
namespace granmem {
namespace {

using testing::error_message;
using testing::LocateScore;
using testing::packing_scan;
using testing::PackingScan;
using testing::percentile;
using testing::score_locate;

constexpr double kPhi = 0.58;

// Prints what a test measured, for the log.
void report(const char* what, const LocateScore& s) {
  std::cout << what << ": " << s.interior_found << "/" << s.interior << " interior grains found, "
            << s.spurious << " spurious of " << s.detections << " detections; RMS error x "
            << s.rms.x() << ", y " << s.rms.y() << ", z " << s.rms.z() << " voxel; bias "
            << s.bias.transpose() << "; locking amplitude " << s.locking.transpose() << "; KS p "
            << s.ks_p.transpose() << "; axis error median " << s.axis_percentile(0.5)
            << " deg, 90% " << s.axis_percentile(0.9) << " deg; standard errors: RMS "
            << s.rms_standard_error.transpose() << " voxel, axis median "
            << percentile(s.axis_standard_error, 0.5) << " deg\n";
}

// What locate's standard errors say of its actual errors: per axis, the RMS error over the
// RMS standard error, and the hole axis' median angle error over the median its standard
// error predicts (a tilt of sigma in each of two directions: a Rayleigh angle, median
// 1.177 sigma). The axes' are their size (1.07-1.30 measured); the centres' run 1.6-3.5x
// small, as the centres' errors are the model's misfit more than the camera's noise (with
// 4x its variance they stay as they were, docs/BENCHMARKS.md "Standard errors"): bounded
// so.
void expect_standard_errors_to_scale(const LocateScore& s) {
  const Eigen::Array3d ratio = s.rms.array() / s.rms_standard_error.array();
  ASSERT_GT(s.axis_standard_error.size(), 50u);
  const double axis_ratio =
      percentile(s.axis_error_seen, 0.5) / (1.177 * percentile(s.axis_standard_error, 0.5));
  std::cout << "actual over standard error: centres " << ratio.transpose() << ", axes "
            << axis_ratio << "\n";
  for (int a = 0; a < 3; ++a) {
    EXPECT_GT(ratio[a], 1.2) << "axis " << a;
    EXPECT_LT(ratio[a], 4.5) << "axis " << a;
  }
  EXPECT_GT(axis_ratio, 0.8);
  EXPECT_LT(axis_ratio, 1.8);
}

// Every interior grain found, nothing else, each well within a tenth of a voxel per axis
// and with no pull towards the voxel grid.
void expect_accurate(const LocateScore& s) {
  EXPECT_GT(s.interior, 50u);
  EXPECT_EQ(s.interior_found, s.interior);
  EXPECT_EQ(s.spurious, 0u);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LT(s.rms[a], 0.1) << "axis " << a;
    EXPECT_LT(std::abs(s.bias[a]), 0.03) << "axis " << a;
    EXPECT_LT(s.locking[a], 0.04) << "axis " << a;  // first harmonic vs the fractional part
    EXPECT_GT(s.ks_p[a], 1e-4) << "axis " << a;     // fractional parts uniform
  }
}

// Flags against how far each found grain reaches out of the stack (voxels): those cut by
// more than `tolerance` flagged, those clear of the border by more than it not.
void expect_edge_flags(const Detections& d, const Table& truth, const Stack& stack,
                       const Eigen::Vector3d& voxel_size, double tolerance) {
  const testing::LocateMatch m = testing::match_locate(d, truth, voxel_size);
  const Eigen::Vector3d last(double(stack.nx) - 0.5, double(stack.ny) - 0.5,
                             double(stack.nz) - 0.5);
  std::size_t cut = 0;
  for (std::size_t i = 0; i < m.truth.size(); ++i) {
    if (m.of_grain[i] < 0) continue;
    const Eigen::Vector3d r = Eigen::Vector3d::Constant(truth["radius"].values[i] * voxel_size.x())
                                  .cwiseQuotient(voxel_size);
    const Eigen::Vector3d c = m.truth[i];
    const double out = std::max(((r - c).array() - 0.5).maxCoeff(), (c + r - last).maxCoeff());
    const bool flagged = d.edge[std::size_t(m.of_grain[i])] != 0;
    if (out > tolerance) {
      ++cut;
      EXPECT_TRUE(flagged) << "grain at " << c.transpose() << " cut by " << out << " voxel";
    }
    if (out < -tolerance) {
      EXPECT_FALSE(flagged) << "grain at " << c.transpose() << " clear by " << -out << " voxel";
    }
  }
  EXPECT_GT(cut, 10u);
}

TEST(Locate, DensePackingIsotropicVoxels) {
  PackingScan scan = packing_scan(220, kPhi, 12, 1, 11);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  const Stack rendered = stack;
  LocateOptions o;
  o.diameter = 12;
  LocateSummary summary;
  const Detections d = locate(stack, o, &summary);
  const Eigen::Vector3d vs = *scan.options.voxel_size;
  // Positions in the stack's unit.
  EXPECT_EQ(d.length_unit, "mm");
  ASSERT_TRUE(d.voxel_size.has_value());
  EXPECT_EQ(*d.voxel_size, vs);
  EXPECT_EQ(summary.located, d.size());
  const LocateScore s = score_locate(d, truth, vs);
  report("d = 12, isotropic", s);
  expect_accurate(s);
  expect_edge_flags(d, truth, rendered, vs, 0.25);
  // Hole axes: the angle between the fitted and the true line.
  ASSERT_TRUE(d.has_axis);
  EXPECT_EQ(s.axis_degrees.size(), s.interior_found);
  EXPECT_LT(s.axis_percentile(0.5), 0.7);  // 0.48 measured (0.88 before the axis refit)
  EXPECT_LT(s.axis_percentile(0.9), 1.5);
  expect_standard_errors_to_scale(s);
}

TEST(Locate, DensePackingCoarserSlices) {
  // Slices 1.5 voxels apart: the grain is 12 voxels across in x and y, 8 slices in z.
  PackingScan scan = packing_scan(220, kPhi, 12, 1.5, 12);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  ASSERT_TRUE(stack.voxel_size.has_value());
  EXPECT_DOUBLE_EQ(stack.voxel_size->z() / stack.voxel_size->x(), 1.5);
  const Stack rendered = stack;
  LocateOptions o;
  o.diameter = 12;  // along x
  const Detections d = locate(stack, o);
  const Eigen::Vector3d vs = *scan.options.voxel_size;
  EXPECT_EQ(d.length_unit, "mm");
  // Radii in the stack's unit: a diameter of 1 mm. The model fits' run 6 % small under
  // this blur (0.47 mm); corrected by the axis refits' measure of it, within 1 %.
  std::vector<double> radius = d.radius;
  std::nth_element(radius.begin(), radius.begin() + long(radius.size() / 2), radius.end());
  std::cout << "median radius " << radius[radius.size() / 2] << " mm\n";
  EXPECT_NEAR(radius[radius.size() / 2], 0.5, 0.005);
  const LocateScore s = score_locate(d, truth, vs);
  report("d = 12, slices 1.5x coarser (errors in slices along z)", s);
  expect_accurate(s);
  // The blur along z, 2.1x that across, in the model: 0.018 / 0.022 voxel across measured
  // (0.027 / 0.030 with one blur alike in every direction).
  EXPECT_LT(s.rms.x(), 0.026);
  EXPECT_LT(s.rms.y(), 0.026);
  expect_edge_flags(d, truth, rendered, vs, 0.25);
  // Issue 5's bar, median <= 1 deg: the blur along z, 2.1x that across here, tilts a
  // model blurred alike everywhere by ~2.3 deg (median); the axis refit on the inner
  // voxels with a blur of its own along z does not tilt (hole_axis.hpp).
  EXPECT_LT(s.axis_percentile(0.5), 1.0);
  EXPECT_LT(s.axis_percentile(0.9), 2.5);
  expect_standard_errors_to_scale(s);
}

// A rendered dense packing of n grains, `diameter` voxels across, slices `z_ratio`
// voxels apart, located with default options and scored against its truth.
LocateScore locate_packing(std::size_t n, double diameter, double z_ratio, std::uint32_t seed,
                           const char* what) {
  PackingScan scan = packing_scan(n, kPhi, diameter, z_ratio, seed);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  LocateOptions o;
  o.diameter = diameter;
  const LocateScore s = score_locate(locate(stack, o), truth, *scan.options.voxel_size);
  report(what, s);
  return s;
}

TEST(Locate, SmallGrains) {
  // 8 voxels across: the hole, 2.4 voxels wide, reads no brighter than ~0.6 of the fluid
  // under the blur; the fits must still start from its axis (they ran out of iterations
  // from a wrong one, and 1.5 % of the grains were lost).
  const LocateScore s = locate_packing(500, 8, 1, 13, "d = 8, isotropic");
  EXPECT_GT(s.interior, 300u);
  EXPECT_GE(double(s.interior_found), 0.995 * double(s.interior));
  EXPECT_LE(s.spurious, 1u);
  for (int a = 0; a < 3; ++a)
    EXPECT_LT(s.rms[a], 0.1) << "axis " << a;
  EXPECT_LT(s.axis_percentile(0.5), 3.0);
}

TEST(Locate, SmallGrainsCoarseSlices) {
  // 8 voxels across and 5.3 slices deep: neighbours' maxima merge (~1.3 % of the grains
  // give no candidate) and a tenth of the fits need more than 20 iterations. The grains
  // are found in what the others leave unexplained before the passes with neighbours
  // modelled (a fit was pulled into an unexplained grain and lost), and fits are given
  // up to 40 iterations (98.4 % found before both on the bench's scans).
  const LocateScore s = locate_packing(1000, 8, 1.5, 13, "d = 8, 1.5x slices");
  EXPECT_GT(s.interior, 700u);
  EXPECT_GE(double(s.interior_found), 0.99 * double(s.interior));
  EXPECT_LE(s.spurious, 3u);
  for (int a = 0; a < 3; ++a)
    EXPECT_LT(s.rms[a], 0.15) << "axis " << a;
}

// The angles between detected and true hole axes of the interior grains found, degrees,
// with how many of them have no axis.
struct AxisErrors {
  std::vector<double> degrees;
  std::size_t without = 0;
  double percentile(double q) const { return testing::percentile(degrees, q); }
  double median() const { return percentile(0.5); }
};
AxisErrors axis_errors(const Detections& d, const Table& truth, const Eigen::Vector3d& vs) {
  const testing::LocateMatch m = testing::match_locate(d, truth, vs);
  AxisErrors e;
  for (std::size_t i = 0; i < m.truth.size(); ++i) {
    if (m.edge[i] || m.of_grain[i] < 0) continue;
    const Eigen::Vector3d a = d.axis.row(Eigen::Index(m.of_grain[i])).transpose();
    const Eigen::Vector3d t(truth["ax"].values[i], truth["ay"].values[i], truth["az"].values[i]);
    if (a.allFinite()) {
      e.degrees.push_back(single_axis_angle(a, t) * 180 / M_PI);
    } else {
      ++e.without;
    }
  }
  return e;
}

TEST(Locate, FittedAxesBeatTheLabsEstimate) {
  // The lab's classical axis (largest-eigenvalue axis of the bright hole voxels within
  // 0.8 R) is what locate gives without the fit; the fit must do better on the same scan.
  PackingScan scan = packing_scan(300, kPhi, 12, 1, 21);
  Table truth;
  const Stack rendered = render_scan(scan.grains, scan.options, &truth);
  const Eigen::Vector3d vs = *scan.options.voxel_size;
  LocateOptions o;
  o.diameter = 12;
  Stack a = rendered, b = rendered;
  const AxisErrors fitted = axis_errors(locate(a, o), truth, vs);
  o.fit_axis = false;
  const AxisErrors lab = axis_errors(locate(b, o), truth, vs);
  std::cout << "axis error median: fitted " << fitted.median() << " deg, lab " << lab.median()
            << " deg; without an axis " << fitted.without << ", " << lab.without << "\n";
  EXPECT_GT(fitted.degrees.size(), 150u);
  EXPECT_LE(fitted.without, fitted.degrees.size() / 100);  // >= 99 % have one
  EXPECT_LE(lab.without, lab.degrees.size() / 100);
  EXPECT_LT(fitted.median(), 1.0);
  EXPECT_LT(lab.median(), 3.0);
  EXPECT_LT(fitted.median(), 0.75 * lab.median());
}

TEST(Locate, TouchingNeighboursAreReadNeitherCloserNorFarther) {
  // The image of two touching grains is the sum of their blurred grain fractions; a model
  // that multiplies what they leave clear reads the rims they share too bright, and each fit
  // then moves its grain towards its neighbours: touching pairs read ~0.01 voxel close
  // (docs/BENCHMARKS.md, "The misfit's direction"): -0.0081 voxel on these 268 pairs. With
  // the neighbours seen through the exactly blurred image and added, +0.0046, their radius
  // the model fit's plus a sample's median shortfall; at the exact refits' line's
  // (exact_radius.hpp) and the centres refitted twice, +0.0010 (the mean of 268 carries
  // +-0.0017 of the centres' own error).
  PackingScan scan = packing_scan(220, kPhi, 12, 1.5, 12);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  LocateOptions o;
  o.diameter = 12;
  const Eigen::Vector3d vs = *scan.options.voxel_size;
  const testing::LocateMatch m = testing::match_locate(locate(stack, o), truth, vs);
  const testing::NeighbourDistance near = testing::touching_distance_offset(m, vs);
  std::cout << near.pairs << " touching pairs read " << near.offset << " voxel longer\n";
  ASSERT_GT(near.pairs, 100u);
  EXPECT_GT(near.offset, -0.004);
  EXPECT_LT(near.offset, 0.004);
}

TEST(Locate, GrainsWithTheirHoleAlongTheSlicesAreNotLockedToThem) {
  // Every hole within 3 deg of the slices' plane: its wall runs along the slices, 1.2
  // slices from the axis, under a blur along z of about a slice, where the model's plane
  // profile of the wall is not the image's. Fitted with it, the centres locked to the
  // slices: the error along z a sine of the centre's place between two slices, of amplitude
  // 0.042 slice here, 0.045 (28 um) on the default render of 5 mm grains; with the hole's
  // wall left out of the last refit 0.0026, the z RMS 0.044 -> 0.020 slice
  // (docs/BENCHMARKS.md, "Centres locked to the slices by a hole along them").
  PackingScan scan = packing_scan(220, kPhi, 12, 1.5, 41);
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> turn(0, 2 * 3.14159265358979323846), tilt(-0.05, 0.05);
  for (RenderedGrain& g : scan.grains) {
    const double phi = turn(rng);
    g.axis = Eigen::Vector3d(std::cos(phi), std::sin(phi), tilt(rng)).normalized();
  }
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  LocateOptions o;
  o.diameter = 12;
  const LocateScore s = score_locate(locate(stack, o), truth, *scan.options.voxel_size);
  report("holes along the slices", s);
  EXPECT_GT(s.interior_found, 80u);
  EXPECT_LT(s.locking.z(), 0.015);  // first harmonic of the error vs the place between slices
  EXPECT_LT(s.rms.z(), 0.03);       // slices
}

TEST(Locate, AxesUnderABlurWiderThanTheHoleAlongZ) {
  // PSF 1.0 / 1.0 / 1.5 voxel on slices 1.5x coarser: the blur along z, 2.25 voxels of x,
  // is wider than the hole's radius (1.8). The model fits' radius runs ~1 voxel small
  // there; the refit's window follows the refit's radius and the neighbours are seen
  // through the exact image (BENCHMARKS "Hole axes": 0.96 / 2.71 deg on 2000 grains).
  PackingScan scan = packing_scan(260, kPhi, 12, 1.5, 31);
  scan.options.blur_sigma = Eigen::Vector3d(1.0, 1.0, 1.5);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  LocateOptions o;
  o.diameter = 12;
  const AxisErrors e = axis_errors(locate(stack, o), truth, *scan.options.voxel_size);
  std::cout << e.degrees.size() << " interior grains: axis error median " << e.median()
            << " deg, p95 " << e.percentile(0.95) << "; without an axis " << e.without << "\n";
  EXPECT_GT(e.degrees.size(), 150u);
  EXPECT_LE(e.without, e.degrees.size() / 100);
  EXPECT_LT(e.median(), 1.2);          // 1.00 measured on these ~180 grains
  EXPECT_LT(e.percentile(0.95), 3.5);  // 2.82
}

TEST(Locate, CutGrainsHaveNoAxisAndHoleContactsAreFlagged) {
  PackingScan scan = packing_scan(500, kPhi, 12, 1, 5);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  const Eigen::Vector3d vs = *scan.options.voxel_size;
  LocateOptions o;
  o.diameter = 12;
  const Detections d = locate(stack, o);
  ASSERT_TRUE(d.has_axis);
  for (std::size_t k = 0; k < d.size(); ++k) {
    const Eigen::Vector3d a = d.axis.row(Eigen::Index(k)).transpose();
    if (d.edge[k]) {
      EXPECT_FALSE(a.allFinite()) << "detection " << k;
    } else if (a.allFinite()) {
      EXPECT_NEAR(a.norm(), 1, 1e-9);
      EXPECT_GT(d.axis_quality[k], 0);
      EXPECT_LE(d.axis_quality[k], 1);
    }
  }
  // Against the true packing's contacts through a hole.
  const testing::LocateMatch m = testing::match_locate(d, truth, vs);
  const std::size_t n = truth.rows();
  const std::vector<std::uint8_t> contact =
      testing::true_hole_contacts(truth, m, vs, scan.options.hole_fraction);
  std::size_t flagged = 0, real = 0, both = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (m.edge[i] || m.of_grain[i] < 0) continue;
    const bool flag = d.hole_contact[std::size_t(m.of_grain[i])];
    flagged += flag;
    real += contact[i];
    both += flag && contact[i];
  }
  std::cout << "hole contacts: " << real << " true, " << flagged << " flagged, " << both
            << " both\n";
  ASSERT_GT(real, 40u);  // ~ a quarter of the grains: six contacts, each 4.6 % likely
  EXPECT_GE(double(both), 0.75 * double(flagged));  // precision (0.88 on the bench)
  EXPECT_GE(double(both), 0.85 * double(real));     // recall (0.95)
}

TEST(Locate, WithoutVoxelSizeInVoxels) {
  PackingScan scan = packing_scan(120, kPhi, 12, 1, 13);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  stack.voxel_size.reset();
  LocateOptions o;
  o.diameter = 12;
  const Detections d = locate(stack, o);
  EXPECT_EQ(d.length_unit, "voxel");
  EXPECT_FALSE(d.voxel_size.has_value());
  const LocateScore s = score_locate(d, truth, Eigen::Vector3d::Ones());
  report("d = 12, no voxel size", s);
  expect_accurate(s);
}

TEST(Locate, BrightGrainsWithoutHoles) {
  PackingScan scan = packing_scan(180, kPhi, 12, 1, 14);
  scan.options.polarity = Polarity::bright_grains;
  scan.options.hole_fraction = 0;
  for (RenderedGrain& g : scan.grains)
    g.axis = Eigen::Vector3d::Constant(NAN);
  Table truth;
  Stack stack = render_scan(scan.grains, scan.options, &truth);
  LocateOptions o;
  o.diameter = 12;
  o.dark_grains = false;
  o.hole_fraction = 0;
  const Detections d = locate(stack, o);
  EXPECT_FALSE(d.has_axis);
  const LocateScore s = score_locate(d, truth, *scan.options.voxel_size);
  report("d = 12, bright grains, no holes", s);
  expect_accurate(s);
}

// Grains in flat layers, as a packing is against a floor or a wall: the illumination
// correction's levels must not follow the layers (slices between two layers, or through
// their caps, are nearly all fluid, or all partial volumes). Measured before the levels
// were pooled over slices: layers pulled by up to 0.5 voxel along z.
TEST(Locate, LayeredGrainsKeepEachLayersHeight) {
  for (const int layers : {2, 4}) {
    std::mt19937_64 rng{std::uint64_t(layers)};
    std::uniform_real_distribution<double> jitter(-0.2, 0.2);
    std::normal_distribution<double> normal;
    std::vector<RenderedGrain> grains;
    for (int k = 0; k < layers; ++k) {
      for (int j = 0; j < 3; ++j) {
        for (int i = 0; i < 3; ++i) {  // 5 mm grains on a 5.6 mm lattice, jittered
          RenderedGrain g;
          g.id = std::int64_t(grains.size());
          g.centre = Eigen::Vector3d(i, j, k) * 5.6 + Eigen::Vector3d::Constant(4.0) +
                     Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
          g.radius = 2.5;
          g.axis = Eigen::Vector3d(normal(rng), normal(rng), normal(rng)).normalized();
          grains.push_back(g);
        }
      }
    }
    RenderOptions r;
    r.length_unit = "mm";
    r.diameter_px = 10;
    r.seed = 3;
    Table truth;
    Stack stack = render_scan(grains, r, &truth);
    const Eigen::Vector3d vs = *stack.voxel_size;
    LocateOptions o;
    o.diameter = 10;
    const Detections d = locate(stack, o);
    ASSERT_EQ(d.size(), grains.size());
    for (int k = 0; k < layers; ++k) {  // each layer's mean error along z
      double sum = 0;
      for (std::size_t g = std::size_t(9 * k); g < std::size_t(9 * (k + 1)); ++g) {
        const Eigen::Vector3d t(truth["x"].values[g], truth["y"].values[g], truth["z"].values[g]);
        double best = 1e9, dz = 0;
        for (std::size_t i = 0; i < d.size(); ++i) {
          const Eigen::Vector3d found =
              d.position.row(Eigen::Index(i)).transpose().cwiseQuotient(vs);
          if ((found - t).norm() < best) {
            best = (found - t).norm();
            dz = found.z() - t.z();
          }
        }
        EXPECT_LT(best, 0.2) << layers << " layers, grain " << g;
        sum += dz;
      }
      EXPECT_LT(std::abs(sum / 9), 0.08) << layers << " layers, layer " << k;
    }
  }
}

TEST(Locate, DiameterLargerThanTheStackIsAnError) {
  Stack stack(20, 20, 10);
  stack.source = "tiny.tif";
  LocateOptions o;
  o.diameter = 12;  // fits in x and y, not in z
  const std::string message = error_message([&] { locate(stack, o); });
  EXPECT_NE(message.find("tiny.tif"), std::string::npos) << message;
  EXPECT_NE(message.find("larger than the stack"), std::string::npos) << message;
  // With slices twice as far apart, 12 voxels across is 6 slices: it fits.
  stack.voxel_size = Eigen::Vector3d(1, 1, 2);
  stack.unit = "um";
  EXPECT_NO_THROW(locate(stack, o));
  o.diameter = 0;
  EXPECT_NE(error_message([&] { locate(stack, o); }).find("positive"), std::string::npos);
}

// locate_scan's options checked before the stack is read: the diameter's text (a length is
// turned into voxels with each stack's voxel size later) and locate's settings.
TEST(ScanLocateOptions, ValidateNamesTheBadOptionBeforeTheStackIsRead) {
  ScanLocateOptions o;
  o.diameter = "12";
  EXPECT_NO_THROW(o.validate());
  o.diameter = "1.5mm";
  EXPECT_NO_THROW(o.validate());
  o.diameter = "-3";
  EXPECT_EQ(error_message([&] { o.validate(); }), "--diameter '-3': expected a positive diameter");
  o.diameter = "3furlong";
  EXPECT_EQ(error_message([&] { o.validate(); }),
            "--diameter '3furlong': unknown unit furlong (m, cm, mm, um, vox)");
  o.diameter = "12";
  o.locate.passes = 11;
  EXPECT_EQ(error_message([&] { locate_scan("no_such_scan.tif", o); }),
            "locate: passes must be 1 to 10");
}

}  // namespace
}  // namespace granmem

namespace granmem {
namespace {

// locate says each stage as it begins and stops between two when asked (Python's Ctrl-C, a
// signal handler): an Error, nothing returned.
TEST(LocateStages, EachStageIsSaidAndAStopEndsLocateBeforeTheNext) {
  const testing::PackingScan p = testing::packing_scan(30, 0.5, 10, 1, 5);
  const Stack stack = render_scan(p.grains, p.options, nullptr);
  LocateOptions o;
  o.diameter = 10;
  std::vector<std::string> said;
  o.log = [&](const std::string& line) { said.push_back(line); };
  locate(stack, o);
  ASSERT_GE(said.size(), 5u);
  EXPECT_EQ(said[0], "illumination");
  EXPECT_EQ(said[1], "candidates");
  EXPECT_EQ(said[2].rfind("fits: the first pass over ", 0), 0u) << said[2];
  EXPECT_EQ(said[3].rfind("fits: round 2 of up to ", 0), 0u) << said[3];
  EXPECT_EQ(said.back(), "hole axes");

  std::atomic<bool> stop{false};
  o.stop = &stop;
  said.clear();
  o.log = [&](const std::string& line) {
    said.push_back(line);
    if (line.rfind("fits: round 2", 0) == 0) stop = true;
  };
  try {
    locate(stack, o);
    ADD_FAILURE() << "not stopped";
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).rfind("locate: stopped before fits: round 3", 0), 0u)
        << e.what();
  }
  EXPECT_EQ(said.size(), 4u);
  stop = true;
  said.clear();
  EXPECT_THROW(locate(stack, o), Error);
  EXPECT_TRUE(said.empty());  // stopped before the first stage
}

}  // namespace
}  // namespace granmem
