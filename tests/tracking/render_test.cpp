#include "granmem/tracking/render.hpp"

#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <random>

#include "checks.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/table.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/tracking/render_run.hpp"
#include "granmem/tracking/stack.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

using testing::random_unit_vector;

// A stack of n^3 voxels of size `voxel` with voxel (0,0,0) at the origin.
RenderOptions box(std::int64_t nx, std::int64_t ny, std::int64_t nz,
                  Eigen::Vector3d voxel = Eigen::Vector3d::Ones()) {
  RenderOptions o;
  o.voxel_size = voxel;
  o.origin = Eigen::Vector3d::Zero();
  o.size = std::array<std::int64_t, 3>{nx, ny, nz};
  o.length_unit = "mm";
  return o;
}

// Clean 16-bit rendering: quantisation (1/65535) is the only error left.
RenderOptions clean(RenderOptions o) {
  o = o.without_artefacts();
  o.bits = 16;
  return o;
}

// Grain fraction of each voxel read back from the image: 1 - normalised intensity.
std::vector<double> dark_fraction(const Stack& s, const RenderOptions& o) {
  std::vector<double> phi;
  for (std::uint16_t v : s.voxels) {
    const double intensity = v / double(s.max_value());
    phi.push_back((o.fluid() - intensity) / (o.fluid() - o.grain()));
  }
  return phi;
}

double dark_volume(const Stack& s, const RenderOptions& o) {
  double sum = 0;
  for (double f : dark_fraction(s, o))
    sum += f;
  return sum * o.voxel_size->prod();
}

Eigen::Vector3d dark_centroid(const Stack& s, const RenderOptions& o) {
  const std::vector<double> phi = dark_fraction(s, o);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double total = 0;
  for (std::int64_t z = 0; z < s.nz; ++z) {
    for (std::int64_t y = 0; y < s.ny; ++y) {
      for (std::int64_t x = 0; x < s.nx; ++x) {
        const double f = phi[s.index(x, y, z)];
        sum += f * Eigen::Vector3d(double(x), double(y), double(z));
        total += f;
      }
    }
  }
  return sum / total;
}

double holed_volume(double radius, double hole_fraction) {
  const double h2 = radius * radius * (1 - hole_fraction * hole_fraction);
  return 4.0 / 3 * M_PI * h2 * std::sqrt(h2);
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v)
    s += x;
  return s / double(v.size());
}

double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v)
    s += (x - m) * (x - m);
  return std::sqrt(s / double(v.size() - 1));
}

std::vector<double> values(const Stack& s) {
  return std::vector<double>(s.voxels.begin(), s.voxels.end());
}

TEST(Render, IsolatedGrainHasTheVolumeOfASphereLessItsHole) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> offset(-0.5, 0.5);
  for (const Eigen::Vector3d& voxel : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1.5)}) {
    for (double radius : {5.0, 9.0}) {
      // 24^3 voxels: the largest grain (r 9, plus the sampling's one voxel) stays inside.
      const RenderOptions o = clean(box(24, 24, 24, voxel));
      RenderedGrain g;
      g.centre = Eigen::Vector3d(11.5 + offset(rng), 11.5 + offset(rng), 11.5 + offset(rng))
                     .cwiseProduct(voxel);
      g.radius = radius;
      g.axis = random_unit_vector(rng);
      Table truth;
      const double v = dark_volume(render_scan({g}, o, &truth), o);
      ASSERT_EQ(truth["edge"].values[0], 0);
      EXPECT_NEAR(v / holed_volume(radius, 0.3), 1.0, 1e-3) << "radius " << radius;
    }
  }
}

