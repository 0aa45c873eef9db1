#include "granmem/core/particle_dump.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <limits>
#include <string>

#include "granmem/core/error.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

class ParticleDump : public granmem::testing::TempDirTest {
 protected:
  // Two frames of two grains (ids 10 and 20); grain 10 is not seen in the second frame.
  fs::path tiny_run(bool with_box, bool with_orientation) {
    Trajectories run;
    RunHeader& h = run.header;
    h.length_unit = "mm";
    h.time_unit = "s";
    h.id = {10, 20};
    h.radius = {0.5, 0.25};
    if (with_box) h.box = Box{Eigen::Vector3d(-1, 0, 0.5), Eigen::Vector3d(2, 3, 4)};
    h.has_axis = true;
    h.has_hole_contact = true;
    h.has_orientation = with_orientation;
    Frame f0 = Frame::unknown(h);
    f0.step = 1;
    f0.time = 0.5;
    f0.position.row(0) = Eigen::Vector3d(0.5, 1, 1.5);
    f0.position.row(1) = Eigen::Vector3d(1.25, 2, 3.5);
    f0.axis.row(0) = Eigen::Vector3d(0, 0, 1);
    f0.axis.row(1) = Eigen::Vector3d(1, 0, 0);
    f0.hole_contact = {1, 0};
    Frame f1 = Frame::unknown(h);
    f1.step = 2;
    f1.time = 1;
    f1.position.row(1) = Eigen::Vector3d(1.5, -2.25, 3);
    f1.axis.row(1) = Eigen::Vector3d(0, 1, 0);
    f1.hole_contact = {0, 1};
    if (with_orientation) {
      f0.orientation.row(0) = Eigen::Vector4d(1, 0, 0, 0);
      f0.orientation.row(1) = Eigen::Vector4d(0, 0, 0, 1);
      f1.orientation.row(0) = Eigen::Vector4d(kNaN, kNaN, kNaN, kNaN);
      f1.orientation.row(1) = Eigen::Vector4d(0.5, -0.5, 0.5, -0.5);
    }
    run.frames = {f0, f1};
    const fs::path p = path("tiny.h5");
    write_trajectories(p, run);
    return p;
  }
};

TEST_F(ParticleDump, LammpsDumpIsExact) {
  const TrajectoryReader run(tiny_run(true, false));
  const fs::path out = path("tiny.dump");
  write_particle_dump(run, out, DumpFormat::lammps);
  const std::string expected =
      "ITEM: TIMESTEP\n"
      "1\n"
      "ITEM: NUMBER OF ATOMS\n"
      "2\n"
      "ITEM: BOX BOUNDS ff ff ff\n"
      "-1 1\n"
      "0 3\n"
      "0.5 4.5\n"
      "ITEM: ATOMS id type x y z radius ax ay az hole_contact\n"
      "11 1 0.5 1 1.5 0.5 0 0 1 1\n"
      "21 1 1.25 2 3.5 0.25 1 0 0 0\n"
      "ITEM: TIMESTEP\n"
      "2\n"
      "ITEM: NUMBER OF ATOMS\n"
      "1\n"
      "ITEM: BOX BOUNDS ff ff ff\n"
      "-1 1\n"
      "0 3\n"
      "0.5 4.5\n"
      "ITEM: ATOMS id type x y z radius ax ay az hole_contact\n"
      "21 1 1.5 -2.25 3 0.25 0 1 0 1\n";
  EXPECT_EQ(read_text(out), expected);
}

