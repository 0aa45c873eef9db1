// Bad input: one clear error line on stderr, a non-zero exit, no output or temporary file
// left behind, and any existing output byte-identical after the failed run.

#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "granmem/core/hdf5.hpp"
#include "run_granmem.hpp"

namespace granmem::testing {
namespace {

namespace fs = std::filesystem;

const char* kGoodTable =
    "frame,particle,x,y,z,ax,ay,az,radius,hole_contact\n"
    "0,1,0,0,0,0,0,1,1,0\n0,2,5,5,5,1,0,0,1,0\n"
    "1,1,1,0,0,0,1,1,1,0\n1,2,5,5,6,1,0,0,1,1\n"
    "2,1,1,1,0,0,1,0,1,0\n2,2,5,6,6,0,0,-1,1,0\n";

class BadInputTest : public GranmemTest {
 protected:
  // Good outputs to be left alone: run.h5 (+ run.xmf), out/ (an analysis), x.dump. Made
  // once per test suite, then copied into each test's work folder.
  static void SetUpTestSuite() {
    good_ =
        fs::temp_directory_path() / ("granmem-test-good-" + std::to_string(std::random_device{}()));
    fs::create_directories(good_);
    write_text(good_ / "good.csv", kGoodTable);
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"import", "good.csv", "--out", "run.h5", "--length-unit", "mm"},
          std::vector<std::string>{"analyze", "run.h5", "--out", "out"},
          std::vector<std::string>{"export", "run.h5", "--out", "x.dump"}}) {
      const RunResult r = run_granmem(args, good_, good_.string() + "-capture");
      ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    fs::remove_all(good_.string() + "-capture");
  }
  static void TearDownTestSuite() {
    std::error_code ec;
    fs::remove_all(good_, ec);
  }
  void make_good_outputs() {
    fs::copy(good_, work(), fs::copy_options::recursive | fs::copy_options::overwrite_existing);
    ASSERT_TRUE(fs::exists(in_work("run.xmf")));
    ASSERT_TRUE(fs::exists(in_work("out") / "per_frame.csv"));
    ASSERT_TRUE(fs::exists(in_work("x.dump")));
  }
  static inline fs::path good_;
};

// ---------------------------------------------------------------------------- CSV tables

struct BadTable {
  const char* name;
  const char* csv;
  std::vector<std::string> expected;  // parts of the error line, besides the file name
};

void PrintTo(const BadTable& c, std::ostream* os) {
  *os << c.name;
}

class BadTableTest : public BadInputTest, public ::testing::WithParamInterface<BadTable> {};

TEST_P(BadTableTest, ImportFailsCleanly) {
  make_good_outputs();
  const BadTable& c = GetParam();
  write_text(in_work("bad.csv"), c.csv);
  std::vector<std::string> expected = c.expected;
  expected.insert(expected.begin(), "bad.csv");
  // Over an existing run (not damaged, sidecar included).
  expect_clean_failure({"import", "bad.csv", "--out", "run.h5", "--length-unit", "mm"}, expected);
  // To a new file (not created), as a voxel table with a voxel size.
  expect_clean_failure({"import", "bad.csv", "--out", "new.h5", "--voxel-size", "0.5,0.5,2mm"},
                       expected);
}