TEST(Render, CentroidFollowsSubVoxelPositionsWithoutLocking) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> offset(-0.5, 0.5);
  for (const Eigen::Vector3d& voxel : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1.5)}) {
    const RenderOptions o = clean(box(18, 18, 14, voxel));
    double worst = 0;
    for (int trial = 0; trial < 12; ++trial) {
      RenderedGrain g;
      g.centre = Eigen::Vector3d(8.5 + offset(rng), 8.5 + offset(rng), 6.5 * voxel.z());
      g.centre.z() += offset(rng) * voxel.z();
      g.radius = 5;  // a 10 px grain: the smallest, where partial volumes matter most
      g.axis = random_unit_vector(rng);
      Table truth;
      const Stack s = render_scan({g}, o, &truth);
      const Eigen::Vector3d expected(truth["x"].values[0], truth["y"].values[0],
                                     truth["z"].values[0]);
      worst = std::max(worst, (dark_centroid(s, o) - expected).cwiseAbs().maxCoeff());
    }
    // Sampled with a box (each voxel its own partial volume), the centroid would swing by up
    // to 0.003 voxel with the sub-voxel position; with the tent it stays within 1e-4.
    EXPECT_LT(worst, 1e-4) << "voxel z " << voxel.z();
  }
}

TEST(Render, HoleLiesAlongTheAxis) {
  // The hole alone: the grain drawn without its hole less the grain drawn with it. (Masking
  // the holed image with a sphere of voxel centres would cut the hole's ends at whole voxels
  // and move its centroid by a few 0.01 voxel.)
  std::mt19937 rng(8);
  for (const Eigen::Vector3d& voxel : {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1.5)}) {
    RenderOptions o = clean(box(22, 22, 16, voxel));
    // Without the hole the sphere's surface is split less finely, and drawn ~1e-3 voxel
    // wider; this tolerance makes that negligible against the hole's 560 voxels.
    o.edge_tolerance = 2e-4;
    RenderOptions solid = o;
    solid.hole_fraction = 0;
    for (int trial = 0; trial < 3; ++trial) {
      RenderedGrain g;
      g.centre = Eigen::Vector3d(10.3, 10.6, 7.4 * voxel.z());
      g.radius = 8;
      g.axis = random_unit_vector(rng);
      const std::vector<double> holed = dark_fraction(render_scan({g}, o), o);
      const std::vector<double> whole = dark_fraction(render_scan({g}, solid), o);
      const Stack& s = render_scan({}, o);  // for the indexing only
      Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
      Eigen::Vector3d first = Eigen::Vector3d::Zero();
      double total = 0;
      for (std::int64_t z = 0; z < s.nz; ++z) {
        for (std::int64_t y = 0; y < s.ny; ++y) {
          for (std::int64_t x = 0; x < s.nx; ++x) {
            const Eigen::Vector3d p =
                Eigen::Vector3d(double(x), double(y), double(z)).cwiseProduct(voxel) - g.centre;
            const double w = whole[s.index(x, y, z)] - holed[s.index(x, y, z)];
            first += w * p;
            second += w * p * p.transpose();
            total += w;
          }
        }
      }
      // The hole bored through the sphere: its volume is the sphere less the holed grain.
      EXPECT_NEAR(total * voxel.prod() / (4.0 / 3 * M_PI * 512 - holed_volume(8, 0.3)), 1.0, 1e-3);
      const Eigen::Vector3d m = first / total;
      // The tent sampling adds its variance, voxel^2 / 6 per axis, to the hole's; anisotropic
      // voxels would otherwise tilt the principal axis by ~0.3 degrees.
      const Eigen::Matrix3d sampling = (voxel.array().square() / 6).matrix().asDiagonal();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(second / total - m * m.transpose() -
                                                               sampling);
      const Eigen::Vector3d principal = eig.eigenvectors().col(2);
      const double degrees = std::acos(std::min(1.0, std::abs(principal.dot(g.axis)))) * 180 / M_PI;
      EXPECT_LT(degrees, 0.1);
      EXPECT_LT(m.norm(), 1e-3);  // centred on the grain (lengths here: x voxels)
    }
  }
}

