// The TOML --config file (and the command line overriding it), `granmem info`, and
// `granmem export` to a LAMMPS dump and extended XYZ.

#include <gtest/gtest.h>

#include <cmath>

#include "granmem/core/hdf5.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

namespace fs = std::filesystem;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// ------------------------------------------------------------------------------ --config

// Voxels of 0.5 x 0.5 x 2 mm. Grain 1 moves (1,2,2) mm, grain 2 (0,0,6) mm, grain 3 stays
// put but touches a neighbour through its hole in frame 0.
const char* kVoxelTable =
    "frame,particle,x,y,z,hole_contact\n"
    "0,1,2,4,1,0\n0,2,10,10,10,0\n0,3,10,10,5,1\n"
    "1,1,4,8,2,0\n1,2,10,10,13,0\n1,3,10,10,5,0\n";

const char* kConfig =
    "# options for the config tests\n"
    "[import]\n"
    "length-unit = \"voxel\"\n"
    "voxel-size = \"0.5,0.5,2mm\"\n"
    "container = \"0,0,0,20,20,20\"\n"
    "\n"
    "[analyze]\n"
    "subtract-drift = true\n"
    "hole-contacts = \"exclude\"\n"
    "pdf = \"dr\"\n"
    "pdf-bins = 7\n";

class ConfigTest : public GranmemTest {
 protected:
  void SetUp() override {
    GranmemTest::SetUp();
    write_text(in_work("voxels.csv"), kVoxelTable);
    write_text(in_work("granmem.toml"), kConfig);
  }
};

// A comma list may be a TOML array: the same options as kConfig's strings.
TEST_F(ConfigTest, ListsMayBeTomlArrays) {
  write_text(in_work("arrays.toml"),
             "[import]\nlength-unit = \"voxel\"\nvoxel-size = [0.5, 0.5, \"2mm\"]\n"
             "container = [0, 0, 0, 20, 20, 20]\n[analyze]\npdf = [\"dr\", \"dz\"]\n");
  granmem_ok({"--config", "arrays.toml", "import", "voxels.csv", "--out", "run.h5"});
  const RunResult info = granmem_ok({"info", "run.h5"});
  EXPECT_TRUE(contains(info.out, "  lengths     mm, voxel size (0.5, 0.5, 2) mm\n")) << info.out;
  EXPECT_TRUE(contains(info.out, "  box         lower (0, 0, 0), edges (10, 10, 40) mm\n"))
      << info.out;
  granmem_ok({"--config", "arrays.toml", "analyze", "run.h5", "--out", "a"});
  EXPECT_TRUE(fs::exists(in_work("a") / "pdf_dr.csv"));
  EXPECT_TRUE(fs::exists(in_work("a") / "pdf_dz.csv"));
  EXPECT_FALSE(fs::exists(in_work("a") / "pdf_dx.csv"));
}

TEST_F(ConfigTest, ImportSectionSetsTheOptions) {
  granmem_ok({"--config", "granmem.toml", "import", "voxels.csv", "--out", "run.h5"});
  const RunResult info = granmem_ok({"info", "run.h5"});
  EXPECT_TRUE(contains(info.out, "  lengths     mm, voxel size (0.5, 0.5, 2) mm\n")) << info.out;
  // The box is given in voxels and stored in mm.
  EXPECT_TRUE(contains(info.out, "  box         lower (0, 0, 0), edges (10, 10, 40) mm\n"))
      << info.out;
  EXPECT_TRUE(contains(info.out, "    import/length-unit = voxel\n")) << info.out;
  EXPECT_TRUE(contains(info.out, "    import/voxel-size = 0.5,0.5,2mm\n")) << info.out;

  // --config may also follow the command name.
  granmem_ok({"import", "voxels.csv", "--out", "after.h5", "--config", "granmem.toml"});
  EXPECT_TRUE(contains(granmem_ok({"info", "after.h5"}).out, "voxel size (0.5, 0.5, 2) mm"));
}

TEST_F(ConfigTest, MistypedKeyIsAnError) {
  // A typo must not be silently ignored: the run would not be what the file says.
  write_text(in_work("typo.toml"), "[import]\nvoxel-sise = \"1mm\"\n");
  const RunResult r = granmem({"--config", "typo.toml", "import", "voxels.csv", "--out", "run.h5"});
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.err, "voxel-sise")) << r.err;
  EXPECT_FALSE(fs::exists(in_work("run.h5")));
}