INSTANTIATE_TEST_SUITE_P(
    Csv, BadTableTest,
    ::testing::Values(
        BadTable{"MissingZ",
                 "frame,particle,x,y\n0,1,1,2\n",
                 {"missing required column 'z'", "header has: frame, particle, x, y"}},
        BadTable{
            "MissingParticle", "x,y,z,frame\n1,2,3,0\n", {"missing required column 'particle'"}},
        BadTable{"MissingFrame", "particle,x,y,z\n1,1,2,3\n", {"missing required column 'frame'"}},
        BadTable{"NonNumericCoordinate",
                 "frame,particle,x,y,z\n0,1,1,2,3\n0,2,1,abc,3\n",
                 {"line 3, column 'y': expected a number, found 'abc'"}},
        BadTable{"NanCoordinate",
                 "frame,particle,x,y,z\n0,1,1,2,3\n0,2,nan,2,3\n",
                 {"line 3, column 'x': expected a finite coordinate"}},
        BadTable{"NaNCapitalised", "frame,particle,x,y,z\n0,1,1,2,NaN\n", {"line 2, column 'z'"}},
        BadTable{"EmptyCoordinate",
                 "frame,particle,x,y,z\n0,1,1,,3\n",
                 {"line 2, column 'y': expected a finite coordinate, found nothing or nan"}},
        BadTable{"InfiniteCoordinate",
                 "frame,particle,x,y,z\n0,1,1,2,inf\n",
                 {"line 2, column 'z': expected a finite coordinate, found infinity"}},
        BadTable{"SameParticleTwiceInAFrame",
                 "frame,particle,x,y,z\n0,1,1,2,3\n0,2,1,2,3\n1,1,1,2,3\n0,2,4,5,6\n",
                 {"line 5: particle 2 appears twice in frame 0 (first at line 3)"}},
        BadTable{"ZeroLengthAxis",
                 "frame,particle,x,y,z,ax,ay,az\n0,1,1,2,3,0,0,1\n1,1,1,2,3,0,0,0\n",
                 {"line 3: axis (ax,ay,az) has zero length"}},
        BadTable{"PartialAxis",
                 "frame,particle,x,y,z,ax,ay,az\n0,1,1,2,3,1,,0\n",
                 {"line 2: axis (ax,ay,az) must be three finite numbers or all empty"}},
        BadTable{"AxisWithoutAz",
                 "frame,particle,x,y,z,ax,ay\n0,1,1,2,3,1,0\n",
                 {"an axis needs all three columns ax, ay, az"}},
        BadTable{"FractionalFrame",
                 "frame,particle,x,y,z\n0.5,1,1,2,3\n",
                 {"line 2, column 'frame': expected an integer label"}},
        BadTable{"MissingParticleLabel",
                 "frame,particle,x,y,z\n0,,1,2,3\n",
                 {"line 2, column 'particle': expected an integer label, found nothing"}},
        BadTable{"HoleContactNotAFlag",
                 "frame,particle,x,y,z,hole_contact\n0,1,1,2,3,0\n0,2,1,2,3,2\n",
                 {"line 3, column 'hole_contact': expected 0 or 1"}},
        BadTable{"NegativeRadius",
                 "frame,particle,x,y,z,radius\n0,1,1,2,3,-1\n",
                 {"line 2, column 'radius': expected a positive radius"}},
        BadTable{"WrongFieldCount",
                 "frame,particle,x,y,z\n0,1,1,2,3\n0,2,1,2\n",
                 {"line 3: 4 fields, expected 5"}},
        BadTable{"HeaderOnly", "frame,particle,x,y,z\n", {"no rows after the header"}},
        BadTable{"Empty", "", {"empty file, expected a CSV header line"}},
        BadTable{"ColumnTwice",
                 "frame,particle,x,y,z,x\n0,1,1,2,3,4\n",
                 {"column 'x' appears twice in the header"}}),
    [](const ::testing::TestParamInfo<BadTable>& info) { return std::string(info.param.name); });