TEST(Render, TouchingGrainsAddTheirVolumes) {
  const RenderOptions o = clean(box(30, 18, 18));
  RenderedGrain a, b;
  a.centre = {8.3, 8.7, 8.4};
  a.radius = 6;
  a.axis = Eigen::Vector3d(0, 1, 1).normalized();
  b = a;
  b.id = 1;
  b.centre.x() += 12;  // touching at one point
  b.axis = Eigen::Vector3d(1, 0, 1).normalized();
  const double both = dark_volume(render_scan({a, b}, o), o);
  EXPECT_NEAR(both / (2 * holed_volume(6, 0.3)), 1.0, 2e-3);
  // Overlapping (a soft-sphere contact): no voxel darker than a grain.
  b.centre.x() -= 1;
  const Stack s = render_scan({a, b}, o);
  for (double f : dark_fraction(s, o))
    ASSERT_LE(f, 1.0 + 1e-4);
}

TEST(Render, BlurKeepsTheMean) {
  // The grain stays farther than the blur's reach (4 sigma) from every border, so none of
  // its light is blurred out of the stack.
  RenderOptions o = clean(box(32, 32, 40));
  // Levels on whole grey values: with 0.75 and 0.15 every sharp voxel of fluid or grain
  // rounds down by 0.25, while the blurred edges round either way, a bias of ~1e-6 in the
  // mean that is the quantisation's, not the blur's.
  o.fluid_level = 49151.0 / 65535;
  o.grain_level = 9830.0 / 65535;
  RenderedGrain g;
  g.centre = {15.2, 16.1, 19.7};
  g.radius = 7;
  const Stack sharp = render_scan({g}, o);
  o.blur_sigma = Eigen::Vector3d(1.0, 1.3, 2.0);
  const Stack blurred = render_scan({g}, o);
  // What is left: the rounding of the ~6000 edge voxels, 0.29 grey values each at random.
  EXPECT_NEAR(mean(values(blurred)) / mean(values(sharp)), 1.0, 1e-7);
  EXPECT_NE(sharp.voxels, blurred.voxels);
  // And the centre stays.
  EXPECT_LT((dark_centroid(blurred, o) - dark_centroid(sharp, o)).norm(), 1e-4);
}

TEST(Render, AttenuationFollowsTheBeam) {
  RenderOptions o = clean(box(48, 6, 3));
  o.attenuation = 0.02;
  const double fluid = o.fluid() * 65535;
  const Stack s = render_scan({}, o);
  for (std::int64_t x = 0; x < s.nx; ++x) {
    double sum = 0;
    for (std::int64_t z = 0; z < s.nz; ++z) {
      for (std::int64_t y = 0; y < s.ny; ++y)
        sum += s.at(x, y, z);
    }
    EXPECT_NEAR(sum / double(s.ny * s.nz), fluid * std::exp(-0.02 * (x + 0.5)), 0.5);
  }
  o.size = std::array<std::int64_t, 3>{5, 40, 2};
  o.beam = Beam::minus_y;  // enters at the last row
  const Stack t = render_scan({}, o);
  for (std::int64_t y = 0; y < t.ny; ++y) {
    EXPECT_NEAR(t.at(2, y, 1), fluid * std::exp(-0.02 * (39.5 - y)), 0.5);
  }
}

TEST(Render, SliceMeansFlickerWithTheSetSigma) {
  RenderOptions o = clean(box(6, 6, 400));
  o.flicker = 0.05;
  const Stack s = render_scan({}, o);
  std::vector<double> slice_means;
  for (std::int64_t z = 0; z < s.nz; ++z) {
    double sum = 0;
    for (std::int64_t i = 0; i < s.nx * s.ny; ++i)
      sum += s.slice(z)[i];
    slice_means.push_back(sum / double(s.nx * s.ny));
  }
  EXPECT_NEAR(mean(slice_means) / (o.fluid() * 65535), 1.0, 0.01);
  EXPECT_NEAR(stddev(slice_means) / mean(slice_means), 0.05, 0.05 * 0.15);
}

