// The linker: hand-worked scans, then dense random packings (packing fraction 0.6) moved
// by known fields (compression, shear, a shear band, drift) plus random per-grain
// displacements, detection noise and missing and spurious detections.

#include "granmem/tracking/link.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "granmem/core/error.hpp"
#include "link_packing.hpp"

namespace granmem::testing {
namespace {

Detections scan(std::int64_t frame, const std::vector<Eigen::Vector3d>& points,
                double radius = 0.5) {
  Detections d;
  d.frame = frame;
  d.length_unit = "mm";
  for (const Eigen::Vector3d& p : points)
    d.add(p, radius, 1.0, false);
  return d;
}

Eigen::Vector3d at(const Trajectories& run, std::size_t frame, std::size_t grain) {
  return run.frames[frame].position.row(Eigen::Index(grain)).transpose();
}

// ------------------------------------------------------------------ hand-worked cases

TEST(Link, ThreeGrainsThreeScans) {
  // Grains 1 diameter apart, each moving 0.2 in its own direction; the detections come in
  // another order in each scan.
  const std::vector<Detections> scans = {
      scan(0, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}),
      scan(1, {{0.2, 1, 0}, {0, 0, 0.2}, {1, 0.2, 0}}),
      scan(2, {{1, 0.4, 0}, {0.4, 1, 0}, {0, 0, 0.4}}),
  };
  LinkOptions options;
  LinkSummary summary;
  const Trajectories run = link_scans(scans, options, &summary);
  ASSERT_EQ(run.header.grain_count(), 3u);
  ASSERT_EQ(run.frames.size(), 3u);
  EXPECT_EQ(run.header.length_unit, "mm");
  EXPECT_EQ(run.header.time_unit, "cycle");
  EXPECT_EQ(run.header.id, (std::vector<std::int64_t>{0, 1, 2}));
  EXPECT_EQ(run.header.radius, (std::vector<double>{0.5, 0.5, 0.5}));
  EXPECT_EQ(at(run, 2, 0), Eigen::Vector3d(0, 0, 0.4));
  EXPECT_EQ(at(run, 2, 1), Eigen::Vector3d(1, 0.4, 0));
  EXPECT_EQ(at(run, 2, 2), Eigen::Vector3d(0.4, 1, 0));
  EXPECT_EQ(at(run, 1, 2), Eigen::Vector3d(0.2, 1, 0));
  EXPECT_EQ(run.frames[2].step, 2);
  EXPECT_DOUBLE_EQ(summary.max_displacement, 0.7);  // 0.7 median diameter
  EXPECT_EQ(summary.tracks, 3u);
  ASSERT_EQ(summary.scans.size(), 3u);
  EXPECT_EQ(summary.scans[0].started, 3u);
  for (std::size_t t = 1; t < 3; ++t) {
    EXPECT_EQ(summary.scans[t].linked, 3u);
    EXPECT_EQ(summary.scans[t].started, 0u);
    EXPECT_EQ(summary.scans[t].ended, 0u);
    EXPECT_DOUBLE_EQ(summary.scans[t].linked_fraction(), 1.0);
  }
}

TEST(Link, GlobalAssignmentBeatsNearestNeighbour) {
  // Grains A at 0 and B at 1 (along x), detections P at 0.55 and Q at 1.5, reach 0.6.
  // The nearest pair is B-P (0.45): taking it first leaves A nothing, costing
  // 0.45^2 + 0.6^2 = 0.5625. Linking A-P and B-Q costs 0.55^2 + 0.5^2 = 0.5525: the optimum.
  const std::vector<Detections> scans = {
      scan(0, {{0, 0, 0}, {1, 0, 0}}),
      scan(1, {{1.5, 0, 0}, {0.55, 0, 0}}),
  };
  LinkOptions options;
  options.max_displacement = 0.6;
  options.estimate_drift = false;
  options.local_field = false;
  LinkSummary summary;
  const Trajectories run = link_scans(scans, options, &summary);
  ASSERT_EQ(run.header.grain_count(), 2u);
  EXPECT_EQ(at(run, 1, 0), Eigen::Vector3d(0.55, 0, 0));
  EXPECT_EQ(at(run, 1, 1), Eigen::Vector3d(1.5, 0, 0));
  EXPECT_EQ(summary.scans[1].ambiguous, 2u);
  EXPECT_NEAR(summary.scans[1].rms_residual, std::sqrt(0.5525 / 2), 1e-12);
}

TEST(Link, MemoryRelinksAGrainMissingOneScan) {
  const std::vector<Eigen::Vector3d> a = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  std::vector<Eigen::Vector3d> b = a;
  b.erase(b.begin() + 1);  // grain 1 not seen in scan 1
  std::vector<Eigen::Vector3d> c = a;
  c[1] += Eigen::Vector3d(0.1, 0, 0);
  const std::vector<Detections> scans = {scan(0, a), scan(1, b), scan(2, c)};
  LinkOptions options;
  options.memory = 1;
  LinkSummary summary;
  const Trajectories run = link_scans(scans, options, &summary);
  ASSERT_EQ(run.header.grain_count(), 4u);  // the same track, no new one
  EXPECT_TRUE(at(run, 1, 1).array().isNaN().all());
  EXPECT_EQ(at(run, 2, 1), Eigen::Vector3d(1.1, 0, 0));
  EXPECT_EQ(summary.scans[1].unlinked, 1u);
  EXPECT_EQ(summary.scans[1].kept, 1u);
  EXPECT_EQ(summary.scans[1].unlinked_tracks, (std::vector<std::int64_t>{1}));
  EXPECT_EQ(summary.scans[2].relinked, 1u);
  EXPECT_EQ(summary.scans[2].linked, 4u);
  EXPECT_EQ(summary.scans[2].previous, 3u);

  // Without memory the grain starts a new track.
  options.memory = 0;
  const Trajectories forgetful = link_scans(scans, options, &summary);
  ASSERT_EQ(forgetful.header.grain_count(), 5u);
  EXPECT_EQ(summary.scans[1].ended, 1u);
  EXPECT_EQ(summary.scans[2].started, 1u);
  EXPECT_EQ(summary.scans[2].new_detections.size(), 1u);
  EXPECT_EQ(at(forgetful, 2, 4), Eigen::Vector3d(1.1, 0, 0));

  // A grain unseen for more scans than the memory is given up.
  options.memory = 1;
  const std::vector<Detections> longer = {scan(0, a), scan(1, b), scan(2, b), scan(3, c)};
  const Trajectories gone = link_scans(longer, options, &summary);
  EXPECT_EQ(gone.header.grain_count(), 5u);
  EXPECT_EQ(summary.scans[1].kept, 1u);
  EXPECT_EQ(summary.scans[2].ended, 1u);
  EXPECT_EQ(summary.scans[3].started, 1u);
}

TEST(Link, ReportsWhatCouldNotBeLinked) {
  // Four grains move by (0.1, 0, 0); grain 2 leaves; a detection appears far from all.
  const std::vector<Detections> scans = {
      scan(0, {{0, 0, 0}, {1, 0, 0}, {0.3, 1, 0}, {0.5, 0.4, 0.9}}),
      scan(1, {{9, 9, 9}, {0.1, 0, 0}, {1.1, 0, 0}, {0.6, 0.4, 0.9}}),
  };
  LinkSummary summary;
  const Trajectories run = link_scans(scans, LinkOptions{}, &summary);
  const ScanLinks& s = summary.scans[1];
  EXPECT_EQ(s.previous, 4u);
  EXPECT_EQ(s.linked, 3u);
  EXPECT_EQ(s.unlinked, 1u);
  EXPECT_EQ(s.unlinked_tracks, (std::vector<std::int64_t>{2}));
  EXPECT_EQ(s.new_detections, (std::vector<std::size_t>{0}));
  EXPECT_EQ(s.started, 1u);
  EXPECT_DOUBLE_EQ(s.linked_fraction(), 0.75);
  EXPECT_EQ(s.first_new_track, 4);
  ASSERT_EQ(run.header.grain_count(), 5u);
  EXPECT_EQ(at(run, 1, 4), Eigen::Vector3d(9, 9, 9));
  EXPECT_EQ(at(run, 1, 3), Eigen::Vector3d(0.6, 0.4, 0.9));
}

TEST(Link, CarriesAxesAndHoleContacts) {
  Detections a = scan(0, {{0, 0, 0}, {1, 0, 0}});
  Detections b = scan(1, {{1, 0, 0.1}, {0, 0, 0.1}});
  for (Detections* d : {&a, &b}) {
    d->has_axis = true;
    d->axis = Vectors3::Zero(2, 3);
    d->axis_quality = {1, 1};
    d->hole_contact = {0, 0};
  }
  a.axis.row(0) << 0, 0, 1;
  a.axis.row(1) << 1, 0, 0;
  b.axis.row(0) << 0, 1, 0;   // grain 1
  b.axis.row(1) << 0, 0, -1;  // grain 0
  b.hole_contact = {1, 0};
  b.radius = {0.4, 0.6};
  const Trajectories run = link_scans({a, b}, LinkOptions{});
  ASSERT_TRUE(run.header.has_axis);
  ASSERT_TRUE(run.header.has_hole_contact);
  EXPECT_EQ(Eigen::Vector3d(run.frames[1].axis.row(0).transpose()), Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(Eigen::Vector3d(run.frames[1].axis.row(1).transpose()), Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(run.frames[1].hole_contact, (std::vector<std::uint8_t>{0, 1}));
  EXPECT_DOUBLE_EQ(run.header.radius[0], 0.55);  // mean of 0.5 and 0.6
  EXPECT_DOUBLE_EQ(run.header.radius[1], 0.45);
  // Scans without standard errors give a store without them.
  EXPECT_FALSE(run.header.has_position_error);
  EXPECT_FALSE(run.header.has_axis_error);

  // Each detection's standard errors go with it to its track; a scan without them (the
  // first: axis errors unknown) leaves NaN.
  a.position_error.row(0) << 0.01, 0.02, 0.03;
  b.position_error.row(0) << 0.04, 0.05, 0.06;  // grain 1
  b.axis_error = {0.002, 0.001};
  const Trajectories with_errors = link_scans({a, b}, LinkOptions{});
  ASSERT_TRUE(with_errors.header.has_position_error);
  ASSERT_TRUE(with_errors.header.has_axis_error);
  EXPECT_EQ(Eigen::Vector3d(with_errors.frames[0].position_error.row(0).transpose()),
            Eigen::Vector3d(0.01, 0.02, 0.03));
  EXPECT_TRUE(with_errors.frames[0].position_error.row(1).array().isNaN().all());
  EXPECT_EQ(Eigen::Vector3d(with_errors.frames[1].position_error.row(1).transpose()),
            Eigen::Vector3d(0.04, 0.05, 0.06));
  EXPECT_TRUE(std::isnan(with_errors.frames[0].axis_error[0]));
  EXPECT_EQ(with_errors.frames[1].axis_error, (std::vector<double>{0.001, 0.002}));
}

TEST(Link, RejectsBadInput) {
  const Detections a = scan(0, {{0, 0, 0}});
  EXPECT_THROW(link_scans({}, LinkOptions{}), Error);
  Detections other_unit = scan(1, {{0, 0, 0}});
  other_unit.length_unit = "voxel";
  EXPECT_THROW(link_scans({a, other_unit}, LinkOptions{}), Error);
  Detections other_voxel = scan(1, {{0, 0, 0}});
  other_voxel.voxel_size = Eigen::Vector3d(0.1, 0.1, 0.1);
  EXPECT_THROW(link_scans({a, other_voxel}, LinkOptions{}), Error);
  EXPECT_THROW(link_scans({a, scan(0, {{0, 0, 0}})}, LinkOptions{}), Error);  // frame again
  Detections nan = scan(1, {{0, 0, 0}});
  nan.position(0, 1) = std::nan("");
  EXPECT_THROW(link_scans({a, nan}, LinkOptions{}), Error);
  LinkOptions negative;
  negative.max_displacement = -1;
  EXPECT_THROW(link_scans({a}, negative), Error);
  LinkOptions no_memory;
  no_memory.memory = -1;
  EXPECT_THROW(link_scans({a}, no_memory), Error);
  try {
    link_scans({a, other_unit}, LinkOptions{});
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("one length unit"), std::string::npos) << e.what();
  }
}

TEST(Link, OneScanAndEmptyScans) {
  LinkSummary summary;
  const Trajectories one = link_scans({scan(3, {{0, 0, 0}, {1, 0, 0}})}, LinkOptions{}, &summary);
  EXPECT_EQ(one.header.grain_count(), 2u);
  EXPECT_EQ(one.frames.size(), 1u);
  EXPECT_EQ(one.frames[0].step, 3);
  const Trajectories gap = link_scans({scan(0, {{0, 0, 0}}), scan(1, {}), scan(2, {{0.1, 0, 0}})},
                                      LinkOptions{}, &summary);
  EXPECT_EQ(gap.header.grain_count(), 1u);  // back from memory across the empty scan
  EXPECT_EQ(summary.scans[1].unlinked, 1u);
  EXPECT_EQ(summary.scans[2].relinked, 1u);
}

// ------------------------------------------------------------------ dense packings

// One packing of 2000 grains of diameter 1 at packing fraction 0.6, made once.
const std::vector<Eigen::Vector3d>& packing(double* edge = nullptr) {
  static double L = 0;
  static const std::vector<Eigen::Vector3d> x = random_packing(2000, 0.6, 11, &L);
  if (edge) *edge = L;
  return x;
}

TEST(LinkPacking, PackingIsDense) {
  double L = 0;
  const auto& x = packing(&L);
  EXPECT_GT(closest_pair(x), 0.99);
  EXPECT_NEAR(double(x.size()) * 3.14159265358979 / 6 / (L * L * L), 0.6, 1e-12);
}

// The scans of `x` and of `x` moved by `field` plus a random displacement uniform in a ball
// of `random` diameters; returns the score of the links.
template <class Field>
LinkScore link_moved(const std::vector<Eigen::Vector3d>& x, Field field, double random,
                     double noise, double missing, std::size_t extra, std::uint32_t seed,
                     const LinkOptions& options, LinkSummary* summary) {
  std::mt19937 rng(seed);
  std::vector<Eigen::Vector3d> y(x.size());
  for (std::size_t i = 0; i < x.size(); ++i)
    y[i] = x[i] + field(x[i]) + in_ball(rng, random);
  const Scan a = scan_of(x, 0, rng, noise, missing, extra);
  const Scan b = scan_of(y, 1, rng, noise, missing, extra);
  const Trajectories run = link_scans({a.detections, b.detections}, options, summary);
  return score_links(run, 0, 1, a, b);
}

TEST(LinkPacking, CompressionAndShearWithRandomMotion) {
  // The wall at y = L moves in by 1.2 diameters, the top slides by 0.6 in x and the whole
  // sample drifts; each grain also moves randomly by up to 0.3 diameter.
  double L = 0;
  const auto& x = packing(&L);
  const auto field = [L](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(0.3 + 0.6 * p.y() / L, -1.2 * p.y() / L, -0.1);
  };
  LinkSummary summary;
  const LinkScore s = link_moved(x, field, 0.3, 0, 0, 0, 1, LinkOptions{}, &summary);
  EXPECT_EQ(s.links, x.size());
  EXPECT_EQ(s.correct, x.size());
  const ScanLinks& r = summary.scans[1];
  EXPECT_EQ(r.linked, x.size());
  // The fit recovers the uniform deformation: d(u_y)/dy = -1.2 / L, d(u_x)/dy = 0.6 / L.
  EXPECT_NEAR(r.gradient(1, 1) * L, -1.2, 0.05);
  EXPECT_NEAR(r.gradient(0, 1) * L, 0.6, 0.05);
}

TEST(LinkPacking, NoiseMissingAndSpuriousDetections) {
  double L = 0;
  const auto& x = packing(&L);
  const auto field = [L](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(0.4 * p.y() / L, -0.8 * p.y() / L, 0.2 * p.z() / L);
  };
  LinkSummary summary;
  const LinkScore s = link_moved(x, field, 0.3, 0.02, 0.01, 10, 2, LinkOptions{}, &summary);
  EXPECT_GE(s.fraction_correct(), 0.999) << s.correct << " of " << s.links;
  EXPECT_GE(s.fraction_found(), 0.999) << s.correct << " of " << s.possible;
}

TEST(LinkPacking, ShearBand) {
  // A shear band across the middle: the top half slides by +0.5, the bottom by -0.5, over
  // a width of two diameters; not a uniform deformation, followed by the local field.
  double L = 0;
  const auto& x = packing(&L);
  const auto field = [L](const Eigen::Vector3d& p) {
    return Eigen::Vector3d(0.5 * std::tanh((p.y() - L / 2) / 2), 0, 0);
  };
  LinkSummary summary;
  const LinkScore s = link_moved(x, field, 0.3, 0.02, 0, 0, 3, LinkOptions{}, &summary);
  EXPECT_GE(s.fraction_correct(), 0.999) << s.correct << " of " << s.links;
  EXPECT_GE(s.fraction_found(), 0.999) << s.correct << " of " << s.possible;
}

TEST(LinkPacking, DriftIsRecovered) {
  // A drift of more than a diameter, larger than the max displacement, and small random
  // motion.
  const auto& x = packing();
  const Eigen::Vector3d drift(1.3, -0.4, 0.25);
  LinkOptions options;
  LinkSummary summary;
  const LinkScore s = link_moved(
      x, [&](const Eigen::Vector3d&) { return drift; }, 0.1, 0, 0, 0, 4, options, &summary);
  EXPECT_EQ(s.correct, x.size());
  const ScanLinks& r = summary.scans[1];
  EXPECT_LT((r.drift - drift).norm(), 0.01) << r.drift.transpose();
  EXPECT_LT((r.mean_displacement - drift).norm(), 0.01) << r.mean_displacement.transpose();

  // Without the drift nothing near is right.
  options.estimate_drift = false;
  options.local_field = false;
  const LinkScore off = link_moved(
      x, [&](const Eigen::Vector3d&) { return drift; }, 0.1, 0, 0, 0, 4, options, &summary);
  EXPECT_LT(off.correct, x.size() / 100);
  EXPECT_EQ(summary.scans[1].drift, Eigen::Vector3d::Zero());
}

TEST(LinkPacking, MemoryFollowsTheCompression) {
  // Three scans of a compressing packing; a few grains are missing in the middle one and
  // must rejoin their tracks although the compression moved them on by up to 0.6.
  double L = 0;
  const auto& x = packing(&L);
  std::mt19937 rng(5);
  std::vector<std::vector<Eigen::Vector3d>> at(3, x);
  for (std::size_t t = 1; t < 3; ++t) {
    for (std::size_t i = 0; i < x.size(); ++i)
      at[t][i] =
          at[t - 1][i] + Eigen::Vector3d(0, -0.6 * at[t - 1][i].y() / L, 0) + in_ball(rng, 0.2);
  }
  const Scan s0 = scan_of(at[0], 0, rng), s1 = scan_of(at[1], 1, rng, 0, 0.02),
             s2 = scan_of(at[2], 2, rng);
  LinkSummary summary;
  const Trajectories run =
      link_scans({s0.detections, s1.detections, s2.detections}, LinkOptions{}, &summary);
  const std::size_t missing = x.size() - s1.grain.size();
  ASSERT_GT(missing, 10u);
  EXPECT_EQ(run.header.grain_count(), x.size());
  EXPECT_EQ(summary.scans[2].relinked, missing);
  const LinkScore whole = score_links(run, 0, 2, s0, s2);
  EXPECT_EQ(whole.correct, x.size());
}

}  // namespace
}  // namespace granmem::testing
