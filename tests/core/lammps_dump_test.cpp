#include "granmem/core/lammps_dump.hpp"

#include <gtest/gtest.h>

#include <string>

#include "granmem/core/error.hpp"
#include "granmem/core/import_table.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

class LammpsDumpTest : public granmem::testing::TempDirTest {
 protected:
  std::filesystem::path dump(const std::string& text) {
    const auto file = path("run.dump");
    write_text(file, text);
    return file;
  }
  std::string error_of(const std::string& text, const std::set<long long>& types = {}) {
    try {
      read_lammps_dump(dump(text), types);
    } catch (const Error& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected granmem::Error for:\n" << text;
    return "";
  }
};

// Two snapshots as LAMMPS writes them with `dump custom ... id type xs ys zs diameter`:
// scaled coordinates become lengths with each snapshot's box, diameters radii, ids grain
// ids (less one), and the lid (type 2) is left out when only type 1 is asked for.
const char* kScaled =
    "ITEM: UNITS\ncgs\n"
    "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS ff ff ff\n"
    "0 10\n-1 1\n0 4\nITEM: ATOMS id type xs ys zs diameter vx\n"
    "1 1 0.5 0.5 0.25 0.5 1e9\n2 1 0.1 0 1 0.5 0\n3 2 0.5 0.5 1 0 0\n"
    "ITEM: TIMESTEP\n100\nITEM: TIME\n0.25\nITEM: NUMBER OF ATOMS\n3\n"
    "ITEM: BOX BOUNDS ff ff ff\n0 10\n-1 1\n0 2\nITEM: ATOMS id type xs ys zs diameter vx\r\n"
    "2 1 0.2 0.5 0.5 0.5 0\r\n1 1 0.5 0.5 0.5 0.5 0\r\n3 2 0.5 0.5 1 0 0\r\n";

TEST_F(LammpsDumpTest, ScaledCoordinatesDiametersAndTypes) {
  const LammpsDump d = read_lammps_dump(dump(kScaled), {1});
  EXPECT_EQ(d.snapshots, 2u);
  EXPECT_EQ(d.units, "cgs");
  ASSERT_TRUE(d.box);
  EXPECT_EQ(d.box->lower, Eigen::Vector3d(0, -1, 0));
  EXPECT_EQ(d.box->edges, Eigen::Vector3d(10, 2, 4));
  EXPECT_TRUE(d.box_changes);
  const Table& t = d.table;
  ASSERT_EQ(t.rows(), 4u);
  EXPECT_FALSE(t.has("vx"));
  EXPECT_EQ(t["frame"].values, (std::vector<double>{0, 0, 100, 100}));
  EXPECT_EQ(t["particle"].values, (std::vector<double>{0, 1, 1, 0}));
  EXPECT_EQ(t["x"].values, (std::vector<double>{5, 1, 2, 5}));
  EXPECT_EQ(t["y"].values, (std::vector<double>{0, -1, 0, 0}));
  EXPECT_EQ(t["z"].values, (std::vector<double>{1, 4, 1, 1}));  // the second box is 2 high
  EXPECT_EQ(t["radius"].values, (std::vector<double>{0.25, 0.25, 0.25, 0.25}));
  EXPECT_EQ(d.lines, (std::vector<std::size_t>{12, 13, 26, 27}));
}

TEST_F(LammpsDumpTest, UnitsStylesWithAGranmemLength) {
  EXPECT_EQ(lammps_length_unit("si"), "m");
  EXPECT_EQ(lammps_length_unit("cgs"), "cm");
  EXPECT_EQ(lammps_length_unit("micro"), "um");
  EXPECT_EQ(lammps_length_unit("lj"), "");
  EXPECT_EQ(lammps_length_unit("real"), "");
}

// import reads a dump as a run: frames by TIMESTEP, grains by id, the unit and box from the
// dump, orientations (quatw..quatk) stored as unit quaternions.
TEST_F(LammpsDumpTest, ImportTakesUnitsBoxAndOrientations) {
  const auto file = dump(
      "ITEM: TIMESTEP\n7\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS pp pp ff\n0 1\n0 1\n0 2\n"
      "ITEM: ATOMS id x y z radius quatw quati quatj quatk\n"
      "5 0.1 0.2 0.3 0.05 1 0 0 0\n9 0.4 0.5 0.6 0.05 0 0 0.6 0.8\n");
  ImportOptions o;
  o.length_unit = "mm";
  ImportSummary s;
  const Trajectories run = import_table(file, o, &s);
  EXPECT_EQ(s.format, "lammps dump");
  EXPECT_EQ(run.header.length_unit, "mm");
  EXPECT_EQ(run.header.id, (std::vector<std::int64_t>{4, 8}));
  ASSERT_TRUE(run.header.box);
  EXPECT_EQ(run.header.box->edges, Eigen::Vector3d(1, 1, 2));
  ASSERT_TRUE(run.header.has_orientation);
  ASSERT_EQ(run.frames.size(), 1u);
  EXPECT_EQ(run.frames[0].step, 7);
  EXPECT_EQ(run.frames[0].position.row(1), Eigen::RowVector3d(0.4, 0.5, 0.6));
  EXPECT_EQ(run.frames[0].orientation.row(1), Eigen::RowVector4d(0, 0, 0.6, 0.8));
  EXPECT_EQ(run.header.radius, (std::vector<double>{0.05, 0.05}));

  // Without ITEM: UNITS the unit must be given; with it, a different one is refused.
  try {
    import_table(file, ImportOptions{});
    ADD_FAILURE() << "no unit refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("give its length unit"), std::string::npos) << e.what();
  }
}

TEST_F(LammpsDumpTest, ADumpInOtherUnitsThanAskedIsRefused) {
  const auto file = dump(kScaled);
  ImportOptions o;
  o.length_unit = "m";
  o.types = {1};
  try {
    import_table(file, o);
    ADD_FAILURE() << "cgs read as m";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("the dump's units are cgs (cm), not --length-unit m"),
              std::string::npos)
        << e.what();
  }
  o.length_unit = "voxel";  // the default: the dump's own unit is taken
  ImportSummary s;
  EXPECT_EQ(import_table(file, o, &s).header.length_unit, "cm");
  EXPECT_EQ(s.notes.size(), 2u);
}