TEST(Render, StreaksAreLinesAlongTheBeamWithTheSetStrength) {
  RenderOptions o = clean(box(5, 200, 300));
  o.streaks_per_slice = 2;
  o.streak_strength = 0.2;
  o.streak_width = 1.5;
  const Stack s = render_scan({}, o);
  const double fluid = o.fluid() * 65535;
  double excess = 0;
  for (std::int64_t z = 0; z < s.nz; ++z) {
    for (std::int64_t y = 0; y < s.ny; ++y) {
      for (std::int64_t x = 1; x < s.nx; ++x)
        ASSERT_EQ(s.at(x, y, z), s.at(0, y, z));
      ASSERT_GE(s.at(0, y, z), fluid - 0.5);  // streaks only brighten
      excess += s.at(0, y, z) / fluid - 1;
    }
  }
  // Mean brightening: streaks per slice * mean strength * the area of a Gaussian profile.
  const double expected = 2 * 0.1 * std::sqrt(2 * M_PI) * 1.5 / 200;
  EXPECT_NEAR(excess / double(s.ny * s.nz) / expected, 1.0, 0.15);
}

TEST(Render, WallIsALineThroughEverySlice) {
  RenderOptions o = clean(box(20, 10, 4));
  o.wall = WallLine{0, 6.25, 2.0, 0.95};  // covers x in [5.25, 7.25]
  const Stack s = render_scan({}, o);
  const double full = 65535, fluid = o.fluid() * full, wall = 0.95 * full;
  EXPECT_NEAR(s.at(5, 3, 2), fluid + 0.25 * (wall - fluid), 0.5);
  EXPECT_NEAR(s.at(6, 7, 0), wall, 0.5);
  EXPECT_NEAR(s.at(7, 0, 3), fluid + 0.75 * (wall - fluid), 0.5);
  EXPECT_NEAR(s.at(8, 0, 3), fluid, 0.5);
}

TEST(Render, NoiseHasTheSetSigma) {
  RenderOptions o = clean(box(64, 64, 16));
  o.fluid_level = 0.5;
  o.read_noise = 0.01;
  o.gain = 1e-4;
  const std::vector<double> v = values(render_scan({}, o));
  EXPECT_NEAR(mean(v) / 65535, 0.5, 2e-4);
  EXPECT_NEAR(stddev(v) / 65535 / std::sqrt(0.01 * 0.01 + 1e-4 * 0.5), 1.0, 0.02);
  // Shot noise alone is Poisson: variance = gain * signal, for few and for many photons.
  // (4 and 40 photons: both ways of drawing Poisson numbers.)
  o.fluid_level = 0.2;
  o.read_noise = 0;
  for (double gain : {0.05, 0.005}) {
    o.gain = gain;
    const std::vector<double> w = values(render_scan({}, o));
    EXPECT_NEAR(mean(w) / 65535, 0.2, 2e-3) << "gain " << gain;
    const double variance = std::pow(stddev(w) / 65535, 2);
    EXPECT_NEAR(variance / (gain * 0.2), 1.0, 0.03) << "gain " << gain;
  }
}

TEST(Render, EightAndSixteenBits) {
  RenderOptions o = box(20, 20, 20).without_artefacts();
  RenderedGrain g;
  g.centre = {10, 10, 10};
  g.radius = 7;
  g.axis = {0, 0, 1};
  for (int bits : {8, 16}) {
    o.bits = bits;
    const Stack s = render_scan({g}, o);
    EXPECT_EQ(s.bits, bits);
    const double full = bits == 8 ? 255 : 65535;
    EXPECT_EQ(s.at(0, 0, 0), std::floor(0.75 * full + 0.5));     // fluid
    EXPECT_EQ(s.at(14, 10, 10), std::floor(0.15 * full + 0.5));  // grain
    EXPECT_EQ(s.at(10, 10, 10), std::floor(0.75 * full + 0.5));  // hole
  }
  // Noise clipped at full scale: an 8-bit stack stays within 0-255.
  o.bits = 8;
  o.fluid_level = 0.99;
  o.read_noise = 0.1;
  const Stack noisy = render_scan({g}, o);
  EXPECT_LE(*std::max_element(noisy.voxels.begin(), noisy.voxels.end()), 255);
  EXPECT_EQ(*std::max_element(noisy.voxels.begin(), noisy.voxels.end()), 255);
}