TEST_F(ConfigTest, CommandLineOverridesTheImportSection) {
  granmem_ok({"--config", "granmem.toml", "import", "voxels.csv", "--out", "run.h5", "--voxel-size",
              "1cm"});
  const RunResult info = granmem_ok({"info", "run.h5"});
  EXPECT_TRUE(contains(info.out, "  lengths     cm, voxel size (1, 1, 1) cm\n")) << info.out;
  EXPECT_TRUE(contains(info.out, "    import/voxel-size = 1cm\n")) << info.out;
  granmem_ok({"analyze", "run.h5", "--out", "a"});
  const Table d = read_columns(in_work("a") / "displacements.csv", {"particle", "dz"});
  EXPECT_EQ(d["dz"].values, (std::vector<double>{1, 3, 0}));  // 1 voxel = 1 cm
}

TEST_F(ConfigTest, AnalyzeSectionSetsTheOptions) {
  granmem_ok({"--config", "granmem.toml", "import", "voxels.csv", "--out", "run.h5"});
  granmem_ok({"--config", "granmem.toml", "analyze", "run.h5", "--out", "a"});
  // hole-contacts = exclude drops grain 3; subtract-drift removes the mean (0.5, 1, 4) mm.
  const Table d =
      read_columns(in_work("a") / "displacements.csv", {"particle", "dx", "dy", "dz", "dr"});
  EXPECT_EQ(d["particle"].values, (std::vector<double>{1, 2}));
  EXPECT_EQ(d["dx"].values, (std::vector<double>{0.5, -0.5}));
  EXPECT_EQ(d["dy"].values, (std::vector<double>{1, -1}));
  EXPECT_EQ(d["dz"].values, (std::vector<double>{-2, 2}));
  EXPECT_EQ(d["dr"].values, (std::vector<double>{std::sqrt(5.25), std::sqrt(5.25)}));
  const Table p =
      read_columns(in_work("a") / "per_frame.csv", {"n", "drift_x", "drift_y", "drift_z"});
  EXPECT_EQ(p["n"].values, (std::vector<double>{2}));
  EXPECT_EQ(p["drift_x"].values, (std::vector<double>{0.5}));
  EXPECT_EQ(p["drift_y"].values, (std::vector<double>{1}));
  EXPECT_EQ(p["drift_z"].values, (std::vector<double>{4}));
  // pdf = "dr", 7 bins.
  EXPECT_EQ(read_columns(in_work("a") / "pdf_dr.csv", {"count"}).rows(), 7u);
  EXPECT_FALSE(fs::exists(in_work("a") / "pdf_dz.csv"));
  // The options used are recorded in analysis.h5.
  const h5::File f = h5::File::open(in_work("a") / "analysis.h5");
  const h5::Handle params = h5::open_group(f, "/parameters/analyze");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "pdf-bins"), "7");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "hole-contacts"), "exclude");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "pdf"), "dr");
}

TEST_F(ConfigTest, CommandLineOverridesTheAnalyzeSection) {
  granmem_ok({"--config", "granmem.toml", "import", "voxels.csv", "--out", "run.h5"});
  granmem_ok({"--config", "granmem.toml", "analyze", "run.h5", "--out", "b", "--pdf-bins", "3",
              "--hole-contacts", "keep", "--pdf", "dz", "--subtract-drift=false"});
  const Table d = read_columns(in_work("b") / "displacements.csv", {"particle", "dz"});
  EXPECT_EQ(d["particle"].values, (std::vector<double>{1, 2, 3}));  // grain 3 kept
  EXPECT_EQ(d["dz"].values, (std::vector<double>{2, 6, 0}));        // drift not removed
  EXPECT_EQ(read_columns(in_work("b") / "pdf_dz.csv", {"count"}).rows(), 3u);
  EXPECT_FALSE(fs::exists(in_work("b") / "pdf_dr.csv"));
  const h5::File f = h5::File::open(in_work("b") / "analysis.h5");
  const h5::Handle params = h5::open_group(f, "/parameters/analyze");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "pdf-bins"), "3");
  EXPECT_EQ(h5::read_string_attribute(params.get(), "hole-contacts"), "keep");
}

