// A scan's locating error read from its contacts: a packing under the paper's lid pressure,
// its centres moved by known normal errors (coarser along z, as a laser sheet's slices
// are), measured against another packing poured under the same load.
#include "granmem/calibration/contact_locating_error.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "granmem/core/error.hpp"
#include "granmem/core/point_index.hpp"
#include "granmem/core/random.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/deposit.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

constexpr double kDiameter = 0.005;

// 400 grains poured into a 3 cm box under 436 Pa; the centres, m.
Vectors3 poured(std::uint64_t seed) {
  DepositOptions pour;
  pour.grains = 400;
  pour.box_side = 0.03;
  pour.lid_mass = 436 * 0.03 * 0.03 / 9.81;
  pour.seed = seed;
  const Simulation sim = deposit(pour, PhysicsOptions{});
  const Grains& g = sim.grains();
  Vectors3 x(Eigen::Index(g.size()), 3);
  for (std::size_t i = 0; i < g.size(); ++i)
    x.row(Eigen::Index(i)) = g.x[i].transpose();
  return x;
}

// `copies` scans of one packing, each centre moved by its own normal error, one after
// another along x far enough apart that no two copies touch.
Vectors3 scanned(const Vectors3& exact, double across, double along_z, int copies,
                 std::uint64_t seed) {
  Random random(seed);
  Vectors3 scans(exact.rows() * copies, 3);
  for (int c = 0; c < copies; ++c) {
    for (Eigen::Index i = 0; i < exact.rows(); ++i) {
      const Eigen::Vector3d e = normal_vector(random);
      scans.row(c * exact.rows() + i) =
          exact.row(i) +
          Eigen::RowVector3d(across * e.x() + c * 0.1, across * e.y(), along_z * e.z());
    }
  }
  return scans;
}

class ContactLocatingErrorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    packing_ = new Vectors3(poured(3));
    reference_ = new Vectors3(poured(4));
  }
  static void TearDownTestSuite() {
    delete packing_;
    delete reference_;
  }
  static Vectors3* packing_;
  static Vectors3* reference_;
};
Vectors3* ContactLocatingErrorTest::packing_ = nullptr;
Vectors3* ContactLocatingErrorTest::reference_ = nullptr;

TEST_F(ContactLocatingErrorTest, ReadsAScansErrorsAcrossTheSlicesAndAlongZApart) {
  // 10 um across, 20 um along z: a 12-pixel render's actual errors are 8 and 16 um.
  for (std::uint64_t seed : {11, 12}) {
    const ContactLocatingError e = locating_error_from_contacts(
        scanned(*packing_, 10e-6, 20e-6, 4, seed), *reference_, kDiameter);
    EXPECT_GT(e.pairs, 3000u);
    EXPECT_NEAR(e.across, 10e-6, 1.5e-6) << "seed " << seed;
    EXPECT_NEAR(e.along_z, 20e-6, 2.5e-6) << "seed " << seed;
    EXPECT_NEAR(e.offset, 0, 2e-6) << "seed " << seed;
  }
  // Three times coarser; isotropic.
  const ContactLocatingError coarse =
      locating_error_from_contacts(scanned(*packing_, 30e-6, 30e-6, 4, 13), *reference_, kDiameter);
  EXPECT_NEAR(coarse.across, 30e-6, 4e-6);
  EXPECT_NEAR(coarse.along_z, 30e-6, 4e-6);
  // A 9-pixel render's with three times the noise: 130 and 190 um (0.026 and 0.038 d), past
  // the narrowest range's reach; the range is found from the data.
  const ContactLocatingError harsh = locating_error_from_contacts(
      scanned(*packing_, 130e-6, 190e-6, 4, 14), *reference_, kDiameter);
  EXPECT_NEAR(harsh.across, 130e-6, 15e-6);
  EXPECT_NEAR(harsh.along_z, 190e-6, 25e-6);
}

TEST_F(ContactLocatingErrorTest, ContactsReadShortAreAnOffsetNotASpread) {
  // The scanned packing shrunk by 1e-3 about its centre: every contact reads 5 um short.
  const Eigen::RowVector3d centre = packing_->colwise().mean();
  Vectors3 shrunk = *packing_;
  for (Eigen::Index i = 0; i < shrunk.rows(); ++i)
    shrunk.row(i) = centre + (1 - 1e-3) * (shrunk.row(i) - centre);
  const ContactLocatingError e =
      locating_error_from_contacts(scanned(shrunk, 10e-6, 20e-6, 4, 15), *reference_, kDiameter);
  EXPECT_NEAR(e.offset, -5e-6, 1.5e-6);
  EXPECT_NEAR(e.across, 10e-6, 1.5e-6);
  EXPECT_NEAR(e.along_z, 20e-6, 2.5e-6);
}

TEST_F(ContactLocatingErrorTest, AnExactPackingReadsLessThanItsOverlaps) {
  // Another pour's exact centres: what is left is the two packings' overlaps differing
  // (~1e-3 d under the lid), not an error.
  const ContactLocatingError e = locating_error_from_contacts(*packing_, *reference_, kDiameter);
  EXPECT_LT(e.across, 2.5e-6);
  EXPECT_LT(e.along_z, 2.5e-6);
}

// The stores calibrate reads: scans in mm with grains unlocated in some frames, the twin's
// run in m; frames pooled, read as the positions are.
class ContactLocatingErrorStores : public testing::TempDirTest {};