TEST(Render, BrightGrainsHaveNoHole) {
  RenderOptions o = clean(box(20, 20, 20));
  o.polarity = Polarity::bright_grains;
  RenderedGrain g;
  g.centre = {10, 10, 10};
  g.radius = 7;
  g.axis = {0, 0, 1};
  const Stack s = render_scan({g}, o);
  EXPECT_EQ(s.at(10, 10, 10), std::floor(0.7 * 65535 + 0.5));  // on the axis: grain
  EXPECT_EQ(s.at(10, 10, 15), std::floor(0.7 * 65535 + 0.5));  // the tent reaches r 6.2
  EXPECT_EQ(s.at(0, 0, 0), std::floor(0.1 * 65535 + 0.5));
  // The whole sphere is bright: its volume, hole included.
  EXPECT_NEAR(dark_volume(s, o) / (4.0 / 3 * M_PI * 343), 1.0, 2e-3);
}

std::vector<RenderedGrain> a_few_grains() {
  std::vector<RenderedGrain> grains;
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 8; ++i) {
    RenderedGrain g;
    g.id = 100 + i;
    g.centre = Eigen::Vector3d(4 + 24 * u(rng), 4 + 24 * u(rng), 3 + 18 * u(rng));
    g.radius = 4 + 2 * u(rng);
    g.axis = random_unit_vector(rng);
    grains.push_back(g);
  }
  return grains;
}

TEST(Render, SameSeedSameImageWhateverTheThreadsAndBlocks) {
  RenderOptions o = box(32, 32, 24, {1, 1, 1.5});  // every artefact on, at its default
  o.wall = WallLine{};
  o.wall->position = 30;
  o.streaks_per_slice = 3;
  const std::vector<RenderedGrain> grains = a_few_grains();
  const Stack reference = render_scan(grains, o);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const Stack one_thread = render_scan(grains, o);
  omp_set_num_threads(3);
  o.slices_per_block = 2;
  const Stack small_blocks = render_scan(grains, o);
  omp_set_num_threads(threads);
  EXPECT_EQ(one_thread.voxels, reference.voxels);
  EXPECT_EQ(small_blocks.voxels, reference.voxels);
  o.seed = 2;
  EXPECT_NE(render_scan(grains, o).voxels, reference.voxels);
}

TEST(Render, TruthTableMatchesTheGrains) {
  RenderOptions o = box(32, 32, 20, {0.5, 0.5, 0.75});
  o.origin = Eigen::Vector3d(1, 2, 3);
  o.frame = 4;
  std::vector<RenderedGrain> grains = a_few_grains();
  grains[0].centre = Eigen::Vector3d(1.5, 9, 9);  // cut by the border x = -1/2
  grains[1].axis = Eigen::Vector3d(0, 0, 2);      // normalised in the truth
  grains[2].axis = Eigen::Vector3d::Constant(std::nan(""));
  Table truth;
  const Stack s = render_scan(grains, o, &truth);
  ASSERT_EQ(truth.rows(), grains.size());
  EXPECT_EQ(truth["x"].unit, "voxel");
  for (std::size_t i = 0; i < grains.size(); ++i) {
    const RenderedGrain& g = grains[i];
    EXPECT_EQ(truth["frame"].values[i], 4);
    EXPECT_EQ(truth["particle"].values[i], double(g.id));
    EXPECT_DOUBLE_EQ(truth["x"].values[i], (g.centre.x() - 1) / 0.5);
    EXPECT_DOUBLE_EQ(truth["y"].values[i], (g.centre.y() - 2) / 0.5);
    EXPECT_DOUBLE_EQ(truth["z"].values[i], (g.centre.z() - 3) / 0.75);
    EXPECT_DOUBLE_EQ(truth["radius"].values[i], g.radius / 0.5);
    const Eigen::Vector3d c =
        (g.centre - Eigen::Vector3d(1, 2, 3)).cwiseQuotient(Eigen::Vector3d(0.5, 0.5, 0.75));
    const Eigen::Vector3d r = g.radius * Eigen::Vector3d(2, 2, 1 / 0.75);
    const bool cut = ((c - r).array() < -0.5).any() ||
                     ((c + r).array() > Eigen::Array3d(31.5, 31.5, 19.5)).any();
    EXPECT_EQ(truth["edge"].values[i], cut ? 1 : 0);
  }
  EXPECT_EQ(truth["edge"].values[0], 1);
  EXPECT_DOUBLE_EQ(truth["az"].values[1], 1.0);
  EXPECT_TRUE(std::isnan(truth["ax"].values[2]));
  EXPECT_DOUBLE_EQ(truth["ax"].values[3], grains[3].axis.x());
  // The stack records where it lies.
  ASSERT_TRUE(s.voxel_size.has_value());
  EXPECT_EQ(*s.voxel_size, Eigen::Vector3d(0.5, 0.5, 0.75));
  EXPECT_EQ(s.unit, "mm");
}