TEST_F(BadInputTest, ImportBadOptions) {
  make_good_outputs();
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--voxel-size", "0.5,0.5,2"},
                       {"--voxel-size needs a length unit"});
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--voxel-size", "1,2mm"},
                       {"--voxel-size '1,2mm': expected one size or three"});
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--voxel-size", "0,1,1mm"},
                       {"--voxel-size", "positive"});
  expect_clean_failure(
      {"import", "good.csv", "--out", "run.h5", "--length-unit", "mm", "--voxel-size", "1mm"},
      {"--voxel-size applies to voxel coordinates, but --length-unit is mm"});
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--length-unit", "inch"},
                       {"--length-unit", "inch"});
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--container", "0,0,0,1,1"},
                       {"--container", "expected six numbers"});
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--radius", "2"},
                       {"good.csv: has a radius column; --radius is for tables without one"});
  expect_clean_failure({"import", "nothere.csv", "--out", "run.h5"}, {"nothere.csv"});
  expect_clean_failure({"import", "good.csv", "--out", "nofolder/run.h5"},
                       {"nofolder/run.h5", "folder 'nofolder' does not exist"});
  expect_clean_failure({"import", "good.csv", "--out", "out"}, {"out: is a folder"});
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--columns", "POSITION_X"},
                       {"--columns 'POSITION_X': expected NAME=column,... e.g. POSITION_X=x"});
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--columns", "A=x,A=y"},
                       {"--columns 'A=x,A=y': A is named twice"});
  // A mapping onto a name the table already has: the header holds it twice.
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--columns", "y=x"},
                       {"column 'x' appears twice in the header"});
}

TEST_F(BadInputTest, ImportSidecarCannotBeWritten) {
  make_good_outputs();
  // The run's XDMF sidecar name is taken by a folder: the import fails before the existing
  // run.h5 is replaced (it used to replace run.h5 and then fail on the sidecar).
  fs::remove(in_work("run.xmf"));
  fs::create_directory(in_work("run.xmf"));
  expect_clean_failure({"import", "good.csv", "--out", "run.h5", "--length-unit", "cm"},
                       {"run.xmf: is a folder"});
}

// ---------------------------------------------------------------------------- HDF5 files

enum class Fault {
  none,
  no_h5md,            // an HDF5 file, but not H5MD
  no_position_value,  // /particles/grains/position/value missing
  no_position_step,   // .../position/step missing
  position_not_3d,    // .../position/value of shape [2,9]
  not_a_length_unit,  // .../position/value with unit "furlong"
  step_count,         // .../position/step with 3 entries for 2 frames
  axis_shape,         // .../axis/value of shape [2,3]
  radius_count,       // .../radius with 2 values for 3 grains
  duplicate_id,       // .../id 1,2,1
  box_size,           // .../box/edges with 2 values
  one_frame,          // a valid run of a single frame (analyze needs two)
};

// A run written by "another H5MD producer": 3 grains, 2 frames, each grain moving by
// (0,1,0) mm, with one part broken as `fault` says.
void write_h5md_run(const fs::path& path, Fault fault) {
  const hsize_t frames = fault == Fault::one_frame ? 1 : 2, n = 3;
  h5::File f = h5::File::create(path);
  if (fault != Fault::no_h5md) h5::create_group(f.id(), "/h5md");
  const h5::Handle grains = h5::create_group(f.id(), "/particles/grains");
  const h5::Handle pos = h5::create_group(f.id(), "/particles/grains/position");
  std::vector<double> x;
  for (hsize_t t = 0; t < frames; ++t) {
    for (hsize_t i = 0; i < n; ++i)
      x.insert(x.end(), {double(i) * 3, double(t), 0.0});
  }
  if (fault == Fault::position_not_3d) {
    h5::write(pos.get(), "value", x.data(), {frames, n * 3}, "mm");
  } else if (fault != Fault::no_position_value) {
    h5::write(pos.get(), "value", x.data(), {frames, n, 3},
              fault == Fault::not_a_length_unit ? "furlong" : "mm");
  }
  const std::vector<std::int64_t> step{0, 1, 2};
  const std::vector<double> time{0, 1, 2};
  if (fault != Fault::no_position_step) {
    h5::write(pos.get(), "step", step.data(), {fault == Fault::step_count ? hsize_t{3} : frames},
              "1");
  }
  h5::write(pos.get(), "time", time.data(), {frames}, "cycle");
  const std::vector<std::int64_t> id = fault == Fault::duplicate_id
                                           ? std::vector<std::int64_t>{1, 2, 1}
                                           : std::vector<std::int64_t>{1, 2, 3};
  h5::write(grains.get(), "id", id.data(), {n}, "1");
  const std::vector<double> radius{1, 1, 1};
  h5::write(grains.get(), "radius", radius.data(), {fault == Fault::radius_count ? hsize_t{2} : n},
            "mm");
  const std::vector<double> edges{10, 10, 10};
  h5::write(grains.get(), "box/edges", edges.data(),
            {fault == Fault::box_size ? hsize_t{2} : hsize_t{3}}, "mm");
  if (fault == Fault::axis_shape) {
    const std::vector<double> axis(frames * n, 1.0);
    h5::write(grains.get(), "axis/value", axis.data(), {frames, n}, "1");
  }
  f.close();
}