TEST_F(ParticleDump, LammpsDumpWithOrientationAndNoBoxUsesTheBoundingBox) {
  const TrajectoryReader run(tiny_run(false, true));
  const fs::path out = path("tiny.dump");
  write_particle_dump(run, out, DumpFormat::lammps);
  const std::string expected =
      "ITEM: TIMESTEP\n"
      "1\n"
      "ITEM: NUMBER OF ATOMS\n"
      "2\n"
      "ITEM: BOX BOUNDS ff ff ff\n"
      "0.5 1.25\n"
      "1 2\n"
      "1.5 3.5\n"
      "ITEM: ATOMS id type x y z radius ax ay az quatw quati quatj quatk hole_contact\n"
      "11 1 0.5 1 1.5 0.5 0 0 1 1 0 0 0 1\n"
      "21 1 1.25 2 3.5 0.25 1 0 0 0 0 0 1 0\n"
      "ITEM: TIMESTEP\n"
      "2\n"
      "ITEM: NUMBER OF ATOMS\n"
      "1\n"
      "ITEM: BOX BOUNDS ff ff ff\n"
      "1.5 1.5\n"
      "-2.25 -2.25\n"
      "3 3\n"
      "ITEM: ATOMS id type x y z radius ax ay az quatw quati quatj quatk hole_contact\n"
      "21 1 1.5 -2.25 3 0.25 0 1 0 0.5 -0.5 0.5 -0.5 1\n";
  EXPECT_EQ(read_text(out), expected);
}

// OVITO reads an extended XYZ `orientation` as its Orientation property, (X, Y, Z, W): the
// scalar part goes last there, first in the LAMMPS dump's named columns.
TEST_F(ParticleDump, ExtendedXyzOrientationIsOvitosXyzw) {
  const TrajectoryReader run(tiny_run(true, true));
  const fs::path out = path("turned.extxyz");
  write_particle_dump(run, out, DumpFormat::extxyz);
  const std::string text = read_text(out);
  EXPECT_NE(text.find("Properties=id:I:1:pos:R:3:radius:R:1:axis:R:3:orientation:R:4:"),
            std::string::npos)
      << text;
  // Frame 1, grain 20: q = (w 0.5, x -0.5, y 0.5, z -0.5), after its axis (0 1 0).
  EXPECT_NE(text.find("\n20 1.5 -2.25 3 0.25 0 1 0 -0.5 0.5 -0.5 0.5 1\n"), std::string::npos)
      << text;
}

TEST_F(ParticleDump, ExtendedXyzIsExact) {
  const TrajectoryReader run(tiny_run(true, false));
  const fs::path out = path("tiny.extxyz");
  write_particle_dump(run, out, DumpFormat::extxyz);
  const std::string properties = " Properties=id:I:1:pos:R:3:radius:R:1:axis:R:3:hole_contact:I:1 ";
  const std::string expected =
      "2\n"
      "Lattice=\"2 0 0 0 3 0 0 0 4\" Origin=\"-1 0 0.5\" cell_origin=\"-1 0 0.5\"" +
      properties +
      "Time=0.5 Step=1 Units=mm pbc=\"F F F\"\n"
      "10 0.5 1 1.5 0.5 0 0 1 1\n"
      "20 1.25 2 3.5 0.25 1 0 0 0\n"
      "1\n"
      "Lattice=\"2 0 0 0 3 0 0 0 4\" Origin=\"-1 0 0.5\" cell_origin=\"-1 0 0.5\"" +
      properties +
      "Time=1 Step=2 Units=mm pbc=\"F F F\"\n"
      "20 1.5 -2.25 3 0.25 0 1 0 1\n";
  EXPECT_EQ(read_text(out), expected);
  // Per frame: the atom count, the comment line, then that many atom lines.
  std::size_t lines = 0;
  for (char c : expected)
    lines += c == '\n';
  EXPECT_EQ(lines, 2u + 2u + 2u + 1u);
}

TEST_F(ParticleDump, WrittenAtomicallyAndErrorsForAMissingFolder) {
  const fs::path h5 = tiny_run(true, true);
  const TrajectoryReader run(h5);
  write_particle_dump(run, path("a.xyz"), DumpFormat::extxyz);
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) {
    const std::string name = e.path().filename().string();
    EXPECT_TRUE(name == "tiny.h5" || name == "tiny.xmf" || name == "a.xyz") << name;
    ++files;
  }
  EXPECT_EQ(files, 3u);
  EXPECT_NE(read_text(path("a.xyz")).find(":orientation:R:4:"), std::string::npos);
  EXPECT_THROW(write_particle_dump(run, path("missing/a.dump"), DumpFormat::lammps), Error);
}

}  // namespace
}  // namespace granmem