// ------------------------------------------------------------------------------- info

// mm, three frames; grain 20 is missing from frame 1 and grain 30 has no radius.
const char* kExportTable =
    "frame,particle,x,y,z,ax,ay,az,radius,hole_contact\n"
    "0,10,1,2,3,0,0,1,0.5,0\n0,20,4,5,6,0,2,0,0.75,1\n0,30,7,8,9,-1,0,0,,0\n"
    "1,10,1.5,2,3,0,0,1,0.5,0\n1,30,7,8,9.25,-1,0,0,,0\n"
    "2,10,1.5,2.5,3,1,0,0,0.5,0\n2,20,4,5,6.5,0,0,4,0.75,0\n2,30,7,8,9.5,0,-3,0,,1\n";

TEST_F(GranmemTest, InfoNamesFramesGrainsUnitsAndDatasets) {
  write_text(in_work("t.csv"), kExportTable);
  granmem_ok({"import", "t.csv", "--out", "run.h5", "--length-unit", "mm"});
  // `granmem --version`: "granmem 0.1.0 (commit ...)"; the store names the release.
  std::istringstream said(granmem_ok({"--version"}).out);
  std::string name, version;
  said >> name >> version;
  ASSERT_EQ(name, "granmem");
  ASSERT_FALSE(version.empty());

  const RunResult r = granmem_ok({"info", "run.h5"});
  EXPECT_EQ(r.err, "");
  const std::string& out = r.out;
  for (const std::string& line : std::vector<std::string>{
           "run.h5: trajectory store (H5MD), group /particles/grains\n",
           "  producer    granmem " + version,
           "  frames      3 (steps 0 to 2), sample end_of_cycle, time in cycle\n",
           std::string("  grains      3, mean radius 0.625 mm, radius unknown for 1\n"),
           std::string("  lengths     mm\n"),
           std::string("  box         none\n"),
           std::string("  per grain   position, cavity axis, hole contact flag\n"),
           std::string("    import/length-unit = mm\n"),
           std::string("  datasets\n"),
           std::string("    /particles/grains/position/value [3,3,3] [mm]\n"),
           std::string("    /particles/grains/position/step [3]\n"),
           std::string("    /particles/grains/position/time [3] [cycle]\n"),
           std::string("    /particles/grains/axis/value [3,3,3]\n"),
           std::string("    /particles/grains/hole_contact/value [3,3]\n"),
           std::string("    /particles/grains/id [3]\n"),
           std::string("    /particles/grains/radius [3] [mm]\n"),
       }) {
    EXPECT_TRUE(contains(out, line)) << "missing: " << line << "\nin:\n" << out;
  }
  EXPECT_FALSE(contains(out, "box/edges"));  // no box given

  // The ids and radii are the table's; the missing radius is NaN.
  const h5::File f = h5::File::open(in_work("run.h5"));
  EXPECT_EQ(h5::read<std::int64_t>(f, "/particles/grains/id"),
            (std::vector<std::int64_t>{10, 20, 30}));
  const std::vector<double> radius = h5::read<double>(f, "/particles/grains/radius");
  ASSERT_EQ(radius.size(), 3u);
  EXPECT_EQ(radius[0], 0.5);
  EXPECT_EQ(radius[1], 0.75);
  EXPECT_TRUE(std::isnan(radius[2]));
  // Grain 20 in frame 1 is NaN.
  const std::vector<double> x = h5::read<double>(f, "/particles/grains/position/value");
  ASSERT_EQ(x.size(), 27u);
  EXPECT_TRUE(std::isnan(x[9 + 3]));
  EXPECT_EQ(x[9 + 6 + 2], 9.25);
}

// ------------------------------------------------------------------------------- export