TEST_F(BadInputTest, HandWrittenH5mdRunIsReadable) {
  // The fault-free version of the files below works, so each failure is the fault's.
  write_h5md_run(in_work("other.h5"), Fault::none);
  const RunResult info = granmem_ok({"info", "other.h5"});
  EXPECT_NE(info.out.find("  frames      2 (steps 0 to 1)"), std::string::npos) << info.out;
  EXPECT_NE(info.out.find("  grains      3, mean radius 1 mm"), std::string::npos) << info.out;
  granmem_ok({"analyze", "other.h5", "--out", "a"});
  const Table d = read_columns(in_work("a") / "displacements.csv", {"particle", "dy", "dr"});
  EXPECT_EQ(d["particle"].values, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(d["dr"].values, (std::vector<double>{1, 1, 1}));
  granmem_ok({"export", "other.h5", "--out", "other.dump"});
}

struct BadRun {
  const char* name;
  Fault fault;
  std::vector<std::string> expected;  // parts of the error line, besides the file name
  bool info_ok = false;               // `info` may read it (only `analyze` must refuse)
};

void PrintTo(const BadRun& c, std::ostream* os) {
  *os << c.name;
}

class BadRunTest : public BadInputTest, public ::testing::WithParamInterface<BadRun> {};

TEST_P(BadRunTest, InfoAnalyzeExportFailCleanly) {
  make_good_outputs();
  const BadRun& c = GetParam();
  write_h5md_run(in_work("bad.h5"), c.fault);
  std::vector<std::string> expected = c.expected;
  expected.insert(expected.begin(), "bad.h5");
  expect_clean_failure({"analyze", "bad.h5", "--out", "out"}, expected);
  expect_clean_failure({"analyze", "bad.h5", "--out", "fresh"}, expected);
  if (c.info_ok) return;
  expect_clean_failure({"info", "bad.h5"}, expected);
  expect_clean_failure({"export", "bad.h5", "--out", "x.dump"}, expected);
  expect_clean_failure({"export", "bad.h5", "--out", "y.xyz"}, expected);
}

INSTANTIATE_TEST_SUITE_P(
    H5, BadRunTest,
    ::testing::Values(
        BadRun{"NotH5md", Fault::no_h5md, {"not a granmem/H5MD trajectory file (no /h5md group)"}},
        BadRun{"NoPositions",
               Fault::no_position_value,
               {"missing dataset /particles/grains/position/value"}},
        BadRun{"NoSteps",
               Fault::no_position_step,
               {"missing dataset /particles/grains/position/step"}},
        BadRun{"PositionsNot3d",
               Fault::position_not_3d,
               {"dataset /particles/grains/position/value has shape [2,9], expected "
                "[frames,grains,3]"}},
        BadRun{"NotALengthUnit",
               Fault::not_a_length_unit,
               {"dataset /particles/grains/position/value has unit 'furlong', expected one of m, "
                "cm, mm, um, voxel"}},
        BadRun{"StepCount",
               Fault::step_count,
               {"/particles/grains/position/step", "one entry per frame (2)"}},
        BadRun{"AxisShape",
               Fault::axis_shape,
               {"dataset /particles/grains/axis/value has shape [2,3], expected [2,3,3]"}},
        BadRun{"RadiusCount",
               Fault::radius_count,
               {"dataset /particles/grains/radius must hold one radius per grain (3)"}},
        BadRun{"DuplicateId", Fault::duplicate_id, {"grain id 1 appears twice"}},
        BadRun{
            "BoxSize", Fault::box_size, {"dataset /particles/grains/box/edges must hold 3 values"}},
        BadRun{"OneFrame",
               Fault::one_frame,
               {"needs at least two frames for displacements, has 1"},
               true}),
    [](const ::testing::TestParamInfo<BadRun>& info) { return std::string(info.param.name); });

TEST_F(BadInputTest, NotAnHdf5File) {
  make_good_outputs();
  write_text(in_work("notes.h5"), "frame,particle,x,y,z\n0,1,1,2,3\n");
  const std::vector<std::string> expected = {
      "notes.h5: not an HDF5 file (or truncated), expected a granmem/H5MD file"};
  expect_clean_failure({"info", "notes.h5"}, expected);
  expect_clean_failure({"analyze", "notes.h5", "--out", "out"}, expected);
  expect_clean_failure({"export", "notes.h5", "--out", "x.dump"}, expected);
}

TEST_F(BadInputTest, TruncatedRun) {
  make_good_outputs();
  const std::string whole = read_text(in_work("run.h5"));
  write_text(in_work("cut.h5"), whole.substr(0, whole.size() / 2));
  const std::vector<std::string> expected = {"cut.h5: cannot open HDF5 file (damaged?)"};
  expect_clean_failure({"info", "cut.h5"}, expected);
  expect_clean_failure({"analyze", "cut.h5", "--out", "out"}, expected);
  expect_clean_failure({"export", "cut.h5", "--out", "x.dump"}, expected);
}

TEST_F(BadInputTest, AnalysisOutputIsNotARun) {
  make_good_outputs();
  const std::vector<std::string> expected = {"out/analysis.h5",
                                             "not a granmem/H5MD trajectory file"};
  expect_clean_failure({"info", "out/analysis.h5"}, expected);
  expect_clean_failure({"analyze", "out/analysis.h5", "--out", "out"}, expected);
  expect_clean_failure({"export", "out/analysis.h5", "--out", "x.dump"}, expected);
}

// An output named like an input (by the same name, another path or a link) would destroy
// the input: refused before any work, for every command that reads and writes files.
TEST_F(BadInputTest, AnOutputThatIsAnInputIsRefused) {
  make_good_outputs();
  fs::create_symlink("good.csv", in_work("link.csv"));
  const std::vector<std::vector<std::string>> commands = {
      {"import", "good.csv", "--out", "good.csv", "--length-unit", "mm"},
      {"import", "good.csv", "--out", "./link.csv", "--length-unit", "mm"},
      {"export", "run.h5", "--out", "run.h5", "--format", "lammps"},
      {"link", "run.h5", "--out", "run.h5"},
      {"link", "run.h5", "x.dump", "--out", "new.h5", "--report", "x.dump"},
      {"locate", "x.dump", "--out", "x.dump", "--diameter", "10"},
      {"locate", "x.dump", "--out", "new.h5", "--csv", "x.dump", "--diameter", "10"},
      {"track", "x.dump", "--out", "x.dump", "--diameter", "10"},
      {"render", "run.h5", "--frame", "0", "--out", "run.h5"},
      {"render", "run.h5", "--frame", "0", "--out", "scan.tif", "--truth", "run.h5"}};
  for (const auto& args : commands)
    expect_clean_failure(args, {"is the input", "choose another name"});
  expect_clean_failure({"locate", "x.dump", "--out", "a.h5", "--csv", "./a.h5", "--diameter", "10"},
                       {"are one file"});
  expect_clean_failure({"track", "x.dump", "nothere.tif", "--out", "new.h5", "--diameter", "10"},
                       {"nothere.tif", "no such file"});
}

// A full disk, made by a file size limit of 4 KiB (SIGXFSZ ignored, so a write past it
// fails as with ENOSPC): one error line naming the output, exit 1, no crash, nothing left
// behind and nothing changed (an existing run.h5 and analysis included).
TEST_F(BadInputTest, AFullDiskIsOneErrorAndDamagesNothing) {
  make_good_outputs();
  const std::vector<std::vector<std::string>> commands = {
      {"import", "good.csv", "--out", "run.h5", "--length-unit", "mm"},
      {"analyze", "run.h5", "--out", "out"},
      {"simulate", "--grains", "60", "--box", "2cm", "--cycles", "1", "--period", "20ms", "--out",
       "run.h5"}};
  for (const auto& args : commands) {
    std::string cmd = "cd " + shell_quote(work().string()) + " && trap '' XFSZ && ulimit -f 4 && " +
                      shell_quote(GRANMEM_EXE);
    for (const std::string& a : args)
      cmd += " " + shell_quote(a);
    SCOPED_TRACE(cmd);
    const auto before = snapshot(work());
    const fs::path err = dir_ / "full.err";
    const int status = std::system((cmd + " > /dev/null 2> " + shell_quote(err.string())).c_str());
    ASSERT_TRUE(WIFEXITED(status)) << "ended by a signal";
    EXPECT_EQ(WEXITSTATUS(status), 1);
    // The error is the last line (simulate reports its deposit before).
    const std::string text = read_text(err);
    const std::size_t last = text.rfind('\n', text.size() - 2);
    const std::string message = text.substr(last == std::string::npos ? 0 : last + 1);
    EXPECT_EQ(message.find("granmem: error: "), 0u) << text;
    EXPECT_EQ(text.find("granmem: error: "), text.rfind("granmem: error: ")) << text;
    EXPECT_NE(message.find("(disk full?)"), std::string::npos) << message;
    EXPECT_EQ(message.find(".tmp-"), std::string::npos) << "names a temporary: " << message;
    EXPECT_EQ(snapshot(work()), before);
  }
}

TEST_F(BadInputTest, MissingFile) {
  make_good_outputs();
  expect_clean_failure({"info", "nothere.h5"}, {"nothere.h5"});
  expect_clean_failure({"analyze", "nothere.h5", "--out", "out"}, {"nothere.h5"});
  expect_clean_failure({"export", "nothere.h5", "--out", "x.dump"}, {"nothere.h5"});
}

// Absurd sizes are refused before anything is allocated, with what they would take.
TEST_F(BadInputTest, GrainsBeyondTheMachinesMemoryAreRefusedBeforeTheWork) {
  expect_clean_failure({"simulate", "--grains", "1e11", "--out", "big.h5", "--cycles", "1"},
                       {"deposit", "100000000000 grains", "more than half of this machine's"});
  EXPECT_FALSE(std::filesystem::exists(in_work("big.h5")));
}

TEST_F(BadInputTest, AnalyzeBadOptions) {
  make_good_outputs();
  const auto analyze = [](std::vector<std::string> extra) {
    std::vector<std::string> args = {"analyze", "run.h5", "--out", "out"};
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  expect_clean_failure(analyze({"--window", "7:9"}),
                       {"--window 7:9: no displacements in these frames"});
  expect_clean_failure(analyze({"--window", "2:1"}), {"--window", "after last frame"});
  expect_clean_failure(analyze({"--window", "1-2"}), {"--window '1-2'", "FIRST:LAST"});
  expect_clean_failure(analyze({"--pdf", "speed"}), {"pdf of 'speed': not a quantity of this run"});
  expect_clean_failure(analyze({"--pdf-range", "5:1"}), {"pdf: empty value range"});
  expect_clean_failure(analyze({"--pdf-scale", "log", "--pdf-range", "0:1"}),
                       {"logarithmic bins need a range above zero"});
  expect_clean_failure(analyze({"--pdf-bins", "0"}),
                       {"--pdf-bins: expected a whole number of bins, at least 1, got '0'"});
  expect_clean_failure(analyze({"--pdf-bins", "many"}),
                       {"--pdf-bins: expected a whole number of bins, at least 1, got 'many'"});
  expect_clean_failure(analyze({"--hole-contacts", "ignore"}), {"--hole-contacts", "ignore"});
  expect_clean_failure(analyze({"--wall-distance", "1"}),
                       {"excluding grains near the walls needs the container"});
  expect_clean_failure(analyze({"--wall-distance", "-1"}),
                       {"--wall-distance '-1': expected a non-negative length"});
  expect_clean_failure(analyze({"--wall-distance", "1 voxel", "--container", "0,0,0,9,9,9"}),
                       {"--wall-distance '1 voxel': cannot convert voxel to the run's unit mm"});
  expect_clean_failure(analyze({"--container", "0,0,0,-1,9,9"}),
                       {"--container", "each max must be greater than its min"});
  // The output folder is a file, or one of its outputs is a folder.
  expect_clean_failure({"analyze", "run.h5", "--out", "x.dump"},
                       {"x.dump: cannot create the output folder"});
  fs::remove(in_work("out") / "pdf_dr.csv");
  fs::create_directory(in_work("out") / "pdf_dr.csv");
  expect_clean_failure({"analyze", "run.h5", "--out", "out"}, {"pdf_dr.csv: is a folder"});
}

TEST_F(BadInputTest, ExportBadOptions) {
  make_good_outputs();
  expect_clean_failure({"export", "run.h5", "--out", "x.txt"},
                       {"--out x.txt: say --format lammps, extxyz, csv or lammps-data"});
  expect_clean_failure({"export", "run.h5", "--out", "x.dump", "--format", "pdb"},
                       {"--format", "pdb"});
  expect_clean_failure({"export", "run.h5", "--out", "nofolder/x.dump"},
                       {"nofolder/x.dump", "does not exist"});
}

TEST_F(BadInputTest, CommandLineErrors) {
  make_good_outputs();
  expect_clean_failure({}, {"A subcommand is required"});
  expect_clean_failure({"import", "good.csv"}, {"--out is required"});
  expect_clean_failure({"analyze", "run.h5", "--out", "out", "--bogus"}, {"--bogus"});
  expect_clean_failure({"--config", "nothere.toml", "info", "run.h5"}, {"nothere.toml"});
  // A bad value in the config file reads like one on the command line.
  // (CLI11 checks every section, whichever command runs: one bad file per command.)
  write_text(in_work("analyze.toml"), "[analyze]\npdf-bins = -2\n");
  write_text(in_work("import.toml"), "[import]\nlength-unit = \"ft\"\n");
  expect_clean_failure({"--config", "analyze.toml", "analyze", "run.h5", "--out", "out"},
                       {"--pdf-bins: expected a whole number of bins, at least 1, got '-2'"});
  expect_clean_failure({"--config", "import.toml", "import", "good.csv", "--out", "run.h5"},
                       {"--length-unit: ft not in {m,cm,mm,um,voxel}"});
  // A config that is not TOML, or names no option, says which line and why.
  write_text(in_work("header.toml"), "[info\n");
  write_text(in_work("equals.toml"), "[info]\nverbose 1\n");
  write_text(in_work("typo.toml"), "[info]\nverbsoe = 1\n");
  expect_clean_failure({"--config", "header.toml", "info", "run.h5"},
                       {"--config: '[info' is not a [command] header (no closing ']')"});
  expect_clean_failure({"--config", "equals.toml", "info", "run.h5"},
                       {"--config: 'verbose 1' in [info] is not 'option = value'"});
  expect_clean_failure({"--config", "typo.toml", "info", "run.h5"},
                       {"--config: no option info.verbsoe"});
}

}  // namespace
}  // namespace granmem::testing