TEST(Render, StackAroundTheGrainsWhenNotGiven) {
  RenderOptions o;
  o.margin = 3;
  std::vector<RenderedGrain> grains = a_few_grains();
  const ScanGeometry g = scan_geometry(grains, o);
  // Median diameter over 20 px (the mean of the middle two radii for an even count).
  std::vector<double> r;
  for (const auto& grain : grains)
    r.push_back(grain.radius);
  std::sort(r.begin(), r.end());
  const double median_r =
      r.size() % 2 ? r[r.size() / 2] : 0.5 * (r[r.size() / 2 - 1] + r[r.size() / 2]);
  EXPECT_DOUBLE_EQ(g.voxel_size.x(), 2 * median_r / 20);
  EXPECT_DOUBLE_EQ(g.voxel_size.z(), g.voxel_size.x());
  for (const auto& grain : grains) {
    const Eigen::Vector3d c = g.to_voxels(grain.centre);
    const Eigen::Vector3d n(double(g.nx), double(g.ny), double(g.nz));
    const double rv = grain.radius / g.voxel_size.x();
    EXPECT_TRUE(((c.array() - rv) >= 2.5).all());
    EXPECT_TRUE(((c.array() + rv) <= n.array() - 3.5).all());
  }
  o.voxel_size = Eigen::Vector3d(1, 1, 1.5);
  const ScanGeometry h = scan_geometry(grains, o);
  EXPECT_EQ(h.voxel_size, *o.voxel_size);
}

TEST(Render, GrainsFromATrajectoryFrame) {
  RunHeader header;
  header.id = {7, 8, 9};
  header.radius = {1.0, 1.5, 2.0};
  Frame frame = Frame::unknown(header);
  frame.position << 0, 0, 0, 1, 1, 1, 2, 2, 2;
  // No axes, no orientations: random axes, seeded.
  const std::vector<RenderedGrain> random = rendered_grains(frame, header, 5);
  ASSERT_EQ(random.size(), 3u);
  EXPECT_EQ(random[1].id, 8);
  EXPECT_EQ(random[2].radius, 2.0);
  EXPECT_NEAR(random[0].axis.norm(), 1.0, 1e-12);
  EXPECT_EQ(rendered_grains(frame, header, 5)[0].axis, random[0].axis);
  EXPECT_NE(rendered_grains(frame, header, 6)[0].axis, random[0].axis);
  EXPECT_NE(random[1].axis, random[0].axis);
  // Orientations: the body z axis (a quarter turn about y takes z to x).
  header.has_orientation = true;
  Frame oriented = Frame::unknown(header);
  oriented.position = frame.position;
  const double h = std::sqrt(0.5);
  for (int i = 0; i < 3; ++i)
    oriented.orientation.row(i) << h, 0, h, 0;
  oriented.position.row(1).setConstant(std::nan(""));  // not seen: left out
  const std::vector<RenderedGrain> turned = rendered_grains(oriented, header);
  ASSERT_EQ(turned.size(), 2u);
  EXPECT_EQ(turned[1].id, 9);
  EXPECT_NEAR((turned[0].axis - Eigen::Vector3d::UnitX()).norm(), 0, 1e-12);
  // Axes come first where known.
  header.has_axis = true;
  Frame with_axes = Frame::unknown(header);
  with_axes.position = frame.position;
  with_axes.orientation = oriented.orientation;
  with_axes.axis.row(0) << 0, 3, 4;
  const std::vector<RenderedGrain> axed = rendered_grains(with_axes, header);
  EXPECT_NEAR((axed[0].axis - Eigen::Vector3d(0, 0.6, 0.8)).norm(), 0, 1e-12);
  EXPECT_NEAR((axed[1].axis - Eigen::Vector3d::UnitX()).norm(), 0, 1e-12);  // axis NaN
  // A grain seen without a radius cannot be drawn.
  header.radius[2] = std::nan("");
  EXPECT_NE(testing::error_message([&] { rendered_grains(with_axes, header); }).find("grain 9"),
            std::string::npos);
}