TEST_F(GranmemTest, ExportLammpsDumpHasTheAtomsOfEachFrame) {
  write_text(in_work("t.csv"), kExportTable);
  granmem_ok({"import", "t.csv", "--out", "run.h5", "--length-unit", "mm"});
  const RunResult r = granmem_ok({"export", "run.h5", "--out", "run.dump"});
  EXPECT_EQ(r.out, "wrote run.dump (lammps, 3 frames)\n");
  // Without a container the box is the grains' bounding box; grain 20 is not in frame 1.
  // Axes are stored as unit vectors; grain 30's radius is unknown.
  const std::string atoms = "ITEM: ATOMS id type x y z radius ax ay az hole_contact\n";
  EXPECT_EQ(read_text(in_work("run.dump")),
            "ITEM: TIMESTEP\n0\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS ff ff ff\n"
            "1 7\n2 8\n3 9\n" +
                atoms +
                "11 1 1 2 3 0.5 0 0 1 0\n"
                "21 1 4 5 6 0.75 0 1 0 1\n"
                "31 1 7 8 9 nan -1 0 0 0\n"
                "ITEM: TIMESTEP\n1\nITEM: NUMBER OF ATOMS\n2\nITEM: BOX BOUNDS ff ff ff\n"
                "1.5 7\n2 8\n3 9.25\n" +
                atoms +
                "11 1 1.5 2 3 0.5 0 0 1 0\n"
                "31 1 7 8 9.25 nan -1 0 0 0\n"
                "ITEM: TIMESTEP\n2\nITEM: NUMBER OF ATOMS\n3\nITEM: BOX BOUNDS ff ff ff\n"
                "1.5 7\n2.5 8\n3 9.5\n" +
                atoms +
                "11 1 1.5 2.5 3 0.5 1 0 0 0\n"
                "21 1 4 5 6.5 0.75 0 0 1 0\n"
                "31 1 7 8 9.5 nan 0 -1 0 1\n");

  // With a container, every frame has its bounds; --format overrides the file name.
  granmem_ok({"import", "t.csv", "--out", "boxed.h5", "--length-unit", "mm", "--container",
              "0,0,0,10,10,20"});
  granmem_ok({"export", "boxed.h5", "--out", "boxed.txt", "--format", "lammps"});
  const std::string boxed = read_text(in_work("boxed.txt"));
  std::size_t bounds = 0;
  for (std::size_t at = 0;
       (at = boxed.find("ITEM: BOX BOUNDS ff ff ff\n0 10\n0 10\n0 20\n", at)) != std::string::npos;
       ++at)
    ++bounds;
  EXPECT_EQ(bounds, 3u) << boxed;
}

// Frame 2 of kExportTable (mm, box 0-10, 0-10, 0-20) exported as a dump, read by LAMMPS
// (`read_dump`), and written back by it to back.dump with `write_dump ... DUMP_ARGS`.
class LammpsRoundTrip : public GranmemTest {
 protected:
  void frame_2_through_lammps(const std::string& dump_args);
};

#ifdef GRANMEM_LAMMPS_EXE
void LammpsRoundTrip::frame_2_through_lammps(const std::string& dump_args) {
  write_text(in_work("t.csv"), kExportTable);
  granmem_ok({"import", "t.csv", "--out", "boxed.h5", "--length-unit", "mm", "--container",
              "0,0,0,10,10,20"});
  granmem_ok({"export", "boxed.h5", "--out", "run.dump"});
  write_text(in_work("read.lmp"),
             "units si\natom_style sphere\nboundary f f f\n"
             "region box block 0 1 0 1 0 1\ncreate_box 1 box\n"
             "read_dump run.dump 2 x y z add keep box yes\n"
             "write_dump all custom back.dump " +
                 dump_args + " format float %.17g\n");
  const std::string cmd = "cd " + testing::shell_quote(work().string()) + " && " +
                          testing::shell_quote(GRANMEM_LAMMPS_EXE) +
                          " -in read.lmp -log none -screen none > lmp.out 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << read_text(in_work("lmp.out"));
}
#endif