TEST_F(LammpsDumpTest, BadDumpsGiveOneLineNamingThePlace) {
  const std::string head =
      "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n"
      "0 1\n0 1\n0 1\n";
  auto expect = [&](const std::string& text, const std::string& part,
                    const std::set<long long>& types = {}) {
    const std::string msg = error_of(text, types);
    EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  };
  expect("frame,particle,x\n", "expected 'ITEM: TIMESTEP'");
  expect("", "no snapshot");
  expect(head + "ITEM: ATOMS id x y z\n1 0 0 0\n", "ends where an atom's line should follow");
  expect(head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0\n",
         "line 11: 3 fields where the ATOMS line has 4");
  expect(head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0 zero\n",
         "line 11: column 4: expected a number");
  expect(head + "ITEM: ATOMS id x y\n1 0 0\n2 0 0\n", "no z position");
  expect(head + "ITEM: ATOMS x y z\n1 0 0\n2 0 0\n", "no 'id' column");
  expect(head + "ITEM: ATOMS id x xu y z\n", "two columns give 'x'");
  expect(head + "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0 0\n", "no 'type' column", {1});
  expect(head + "ITEM: ATOMS id type x y z\n1 0.5 0 0 0\n2 1 0 0 0\n", "not a whole number", {1});
  expect("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS xy xz yz ff ff ff\n",
         "triclinic");
  expect("ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n1\nITEM: BOX BOUNDS ff ff ff\n1 0\n",
         "expected finite lo <= hi");
  expect("ITEM: TIMESTEP\n-3\n", "timestep: expected a whole number");
  expect("ITEM: TIMESTEP\n0\nITEM: ATOMS id x y z\n", "before the number of atoms and the box");
  expect(head +
             "ITEM: ATOMS id x y z\n1 0 0 0\n2 0 0 0\nITEM: TIMESTEP\n1\n"
             "ITEM: NUMBER OF ATOMS\n0\nITEM: BOX BOUNDS ff ff ff\n0 1\n0 1\n0 1\n"
             "ITEM: ATOMS id y x z\n",
         "differ from the first snapshot's");
}

}  // namespace
}  // namespace granmem