TEST_F(ContactLocatingErrorStores, ReadsTheScansFramesInTheirUnit) {
  const Vectors3 exact = poured(3), reference = poured(4);
  Trajectories scans, twin;
  scans.header.length_unit = "mm";
  twin.header.length_unit = "m";
  for (Trajectories* run : {&scans, &twin}) {
    const Eigen::Index n = run == &scans ? exact.rows() : reference.rows();
    for (Eigen::Index i = 0; i < n; ++i) {
      run->header.id.push_back(i + 1);
      run->header.radius.push_back(run == &scans ? 2.5 : 2.5e-3);
    }
  }
  Vectors3 pooled(0, 3);
  for (int t = 0; t < 3; ++t) {
    Frame f = Frame::unknown(scans.header);
    f.step = t;
    f.position = scanned(exact, 10e-6, 20e-6, 1, 20 + t);
    f.position.row(7 * t).setConstant(NAN);  // not located in this scan
    pooled.conservativeResize(pooled.rows() + f.position.rows(), 3);
    pooled.bottomRows(f.position.rows()) = f.position;
    pooled.bottomRows(f.position.rows()).col(0).array() += 0.2 * t;  // frames apart
    f.position *= 1e3;
    scans.frames.push_back(f);
  }
  Frame r = Frame::unknown(twin.header);
  r.position = reference;
  twin.frames.push_back(r);
  write_trajectories(path("scans.h5"), scans);
  write_trajectories(path("twin.h5"), twin);
  const ContactLocatingError from_stores = locating_error_from_contacts(
      TrajectoryReader(path("scans.h5")), TrajectoryReader(path("twin.h5")), kDiameter);
  const ContactLocatingError from_positions =
      locating_error_from_contacts(finite_rows(pooled), reference, kDiameter);
  EXPECT_EQ(from_stores.pairs, from_positions.pairs);
  EXPECT_NEAR(from_stores.across, from_positions.across, 1e-9);
  EXPECT_NEAR(from_stores.along_z, from_positions.along_z, 1e-9);
  EXPECT_NEAR(from_stores.across, 10e-6, 1.5e-6);
  EXPECT_NEAR(from_stores.along_z, 20e-6, 2.5e-6);
}

// One packing at rest scanned in frames 0-3, each frame's centres moved by `shared` (the
// same in every frame, grain by grain) plus an error of its own, (across, across, along_z)
// RMS; and the packing itself, exact, as the reference; in m.
void write_rest_scans(const std::filesystem::path& scans, const std::filesystem::path& exact,
                      double shared, double across, double along_z) {
  const Vectors3 packing = poured(3);
  const Vectors3 fixed = scanned(packing, shared, shared, 1, 40);
  Trajectories scan, rest;
  for (Trajectories* run : {&scan, &rest}) {
    run->header.length_unit = "m";
    for (Eigen::Index i = 0; i < packing.rows(); ++i) {
      run->header.id.push_back(i + 1);
      run->header.radius.push_back(kDiameter / 2);
    }
    for (int t = 0; t < 4; ++t) {
      Frame f = Frame::unknown(run->header);
      f.step = t;
      f.position = run == &rest ? packing : scanned(fixed, across, along_z, 1, 50 + t);
      run->frames.push_back(f);
    }
  }
  write_trajectories(scans, scan);
  write_trajectories(exact, rest);
}

// A packing at rest: a persistent contact's change is the two centres' errors' change along
// it, 2 s spread for independent errors of s per frame, so the reading is each frame's own
// error, across the slices on horizontal contacts and along z on vertical ones; an error a
// grain keeps from frame to frame moves no displacement and is not read.
TEST_F(ContactLocatingErrorStores, DisplacementsErrByEachFramesOwnErrorAlongTheContacts) {
  write_rest_scans(path("own.h5"), path("exact.h5"), 0, 5e-6, 10e-6);
  const TrajectoryReader exact(path("exact.h5"));
  const DisplacementError own =
      displacement_error_from_contacts(TrajectoryReader(path("own.h5")), exact, kDiameter, {1, 3});
  EXPECT_GT(own.contacts, 500u);
  EXPECT_NEAR(own.across, 5e-6, 0.6e-6);
  EXPECT_NEAR(own.along_z, 10e-6, 1.2e-6);
  write_rest_scans(path("kept.h5"), path("exact.h5"), 8e-6, 3e-6, 6e-6);
  const DisplacementError kept =
      displacement_error_from_contacts(TrajectoryReader(path("kept.h5")), exact, kDiameter, {1, 3});
  EXPECT_NEAR(kept.across, 3e-6, 0.4e-6);
  EXPECT_NEAR(kept.along_z, 6e-6, 0.8e-6);
  // Read against themselves, the scans' changes are all true ones: no error.
  const DisplacementError self = displacement_error_from_contacts(
      TrajectoryReader(path("own.h5")), TrajectoryReader(path("own.h5")), kDiameter, {1, 3});
  EXPECT_EQ(self.across, 0);
  EXPECT_EQ(self.along_z, 0);
}

TEST_F(ContactLocatingErrorTest, RefusesARangeOutsideItsReachAndNoDiameter) {
  ContactErrorOptions wide;
  wide.below = 0.4;
  EXPECT_THROW(locating_error_from_contacts(*packing_, *reference_, kDiameter, wide), Error);
  EXPECT_THROW(locating_error_from_contacts(*packing_, *reference_, 0.0), Error);
}

TEST_F(ContactLocatingErrorTest, TooFewContactsReadNothing) {
  const ContactLocatingError e =
      locating_error_from_contacts(packing_->topRows(20), *reference_, kDiameter);
  EXPECT_LT(e.pairs, 100u);
  EXPECT_TRUE(std::isnan(e.across));
  EXPECT_TRUE(std::isnan(e.along_z));
}

}  // namespace
}  // namespace granmem
