// link_run: `granmem link`'s job on hand-made scans whose every link is known.
#include "granmem/tracking/link_run.hpp"

#include <gtest/gtest.h>

#include "checks.hpp"
#include "granmem/core/error.hpp"
#include "granmem/tracking/track_run.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

Detections scan(std::int64_t frame, const std::vector<Eigen::Vector3d>& points,
                const std::string& unit = "mm") {
  Detections d;
  d.frame = frame;
  d.length_unit = unit;
  for (const Eigen::Vector3d& p : points)
    d.add(p, 2.5, 1.0, false);
  return d;
}

// The error `f` throws names every one of `parts`.
template <class F>
void expect_error(F&& f, const std::vector<std::string>& parts) {
  const std::string message = testing::error_message(f);
  for (const std::string& part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << part << " in: " << message;
}

// Grain a moves a little, b is not seen again, c appears far from both.
const Eigen::Vector3d a(10, 10, 10), b(20, 10, 10), c(40, 30, 10);
std::vector<Detections> scans_of_three_grains() {
  return {scan(0, {a, b}), scan(0, {a + Eigen::Vector3d(0.2, 0, 0), c})};
}

// Linking says each scan as it begins and stops between two when asked (Python's Ctrl-C).
TEST(LinkRun, EachScanIsSaidAndAStopEndsLinkingBeforeTheNext) {
  const std::vector<Detections> scans{scan(0, {a, b}), scan(1, {a, b}), scan(2, {a, b}),
                                      scan(3, {a, b})};
  const std::vector<std::string> names{"s0", "s1", "s2", "s3"};
  LinkRunOptions o;
  std::vector<std::string> said;
  o.log = [&](const std::string& line) { said.push_back(line); };
  EXPECT_EQ(link_run(scans, names, o).run.frames.size(), 4u);
  EXPECT_EQ(said, (std::vector<std::string>{"linking scan 2 of 4", "linking scan 3 of 4",
                                            "linking scan 4 of 4"}));
  std::atomic<bool> stop{false};
  o.stop = &stop;
  said.clear();
  o.log = [&](const std::string& line) {
    said.push_back(line);
    stop = line == "linking scan 3 of 4";
  };
  expect_error([&] { link_run(scans, names, o); }, {"link: stopped before scan 4 of 4"});
  EXPECT_EQ(said.size(), 2u);
}

TEST(LinkRun, ScansThatAllSayOneFrameAreNumberedInOrder) {
  const LinkRun r = link_run(scans_of_three_grains(), {"s0", "s1"}, {});
  ASSERT_EQ(r.run.frames.size(), 2u);
  EXPECT_EQ(r.run.frames[1].step, 1);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("numbered 0..1"), std::string::npos) << r.notes[0];
  EXPECT_NE(r.Report().find("linked 2 scans: 3 tracks"), std::string::npos) << r.Report();
}

// The last scans of a long run: numbered from the cycle given, the store's steps those
// cycles. Scans that say their own frames keep them, and are not renumbered.
TEST(LinkRun, ScansAreNumberedFromTheFirstCycleGiven) {
  LinkRunOptions o;
  o.first_cycle = 491;
  const LinkRun r = link_run(scans_of_three_grains(), {"s0", "s1"}, o);
  ASSERT_EQ(r.run.frames.size(), 2u);
  EXPECT_EQ(r.run.frames[0].step, 491);
  EXPECT_EQ(r.run.frames[1].step, 492);
  EXPECT_NE(r.notes[0].find("numbered 491..492"), std::string::npos) << r.notes[0];
  const std::vector<Detections> numbered{scan(491, {a, b}), scan(492, {a, b})};
  EXPECT_EQ(link_run(numbered, {"s0", "s1"}, o).run.frames[1].step, 492);
  const std::vector<Detections> own{scan(0, {a, b}), scan(1, {a, b})};
  expect_error(
      [&] {
        link_run(own, {"s0", "s1"}, o);
      },
      {"--first-cycle 491", "their own frames (0, 1, ...)"});
  o.first_cycle = -1;
  expect_error([&] { o.validate(); }, {"--first-cycle", "0 or more"});
}

TEST(LinkRun, WhatCouldNotBeLinkedIsInTheContainersFrame) {
  LinkRunOptions o;
  o.container = "1,2,3,51,52,53mm";
  o.memory = 0;
  const LinkRun r = link_run(scans_of_three_grains(), {"s0", "s1"}, o);
  const Eigen::Vector3d origin(1, 2, 3);
  EXPECT_TRUE(r.run.header.box.has_value());
  const Table t = unlinked_table(r);
  ASSERT_EQ(t.rows(), 2u);  // b lost, c new
  for (std::size_t k = 0; k < 2; ++k) {
    const bool lost = t["lost"].values[k] == 1;
    const Eigen::Vector3d at(t["x"].values[k], t["y"].values[k], t["z"].values[k]);
    // Lost: where the run last saw it; new: where the scan saw it; both from the origin.
    EXPECT_LT((at - ((lost ? b : c) - origin)).norm(), 1e-12) << k << ": " << at.transpose();
  }
  // The run's positions too.
  EXPECT_LT((r.run.frames[0].position.row(0).transpose() - (a - origin)).norm(), 1e-12);
}

TEST(LinkRun, BadScansAndOptionsAreOneClearError) {
  std::vector<Detections> mixed = scans_of_three_grains();
  mixed[1].length_unit = "cm";
  expect_error([&] { link_run(mixed, {"s0", "s1"}, {}); }, {"s1", "cm", "one length unit"});
  LinkRunOptions both;
  both.container = "0,0,0,5,5,5cm";
  both.container_size = "5,5,5cm";
  expect_error([&] { both.validate(); }, {"--container and --container-size"});
  LinkRunOptions unitless;
  unitless.container = "0,0,0,5,5,5";
  expect_error([&] { unitless.validate(); }, {"--container", "length unit"});
}

// track_run's options, checked before any scan is located or any folder made: its link and
// locate parts, the scans there, an output named.
class TrackRun : public testing::TempDirTest {};

TEST_F(TrackRun, ValidateNamesTheBadOptionBeforeAnyScanIsLocated) {
  TrackRunOptions o;
  o.locate.diameter = "12";
  o.out = path("run.h5");
  EXPECT_EQ(testing::error_message([&] { o.validate(); }), "track: no scans");
  o.scans = {path("scan0.tif")};
  EXPECT_EQ(testing::error_message([&] { o.validate(); }),
            "scan " + path("scan0.tif").string() + ": no such file or folder");
  write_text(path("scan0.tif"), "");  // there (read only when located)
  EXPECT_NO_THROW(o.validate());
  o.link.memory = -1;
  EXPECT_EQ(testing::error_message([&] { o.validate(); }), "--memory: 0 or more scans");
  o.link.memory = 2;
  o.locate.diameter = "0";
  o.detections = path("detections");
  EXPECT_EQ(testing::error_message([&] { track_run(o); }),
            "--diameter '0': expected a positive diameter");
  EXPECT_FALSE(std::filesystem::exists(o.detections));
  o.locate.diameter = "12";
  o.out.clear();
  EXPECT_EQ(testing::error_message([&] { o.validate(); }),
            "track: no --out (the trajectory store to write)");
}

}  // namespace
}  // namespace granmem
