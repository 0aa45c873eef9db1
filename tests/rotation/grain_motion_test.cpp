#include "granmem/rotation/grain_motion.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

#include "checks.hpp"
#include "granmem/core/error.hpp"

namespace granmem {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

RunHeader header_of(std::size_t grains, bool axes = false, bool orientations = false,
                    bool hole_contacts = false) {
  RunHeader h;
  h.length_unit = "mm";
  for (std::size_t i = 0; i < grains; ++i) {
    h.id.push_back(static_cast<std::int64_t>(100 + i));
    h.radius.push_back(1.0);
  }
  h.has_axis = axes;
  h.has_orientation = orientations;
  h.has_hole_contact = hole_contacts;
  return h;
}

// A frame with every grain at rest at the origin, facing +z, no contacts.
Frame frame_of(const RunHeader& h) {
  Frame f = Frame::unknown(h);
  f.position.setZero();
  if (h.has_axis) {
    f.axis.setZero();
    f.axis.col(2).setOnes();
  }
  if (h.has_orientation) {
    f.orientation = Quaternions::Zero(f.orientation.rows(), 4);
    f.orientation.col(0).setOnes();  // (w, x, y, z) = identity
  }
  return f;
}

MotionOptions drift_removed() {
  MotionOptions o;
  o.subtract_drift = true;
  return o;
}

MotionOptions away_from_walls(double distance, std::optional<Box> box = std::nullopt) {
  MotionOptions o;
  o.wall_distance = distance;
  o.box = box;
  return o;
}

MotionOptions hole_contacts(HoleContactPolicy policy) {
  MotionOptions o;
  o.hole_contacts = policy;
  return o;
}

void set_orientation(Frame& f, Eigen::Index grain, const Eigen::Quaterniond& q) {
  f.orientation.row(grain) << q.w(), q.x(), q.y(), q.z();
}

std::vector<std::size_t> kept(const FrameMotion& m) {
  return m.grain;
}

TEST(GrainMotion, DisplacementOfEachGrainSeenInBothFrames) {
  const RunHeader h = header_of(4);
  Frame before = frame_of(h), after = frame_of(h);
  before.position << 1, 2, 3,  //
      0, 0, 0,                 //
      -1, -1, -1,              //
      5, 5, 5;
  after.position << 4, 6, 15,  // moved (3, 4, 12): 13
      0, 0, 0,                 //
      1, -2, 1,                // moved (2, -1, 2): 3
      5, 5, 5;
  before.position.row(1).setConstant(kNaN);  // not seen before: no displacement
  after.position(3, 1) = kNaN;               // lost afterwards: no displacement
  const FrameMotion m = grain_motion(h, before, after, {});
  ASSERT_EQ(kept(m), (std::vector<std::size_t>{0, 2}));
  EXPECT_EQ(Eigen::Vector3d(m.displacement.row(0)), Eigen::Vector3d(3, 4, 12));
  EXPECT_EQ(Eigen::Vector3d(m.displacement.row(1)), Eigen::Vector3d(2, -1, 2));
  EXPECT_EQ(m.dr, (std::vector<double>{13, 3}));
  // Drift is the mean displacement even when not removed.
  EXPECT_EQ(m.drift, Eigen::Vector3d(2.5, 1.5, 7));
  // No axes or orientations: nothing about rotation.
  EXPECT_FALSE(m.has_rotation);
  EXPECT_TRUE(m.theta_axis.empty());
  EXPECT_TRUE(m.rot_disp.empty());
  EXPECT_TRUE(m.theta_full.empty());
}

TEST(GrainMotion, NoGrainInCommonGivesNoEntries) {
  const RunHeader h = header_of(2);
  Frame before = frame_of(h), after = frame_of(h);
  before.position.row(0).setConstant(kNaN);
  after.position.row(1).setConstant(kNaN);
  const FrameMotion m = grain_motion(h, before, after, drift_removed());
  EXPECT_TRUE(m.grain.empty());
  EXPECT_EQ(m.displacement.rows(), 0);
  EXPECT_EQ(m.drift, Eigen::Vector3d::Zero());
}

TEST(GrainMotion, DriftRemovalOfAPureTranslationLeavesNoDisplacement) {
  const RunHeader h = header_of(5);
  Frame before = frame_of(h), after = frame_of(h);
  // Positions and translation in eighths, exact in binary: the drift is exactly the
  // translation and every residual exactly zero.
  const Eigen::Vector3d translation(0.375, -2.5, 1.125);
  before.position << 0, 0, 0,  //
      1.5, 2, -3,              //
      10.25, 0.5, 4,           //
      -7, 3.75, 8,             //
      2, 2, 2;
  after.position = before.position.rowwise() + translation.transpose();
  const FrameMotion m = grain_motion(h, before, after, drift_removed());
  ASSERT_EQ(m.grain.size(), 5u);
  EXPECT_EQ(m.drift, translation);
  EXPECT_EQ(m.displacement, Vectors3::Zero(5, 3));
  EXPECT_EQ(m.dr, std::vector<double>(5, 0.0));

  // Any positions and translation: zero up to rounding of the positions themselves.
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> coordinate(-50, 50);
  const RunHeader many = header_of(200);
  Frame b = frame_of(many), a = frame_of(many);
  const Eigen::Vector3d shift(coordinate(rng), coordinate(rng), coordinate(rng));
  for (Eigen::Index i = 0; i < b.position.rows(); ++i) {
    b.position.row(i) << coordinate(rng), coordinate(rng), coordinate(rng);
  }
  a.position = b.position.rowwise() + shift.transpose();
  const FrameMotion r = grain_motion(many, b, a, drift_removed());
  EXPECT_LT((r.drift - shift).norm(), 1e-12);
  for (double dr : r.dr)
    EXPECT_LT(dr, 1e-12);
}

TEST(GrainMotion, DriftRemovalSubtractsTheMeanDisplacement) {
  const RunHeader h = header_of(3);
  Frame before = frame_of(h), after = frame_of(h);
  after.position << 3, 0, 0,  //
      0, 6, 0,                //
      0, 0, 9;
  const FrameMotion raw = grain_motion(h, before, after, {});
  const FrameMotion relative = grain_motion(h, before, after, drift_removed());
  EXPECT_EQ(raw.drift, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(relative.drift, raw.drift);
  Vectors3 expected(3, 3);
  expected << 2, -2, -3,  //
      -1, 4, -3,          //
      -1, -2, 6;
  EXPECT_EQ(relative.displacement, expected);
  // The residual displacements of the analysed grains have zero mean.
  EXPECT_EQ(Eigen::Vector3d(relative.displacement.colwise().sum()), Eigen::Vector3d::Zero());
  EXPECT_DOUBLE_EQ(relative.dr[0], std::sqrt(17.0));
  EXPECT_DOUBLE_EQ(relative.dr[2], std::sqrt(41.0));
}

TEST(GrainMotion, DriftIsTheMeanOfTheGrainsKeptOnly) {
  // A grain left out (unseen, or near a wall) must not pull the drift.
  RunHeader h = header_of(3);
  h.box = Box{Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 10, 10)};
  Frame before = frame_of(h), after = frame_of(h);
  before.position << 5, 5, 5,  //
      4, 4, 4,                 //
      0.5, 5, 5;               // near the x = 0 face
  after.position << 6, 5, 5,   //
      5, 4, 4,                 //
      9.5, 5, 5;               // a large jump that would dominate the mean
  MotionOptions options = away_from_walls(1);
  options.subtract_drift = true;
  const FrameMotion m = grain_motion(h, before, after, options);
  ASSERT_EQ(kept(m), (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(m.drift, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(m.dr, (std::vector<double>{0, 0}));
}

TEST(GrainMotion, GrainsNearAnyWallInEitherFrameAreLeftOut) {
  RunHeader h = header_of(9);
  // Box from (-1, -2, -3) to (9, 18, 27).
  h.box = Box{Eigen::Vector3d(-1, -2, -3), Eigen::Vector3d(10, 20, 30)};
  Frame before = frame_of(h), after = frame_of(h);
  before.position << 4, 8, 12,  // centre, stays: kept
      -0.5, 8, 12,              // 0.5 from the x-low face
      8.5, 8, 12,               // 0.5 from the x-high face
      4, -1.5, 12,              // y-low
      4, 17.5, 12,              // y-high
      4, 8, -2.5,               // z-low
      4, 8, 26.5,               // z-high
      4, 8, 12,                 // moves next to a wall afterwards
      0.5, 8, 12;               // 1.5 from the x-low face: outside the 1.0 band, kept
  after.position = before.position;
  after.position.row(7) << 4, 8, 26.8;
  const MotionOptions options = away_from_walls(1.0);
  EXPECT_EQ(kept(grain_motion(h, before, after, options)), (std::vector<std::size_t>{0, 8}));
  // Swapping the frames must not matter: either frame near a wall excludes the grain.
  EXPECT_EQ(kept(grain_motion(h, after, before, options)), (std::vector<std::size_t>{0, 8}));
  // A wider band catches grain 8 too; none at all keeps every grain.
  EXPECT_EQ(kept(grain_motion(h, before, after, away_from_walls(2.0))),
            (std::vector<std::size_t>{0}));
  EXPECT_EQ(grain_motion(h, before, after, {}).grain.size(), 9u);
}

TEST(GrainMotion, WallDistanceNeedsAContainer) {
  const RunHeader no_box = header_of(2);
  Frame before = frame_of(no_box), after = frame_of(no_box);
  before.position << 0.5, 5, 5,  //
      5, 5, 5;
  after.position = before.position;
  EXPECT_THROW(grain_motion(no_box, before, after, away_from_walls(1)), Error);
  // A box given with the options serves when the run has none...
  const Box box{Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 10, 10)};
  EXPECT_EQ(kept(grain_motion(no_box, before, after, away_from_walls(1, box))),
            (std::vector<std::size_t>{1}));
  // ...and replaces the run's own box when it has one: here the run's box is far away,
  // so by it both grains are near walls, but by the given box only grain 0 is.
  RunHeader far_box = no_box;
  far_box.box = Box{Eigen::Vector3d(4.5, 4.5, 4.5), Eigen::Vector3d(1, 1, 1)};
  EXPECT_TRUE(grain_motion(far_box, before, after, away_from_walls(1)).grain.empty());
  EXPECT_EQ(kept(grain_motion(far_box, before, after, away_from_walls(1, box))),
            (std::vector<std::size_t>{1}));
}

class HoleContactPolicyTest : public ::testing::Test {
 protected:
  // Grain 0 never touches through its hole, grain 1 does before, grain 2 after. Each
  // tilts its axis by a different angle and moves by a different amount.
  void SetUp() override {
    h = header_of(3, /*axes=*/true, /*orientations=*/false, /*hole_contacts=*/true);
    before = frame_of(h);
    after = frame_of(h);
    before.hole_contact = {0, 1, 0};
    after.hole_contact = {0, 0, 1};
    after.position << 1, 0, 0,  //
        0, 2, 0,                //
        0, 0, 4;
    after.axis << std::sin(0.1), 0, std::cos(0.1),  //
        0, std::sin(0.2), std::cos(0.2),            //
        std::sin(0.3), std::cos(0.3), 0;            // 90 degrees from z
  }
  RunHeader h;
  Frame before, after;
};

TEST_F(HoleContactPolicyTest, KeepMeasuresEveryGrain) {
  const FrameMotion m = grain_motion(h, before, after, hole_contacts(HoleContactPolicy::keep));
  ASSERT_EQ(kept(m), (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_NEAR(m.theta_axis[0], 0.1, 1e-15);
  EXPECT_NEAR(m.theta_axis[1], 0.2, 1e-15);
  EXPECT_EQ(m.theta_axis[2], M_PI / 2);
}

TEST_F(HoleContactPolicyTest, ExcludeRotationsKeepsTranslations) {
  const FrameMotion m =
      grain_motion(h, before, after, hole_contacts(HoleContactPolicy::exclude_rotations));
  ASSERT_EQ(kept(m), (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_EQ(m.dr, (std::vector<double>{1, 2, 4}));
  EXPECT_NEAR(m.theta_axis[0], 0.1, 1e-15);
  // A contact in either frame locks the grain: no rotation measured.
  EXPECT_TRUE(std::isnan(m.theta_axis[1]));
  EXPECT_TRUE(std::isnan(m.theta_axis[2]));
  EXPECT_TRUE(std::isnan(m.rot_disp[1]));
  EXPECT_TRUE(std::isnan(m.rot_disp[2]));
  // The translations still count towards the drift.
  EXPECT_EQ(m.drift, Eigen::Vector3d(1.0 / 3, 2.0 / 3, 4.0 / 3));
}

TEST_F(HoleContactPolicyTest, ExcludeDropsTheGrain) {
  const FrameMotion m = grain_motion(h, before, after, hole_contacts(HoleContactPolicy::exclude));
  ASSERT_EQ(kept(m), (std::vector<std::size_t>{0}));
  EXPECT_EQ(m.dr, (std::vector<double>{1}));
  EXPECT_NEAR(m.theta_axis[0], 0.1, 1e-15);
  EXPECT_EQ(m.drift, Eigen::Vector3d(1, 0, 0));
}

TEST_F(HoleContactPolicyTest, PolicyIsIgnoredWhenTheRunHasNoContactFlags) {
  RunHeader unflagged = h;
  unflagged.has_hole_contact = false;
  before.hole_contact.clear();
  after.hole_contact.clear();
  const FrameMotion m =
      grain_motion(unflagged, before, after, hole_contacts(HoleContactPolicy::exclude));
  EXPECT_EQ(kept(m), (std::vector<std::size_t>{0, 1, 2}));
  EXPECT_NEAR(m.theta_axis[1], 0.2, 1e-15);
}

TEST(GrainMotion, SingleAxisRotationAndRotationalDisplacementFromAxes) {
  RunHeader h = header_of(4, /*axes=*/true);
  h.radius = {0.5, 2.0, kNaN, 3.0};
  Frame before = frame_of(h), after = frame_of(h);
  after.axis << 0, std::sin(0.25), std::cos(0.25),  // tilted by 0.25 rad
      0, 0, -3,                                     // flipped end for end: same line
      std::sin(0.4), 0, std::cos(0.4),              // radius unknown
      kNaN, kNaN, kNaN;                             // axis not seen
  const FrameMotion m = grain_motion(h, before, after, {});
  ASSERT_EQ(m.grain.size(), 4u);
  EXPECT_TRUE(m.has_rotation);
  EXPECT_NEAR(m.theta_axis[0], 0.25, 1e-15);
  EXPECT_NEAR(m.rot_disp[0], 0.25 * 0.5, 1e-15);
  EXPECT_EQ(m.theta_axis[1], 0.0);
  EXPECT_EQ(m.rot_disp[1], 0.0);
  EXPECT_NEAR(m.theta_axis[2], 0.4, 1e-15);
  EXPECT_TRUE(std::isnan(m.rot_disp[2]));
  EXPECT_TRUE(std::isnan(m.theta_axis[3]));
  EXPECT_TRUE(std::isnan(m.rot_disp[3]));
  EXPECT_EQ(m.dr[3], 0.0);            // its translation is still known
  EXPECT_TRUE(m.theta_full.empty());  // axes alone do not give the full rotation
}

TEST(GrainMotion, OrientationsGiveBothRotationsWhenTheRunHasNoAxes) {
  RunHeader h = header_of(4, /*axes=*/false, /*orientations=*/true);
  h.radius = {1.0, 2.0, 0.5, 4.0};
  Frame before = frame_of(h), after = frame_of(h);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  // Tilting the body z axis by 0.3 about x: both measures see 0.3.
  set_orientation(after, 0, Eigen::Quaterniond(Eigen::AngleAxisd(0.3, x)));
  // Spinning about the cavity axis: invisible to the axis, a full 1.0 rad turn.
  set_orientation(after, 1, Eigen::Quaterniond(Eigen::AngleAxisd(1.0, z)));
  // Tilting by 2.5 rad: the line is then pi - 2.5 from where it was.
  set_orientation(after, 2, Eigen::Quaterniond(Eigen::AngleAxisd(2.5, y)));
  // From an already turned start: the relative turn counts, not the absolute orientation.
  const Eigen::Quaterniond start(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()));
  set_orientation(before, 3, start);
  set_orientation(after, 3, Eigen::Quaterniond(Eigen::AngleAxisd(0.2, start * x)) * start);

  const FrameMotion m = grain_motion(h, before, after, {});
  ASSERT_EQ(m.grain.size(), 4u);
  EXPECT_TRUE(m.has_rotation);
  ASSERT_EQ(m.theta_full.size(), 4u);
  EXPECT_NEAR(m.theta_axis[0], 0.3, 1e-15);
  EXPECT_NEAR(m.theta_full[0], 0.3, 1e-15);
  EXPECT_NEAR(m.rot_disp[0], 0.3 * 1.0, 1e-15);
  EXPECT_NEAR(m.theta_axis[1], 0.0, 1e-15);
  EXPECT_NEAR(m.theta_full[1], 1.0, 1e-15);
  EXPECT_NEAR(m.rot_disp[1], 0.0, 1e-15);
  EXPECT_NEAR(m.theta_axis[2], M_PI - 2.5, 1e-14);
  EXPECT_NEAR(m.theta_full[2], 2.5, 1e-14);
  EXPECT_NEAR(m.rot_disp[2], (M_PI - 2.5) * 0.5, 1e-14);
  // A turn about the grain's own x axis (perpendicular to its cavity axis) tilts the
  // cavity axis by the whole angle.
  EXPECT_NEAR(m.theta_axis[3], 0.2, 1e-14);
  EXPECT_NEAR(m.theta_full[3], 0.2, 1e-14);
  EXPECT_NEAR(m.rot_disp[3], 0.2 * 4.0, 1e-13);
}

TEST(GrainMotion, OrientationsGiveEachBodyAxisItsSingleAxisRotation) {
  // A turn by phi about one body axis leaves that axis where it was and tilts the other
  // two by phi; a turn about a body diagonal (1, 1, 1)/sqrt 3 tilts each axis e by
  // arccos(cos phi + (1 - cos phi)/3) (Rodrigues: e . R e = cos phi + (1 - cos phi)(u.e)^2).
  RunHeader h = header_of(3, /*axes=*/false, /*orientations=*/true);
  Frame before = frame_of(h), after = frame_of(h);
  const double phi = 0.4;
  const Eigen::Quaterniond start(
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.2, -1, 0.5).normalized()));
  for (std::size_t i = 0; i < 3; ++i)
    set_orientation(before, i, start);
  // Body axes in the lab: start * e.
  set_orientation(
      after, 0,
      Eigen::Quaterniond(Eigen::AngleAxisd(phi, start * Eigen::Vector3d::UnitX())) * start);
  set_orientation(
      after, 1,
      Eigen::Quaterniond(Eigen::AngleAxisd(phi, start * Eigen::Vector3d::UnitZ())) * start);
  const Eigen::Vector3d diagonal = Eigen::Vector3d::Ones().normalized();
  set_orientation(after, 2, Eigen::Quaterniond(Eigen::AngleAxisd(phi, start * diagonal)) * start);

  const FrameMotion m = grain_motion(h, before, after, {});
  ASSERT_EQ(m.theta_body_x.size(), 3u);
  ASSERT_EQ(m.theta_body_y.size(), 3u);
  EXPECT_NEAR(m.theta_body_x[0], 0, 1e-12);  // about x
  EXPECT_NEAR(m.theta_body_y[0], phi, 1e-12);
  EXPECT_NEAR(m.theta_axis[0], phi, 1e-12);
  EXPECT_NEAR(m.theta_body_x[1], phi, 1e-12);  // about the cavity axis z
  EXPECT_NEAR(m.theta_body_y[1], phi, 1e-12);
  EXPECT_NEAR(m.theta_axis[1], 0, 1e-12);
  const double tilt = std::acos(std::cos(phi) + (1 - std::cos(phi)) / 3);
  EXPECT_NEAR(m.theta_body_x[2], tilt, 1e-12);
  EXPECT_NEAR(m.theta_body_y[2], tilt, 1e-12);
  EXPECT_NEAR(m.theta_axis[2], tilt, 1e-12);
  EXPECT_NEAR(m.theta_full[2], phi, 1e-12);
}

TEST(GrainMotion, TrackedAxesTakePrecedenceOverOrientations) {
  // Experiments with both: the tracked axis is the measurement of the single-axis
  // rotation; the orientation only gives the full rotation.
  RunHeader h = header_of(1, /*axes=*/true, /*orientations=*/true);
  Frame before = frame_of(h), after = frame_of(h);
  after.axis.row(0) << std::sin(0.2), 0, std::cos(0.2);
  set_orientation(after, 0, Eigen::Quaterniond(Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitZ())));
  const FrameMotion m = grain_motion(h, before, after, {});
  EXPECT_NEAR(m.theta_axis[0], 0.2, 1e-15);
  EXPECT_NEAR(m.theta_full[0], 0.6, 1e-15);
}

TEST(GrainMotion, UnknownOrientationGivesNaNRotationsButKeepsTheTranslation) {
  RunHeader h = header_of(2, /*axes=*/false, /*orientations=*/true);
  Frame before = frame_of(h), after = frame_of(h);
  after.orientation.row(1).setConstant(kNaN);
  after.position.row(1) << 0, 0, 2;
  const FrameMotion m = grain_motion(h, before, after, {});
  ASSERT_EQ(kept(m), (std::vector<std::size_t>{0, 1}));
  EXPECT_EQ(m.theta_axis[0], 0.0);
  EXPECT_EQ(m.theta_full[0], 0.0);
  EXPECT_TRUE(std::isnan(m.theta_axis[1]));
  EXPECT_TRUE(std::isnan(m.theta_full[1]));
  EXPECT_TRUE(std::isnan(m.rot_disp[1]));
  EXPECT_EQ(m.dr[1], 2.0);
}

TEST(MotionOptions, ValidateRefusesAWallDistanceThatIsNotALengthAtLeastZero) {
  EXPECT_NO_THROW(MotionOptions{}.validate());
  MotionOptions o;
  o.wall_distance = 0.5;
  EXPECT_NO_THROW(o.validate());
  for (double bad : {-0.1, kNaN, std::numeric_limits<double>::infinity()}) {
    o.wall_distance = bad;
    EXPECT_EQ(testing::error_message([&] { o.validate(); }),
              "--wall-distance: expected a length >= 0")
        << bad;
  }
}

}  // namespace
}  // namespace granmem
