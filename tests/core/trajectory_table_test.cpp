#include "granmem/core/trajectory_table.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "granmem/core/error.hpp"
#include "granmem/core/import_table.hpp"

namespace granmem {
namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

// Three grains over two frames, grain 20 unseen in the second, with axes and flags.
Trajectories two_frames() {
  Trajectories run;
  RunHeader& h = run.header;
  h.length_unit = "mm";
  h.time_unit = "cycle";
  h.id = {10, 20, 30};
  h.radius = {0.5, 0.75, kNaN};
  h.has_axis = h.has_hole_contact = true;
  for (int t = 0; t < 2; ++t) {
    Frame f = Frame::unknown(h);
    f.step = 4 + t;
    f.time = 4 + t;
    for (Eigen::Index g = 0; g < 3; ++g) {
      if (t == 1 && g == 1) continue;
      f.position.row(g) << 1.0 + double(g), 2.0 + 0.25 * t, 3.0;
      f.axis.row(g) << 0, 0, 1;
      f.hole_contact[std::size_t(g)] = std::uint8_t(g == 2);
    }
    run.frames.push_back(f);
  }
  return run;
}

TEST(TrajectoryTable, ARowPerGrainSeenWithTrackpysColumns) {
  const Table t = trajectory_table(two_frames());
  std::vector<std::string> names;
  for (const Column& c : t.columns())
    names.push_back(c.name);
  EXPECT_EQ(names, (std::vector<std::string>{"frame", "particle", "time", "x", "y", "z", "radius",
                                             "ax", "ay", "az", "hole_contact"}));
  ASSERT_EQ(t.rows(), 5u);  // 3 + 2: grain 20 is not in frame 5
  EXPECT_EQ(t["frame"].values, (std::vector<double>{4, 4, 4, 5, 5}));
  EXPECT_EQ(t["particle"].values, (std::vector<double>{10, 20, 30, 10, 30}));
  EXPECT_EQ(t["y"].values[4], 2.25);
  EXPECT_EQ(t["x"].unit, "mm");
  EXPECT_EQ(t["time"].unit, "cycle");
  EXPECT_TRUE(std::isnan(t["radius"].values[2]));
  EXPECT_EQ(t["hole_contact"].values[4], 1);
}

TEST(TrajectoryTable, ImportedBackFromMemoryGivesTheSameRun) {
  const Trajectories run = two_frames();
  ImportOptions o;
  o.length_unit = "mm";
  const Trajectories back = import_table(trajectory_table(run), "tracks", o);
  EXPECT_EQ(back.header.id, run.header.id);
  ASSERT_EQ(back.frames.size(), 2u);
  for (std::size_t t = 0; t < 2; ++t) {
    EXPECT_EQ(back.frames[t].step, run.frames[t].step);
    for (Eigen::Index g = 0; g < 3; ++g) {
      for (int a = 0; a < 3; ++a) {
        const double x = run.frames[t].position(g, a), y = back.frames[t].position(g, a);
        EXPECT_TRUE(x == y || (std::isnan(x) && std::isnan(y))) << t << " " << g << " " << a;
      }
    }
    EXPECT_EQ(back.frames[t].hole_contact, run.frames[t].hole_contact);
  }
  EXPECT_EQ(back.header.radius[1], 0.75);
  EXPECT_TRUE(std::isnan(back.header.radius[2]));
}

TEST(TrajectoryTable, BadRowsInMemoryAreNamedByRow) {
  Table t = trajectory_table(two_frames());
  t["frame"].values[3] = 4.5;
  try {
    import_table(t, "tracks", ImportOptions{});
    FAIL() << "expected an Error";
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(),
                 "tracks row 4, column 'frame': expected an integer label, found 4.500000");
  }
  Table no_particle;
  no_particle.add("frame");
  EXPECT_THROW(import_table(no_particle, "tracks", ImportOptions{}), Error);
}

}  // namespace
}  // namespace granmem