TEST(Render, BadOptionsSayWhich) {
  RenderOptions o = box(8, 8, 8);
  o.bits = 12;
  EXPECT_NE(testing::error_message([&] { render_scan({}, o); }).find("bits must be 8 or 16"),
            std::string::npos);
  o.bits = 8;
  o.hole_fraction = 1.2;
  EXPECT_NE(testing::error_message([&] { render_scan({}, o); }).find("hole_fraction"),
            std::string::npos);
  RenderOptions no_size;
  EXPECT_NE(testing::error_message([&] { render_scan({}, no_size); }).find("no grains"),
            std::string::npos);
  RenderedGrain flat;
  flat.radius = 0;
  EXPECT_NE(testing::error_message([&] { render_scan({flat}, box(8, 8, 8)); }).find("radius"),
            std::string::npos);
}

}  // namespace
}  // namespace granmem

namespace granmem {
namespace {

// render as one call: the frame found by its label, the scan and its truth written, the
// report; a frame the run does not have named with the frames it has, nothing written.
class RenderRun : public testing::TempDirTest {};

TEST_F(RenderRun, TheFrameByItsLabelDrawnAndWritten) {
  Trajectories run;
  run.header.length_unit = "mm";
  run.header.id = {1, 2};
  run.header.radius = {2.5, 2.5};
  for (std::int64_t step : {10, 20}) {
    Frame f = Frame::unknown(run.header);
    f.step = step;
    f.position << 5, 5, 5, 10.5, 5, 5;
    run.frames.push_back(f);
  }
  write_trajectories(path("run.h5"), run);
  RenderRunOptions o;
  o.run = path("run.h5");
  o.frame = 20;
  o.out = path("scan.tif");
  o.truth = path("truth.csv");
  o.render.diameter_px = 10;
  o.voxel_size = "0.5,0.5,0.5mm";
  const RenderSummary s = render_run(o);
  EXPECT_EQ(s.grains, 2u);
  EXPECT_EQ(s.voxel_size, Eigen::Vector3d(0.5, 0.5, 0.5));
  EXPECT_EQ(s.Report().rfind("rendered 2 grains of frame 20 of ", 0), 0u) << s.Report();
  const Stack back = read_stack(o.out);
  EXPECT_EQ(back.nx, s.nx);
  EXPECT_EQ(read_csv(o.truth, {"x", "y", "z"}).table.rows(), 2u);

  o.frame = 15;
  o.out = path("none.tif");
  o.truth.clear();
  EXPECT_THROW(
      {
        try {
          render_run(o);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find("has no such frame; its frames are 10 to 20"),
                    std::string::npos)
              << e.what();
          throw;
        }
      },
      Error);
  EXPECT_FALSE(std::filesystem::exists(o.out));
}

TEST_F(RenderRun, ARunsScansShareTheContainersFrame) {
  // A run in a container: grain 1 stays, grain 2 rises, so the frames' grains span
  // different heights. Each frame drawn alone, grain 1 sits at the same voxel in both, its
  // first voxel `margin` voxels below the container's corner (a scanner does not move
  // with the grains; a stack centred on each frame's grains moved by half the change).
  Trajectories run;
  run.header.length_unit = "mm";
  run.header.id = {1, 2};
  run.header.radius = {2.5, 2.5};
  Box container;
  container.edges = Eigen::Vector3d(20, 20, 30);
  run.header.box = container;
  for (auto [step, z] : {std::pair{10, 5.0}, std::pair{20, 17.3}}) {
    Frame f = Frame::unknown(run.header);
    f.step = step;
    f.position << 5, 5, 2.5, 12, 6, z;
    run.frames.push_back(f);
  }
  write_trajectories(path("run.h5"), run);
  RenderRunOptions o;
  o.run = path("run.h5");
  o.render = o.render.without_artefacts();
  o.voxel_size = "0.5,0.5,0.75mm";
  std::vector<Eigen::Vector3d> first;
  for (std::int64_t frame : {10, 20}) {
    o.frame = frame;
    o.out = path("scan" + std::to_string(frame) + ".tif");
    o.truth = path("truth" + std::to_string(frame) + ".csv");
    render_run(o);
    const Table truth = read_csv(o.truth, {"x", "y", "z", "edge"}).table;
    first.emplace_back(truth["x"].values[0], truth["y"].values[0], truth["z"].values[0]);
    EXPECT_EQ(truth["edge"].values, std::vector<double>(2, 0.0)) << "a grain cut, frame " << frame;
  }
  EXPECT_EQ(first[0], first[1]);
  const double margin = o.render.margin;
  EXPECT_NEAR(first[0].x(), 5 / 0.5 + margin, 1e-9);
  EXPECT_NEAR(first[0].z(), 2.5 / 0.75 + margin, 1e-9);
}

TEST_F(RenderRun, ARunsFramesShareOneVoxelSize) {
  // Grains of 2.5, 3 and 3.5 mm; the last has no position in frame 20. Each frame drawn
  // at the run's median radius (3 mm: 0.5 mm pixels at 12 pixels a diameter), not at its
  // own grains' (frame 20's median is 2.75 mm).
  Trajectories run;
  run.header.length_unit = "mm";
  run.header.id = {1, 2, 3};
  run.header.radius = {2.5, 3, 3.5};
  for (std::int64_t step : {10, 20}) {
    Frame f = Frame::unknown(run.header);
    f.step = step;
    f.position << 5, 5, 5, 12, 5, 5, 20, 5, 5;
    if (step == 20) f.position.row(2).setConstant(std::nan(""));
    run.frames.push_back(f);
  }
  write_trajectories(path("run.h5"), run);
  RenderRunOptions o;
  o.run = path("run.h5");
  o.render = o.render.without_artefacts();
  o.render.diameter_px = 12;
  o.render.slice_spacing_ratio = 1.5;
  for (std::int64_t frame : {10, 20}) {
    o.frame = frame;
    o.out = path("scan" + std::to_string(frame) + ".tif");
    const RenderSummary s = render_run(o);
    EXPECT_NEAR(s.voxel_size.x(), 0.5, 1e-12) << "frame " << frame;
    EXPECT_NEAR(s.voxel_size.z(), 0.75, 1e-12) << "frame " << frame;
  }
}

// validate() before the run is read: the defaults (with a run and --out) pass; a bad
// drawing option or --voxel-size is one line naming it, and nothing is written.
TEST_F(RenderRun, ValidateNamesTheBadOptionBeforeTheRunIsRead) {
  RenderRunOptions o;
  EXPECT_EQ(testing::error_message([&] { o.validate(); }),
            "render: no run to draw (a trajectory store)");
  o.run = path("not_there.h5");
  EXPECT_EQ(testing::error_message([&] { o.validate(); }),
            "render: no --out (the TIFF stack to write)");
  o.out = path("scan.tif");
  EXPECT_NO_THROW(o.validate());
  o.voxel_size = "0.5,-1,0.5mm";
  EXPECT_EQ(testing::error_message([&] { render_run(o); }),
            "--voxel-size '0.5,-1,0.5mm': sizes must be positive");
  o.voxel_size.clear();
  o.render.flicker = -0.5;
  EXPECT_EQ(testing::error_message([&] { render_run(o); }),
            "render: flicker must be >= 0, got -0.5");
  EXPECT_FALSE(std::filesystem::exists(o.out));
}

}  // namespace
}  // namespace granmem