// LAMMPS itself reads the dump: `read_dump` adds every grain of a frame with its id (the
// granmem id + 1) and position, and writes them back.
TEST_F(LammpsRoundTrip, ExportLammpsDumpIsReadByLammps) {
#ifndef GRANMEM_LAMMPS_EXE
  GTEST_SKIP() << "no lmp when the build was configured (Debian's lammps)";
#else
  ASSERT_NO_FATAL_FAILURE(frame_2_through_lammps("id type x y z modify sort id"));
  std::istringstream back(read_text(in_work("back.dump")));
  std::string line;
  while (std::getline(back, line) && line.rfind("ITEM: ATOMS", 0) != 0) {
  }
  EXPECT_EQ(line, "ITEM: ATOMS id type x y z");
  std::vector<std::vector<double> > atoms;
  for (double id, type, x, y, z; back >> id >> type >> x >> y >> z;)
    atoms.push_back({id, type, x, y, z});
  // Frame 2 of the table: grains 10, 20 and 30.
  EXPECT_EQ(atoms, (std::vector<std::vector<double> >{
                       {11, 1, 1.5, 2.5, 3}, {21, 1, 4, 5, 6.5}, {31, 1, 7, 8, 9.5}}));
#endif
}

// And back: a dump LAMMPS writes (scaled coordinates, its own column order) is imported
// as the same grains at the same places, ids and box included: granmem -> LAMMPS -> granmem.
TEST_F(LammpsRoundTrip, ADumpWrittenByLammpsImportsAsTheSameGrains) {
#ifndef GRANMEM_LAMMPS_EXE
  GTEST_SKIP() << "no lmp when the build was configured (Debian's lammps)";
#else
  ASSERT_NO_FATAL_FAILURE(frame_2_through_lammps("type zs id ys xs modify"));
  const RunResult r = granmem_ok(
      {"import", "back.dump", "--out", "back.h5", "--length-unit", "mm", "--types", "1"});
  EXPECT_NE(r.out.find("(lammps dump): 1 frames, 3 grains, 0 missing"), std::string::npos) << r.out;
  const TrajectoryReader back(in_work("back.h5"));
  EXPECT_EQ(back.header().id, (std::vector<std::int64_t>{10, 20, 30}));
  ASSERT_TRUE(back.header().box);
  EXPECT_EQ(back.header().box->edges, Eigen::Vector3d(10, 10, 20));
  ASSERT_EQ(back.frame_count(), 1u);
  const Frame f = back.read_frame(0);
  EXPECT_EQ(f.step, 2);
  const Eigen::Matrix3d expected{{1.5, 2.5, 3}, {4, 5, 6.5}, {7, 8, 9.5}};
  EXPECT_LT((f.position - expected).cwiseAbs().maxCoeff(), 1e-12) << f.position;
#endif
}

// A frame as a LAMMPS data file: LAMMPS starts from it with every grain (id + 1), its
// diameter, its mass from the density, at its place in metres.
TEST_F(LammpsRoundTrip, ADataFileStartsALammpsRun) {
#ifndef GRANMEM_LAMMPS_EXE
  GTEST_SKIP() << "no lmp when the build was configured (Debian's lammps)";
#else
  write_text(in_work("t.csv"),
             "frame,particle,x,y,z,radius\n0,4,1,2,3,0.5\n0,9,4,5,6,0.75\n"
             "1,4,1,2,3.5,0.5\n1,9,4,5,6.25,0.75\n");
  granmem_ok({"import", "t.csv", "--out", "run.h5", "--length-unit", "mm"});
  expect_clean_failure({"export", "run.h5", "--out", "run.data"}, {"density"});
  granmem_ok({"export", "run.h5", "--out", "run.data", "--frame", "0", "--density", "1.2g/cm^3"});
  write_text(in_work("start.lmp"),
             "units si\natom_style sphere\nboundary f f f\nread_data run.data\n"
             "write_dump all custom back.dump id x y z diameter mass modify sort id "
             "format float %.17g\n");
  const std::string cmd = "cd " + testing::shell_quote(work().string()) + " && " +
                          testing::shell_quote(GRANMEM_LAMMPS_EXE) +
                          " -in start.lmp -log none -screen none > lmp.out 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << read_text(in_work("lmp.out"));
  std::istringstream back(read_text(in_work("back.dump")));
  std::string line;
  while (std::getline(back, line) && line.rfind("ITEM: ATOMS", 0) != 0) {
  }
  std::vector<std::vector<double> > atoms;
  for (double id, x, y, z, d, m; back >> id >> x >> y >> z >> d >> m;)
    atoms.push_back({id, x, y, z, d, m});
  ASSERT_EQ(atoms.size(), 2u);
  const double pi = std::acos(-1.0);
  const std::vector<std::vector<double> > expected{
      {5, 1e-3, 2e-3, 3e-3, 1e-3, 1200 * pi / 6 * 1e-9},
      {10, 4e-3, 5e-3, 6e-3, 1.5e-3, 1200 * pi / 6 * 3.375e-9}};
  for (std::size_t a = 0; a < 2; ++a) {
    for (std::size_t k = 0; k < 6; ++k)
      EXPECT_NEAR(atoms[a][k], expected[a][k], 1e-12 * std::abs(expected[a][k])) << a << " " << k;
  }
#endif
}

TEST_F(GranmemTest, ExportExtendedXyz) {
  write_text(in_work("t.csv"), kExportTable);
  granmem_ok({"import", "t.csv", "--out", "run.h5", "--length-unit", "mm"});
  const RunResult r = granmem_ok({"export", "run.h5", "--out", "run.xyz"});
  EXPECT_EQ(r.out, "wrote run.xyz (extxyz, 3 frames)\n");
  std::vector<std::string> lines;
  std::istringstream s(read_text(in_work("run.xyz")));
  for (std::string line; std::getline(s, line);)
    lines.push_back(line);
  ASSERT_EQ(lines.size(), 14u);  // (2 + 3) + (2 + 2) + (2 + 3)
  EXPECT_EQ(lines[0], "3");
  EXPECT_EQ(lines[1],
            "Lattice=\"6 0 0 0 6 0 0 0 6\" Origin=\"1 2 3\" cell_origin=\"1 2 3\" "
            "Properties=id:I:1:pos:R:3:radius:R:1:axis:R:3:hole_contact:I:1 Time=0 Step=0 "
            "Units=mm pbc=\"F F F\"");
  EXPECT_EQ(lines[2], "10 1 2 3 0.5 0 0 1 0");
  EXPECT_EQ(lines[5], "2");
  EXPECT_TRUE(contains(lines[6], " Step=1 ")) << lines[6];
  EXPECT_EQ(lines[8], "30 7 8 9.25 nan -1 0 0 0");
  EXPECT_EQ(lines[9], "3");
  EXPECT_EQ(lines[13], "30 7 8 9.5 nan 0 -1 0 1");
}

// trackpy's long table: a row per grain seen, and `import` reads it back to the same run.
TEST_F(GranmemTest, ExportCsvIsTheTrackTableImportReadsBack) {
  write_text(in_work("t.csv"), kExportTable);
  granmem_ok({"import", "t.csv", "--out", "run.h5", "--length-unit", "mm"});
  EXPECT_EQ(granmem_ok({"export", "run.h5", "--out", "tracks.csv"}).out,
            "wrote tracks.csv (csv, 3 frames)\n");
  std::vector<std::string> lines;
  std::istringstream s(read_text(in_work("tracks.csv")));
  for (std::string line; std::getline(s, line);)
    lines.push_back(line);
  ASSERT_EQ(lines.size(), 2u + 8u);  // comment, names, 3 + 2 + 3 grains seen
  EXPECT_EQ(lines[1], "frame,particle,time,x,y,z,radius,ax,ay,az,hole_contact");
  EXPECT_EQ(lines[2], "0,10,0,1,2,3,0.5,0,0,1,0");
  EXPECT_EQ(lines[9], "2,30,2,7,8,9.5,nan,0,-1,0,1");

  granmem_ok({"import", "tracks.csv", "--out", "again.h5", "--length-unit", "mm"});
  const h5::File a = h5::File::open(in_work("run.h5")), b = h5::File::open(in_work("again.h5"));
  for (const char* d : {"/particles/grains/id", "/particles/grains/position/step"})
    EXPECT_EQ(h5::read<std::int64_t>(a, d), h5::read<std::int64_t>(b, d)) << d;
  for (const char* d : {"/particles/grains/position/value", "/particles/grains/axis/value",
                        "/particles/grains/radius"}) {
    const std::vector<double> x = h5::read<double>(a, d), y = h5::read<double>(b, d);
    ASSERT_EQ(x.size(), y.size()) << d;
    for (std::size_t k = 0; k < x.size(); ++k)
      EXPECT_TRUE(x[k] == y[k] || (std::isnan(x[k]) && std::isnan(y[k]))) << d << " " << k;
  }
}

}  // namespace
}  // namespace granmem::testing
