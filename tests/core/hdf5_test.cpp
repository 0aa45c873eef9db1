#include "granmem/core/hdf5.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "granmem/core/error.hpp"
#include "temp_dir.hpp"

#include "checks.hpp"

namespace granmem {
namespace {

using testing::error_message;

class Hdf5 : public granmem::testing::TempDirTest {};

TEST_F(Hdf5, TableRoundTripKeepsOrderUnitsTypesAndBits) {
  Table t;
  Column& z = t.add("z_last_by_name", "mm");
  Column& frame = t.add("frame", "", true);
  Column& a = t.add("a", "1/s");
  z.values = {1.0 / 3.0, -0.0, std::numeric_limits<double>::denorm_min(),
              std::numeric_limits<double>::quiet_NaN()};
  frame.values = {0, -7, 9007199254740991.0, 3};
  a.values = {1e300, -1e-300, 0.1, std::numeric_limits<double>::infinity()};
  const auto p = path("t.h5");
  {
    h5::File f = h5::File::create(p);
    h5::write_table(f.id(), "/tables/one", t);
    f.close();
  }
  const h5::File f = h5::File::open(p);
  const Table back = h5::read_table(f, "/tables/one");
  ASSERT_EQ(back.columns().size(), 3u);
  const char* names[] = {"z_last_by_name", "frame", "a"};  // the `columns` order, not by name
  for (std::size_t c = 0; c < 3; ++c) {
    const Column& in = t.columns()[c];
    const Column& out = back.columns()[c];
    EXPECT_EQ(out.name, names[c]);
    EXPECT_EQ(out.unit, in.unit);
    EXPECT_EQ(out.integer, in.integer);
    ASSERT_EQ(out.values.size(), in.values.size());
    EXPECT_EQ(std::memcmp(out.values.data(), in.values.data(), 4 * sizeof(double)), 0) << in.name;
  }
  const std::vector<h5::DatasetInfo> sets = h5::list_datasets(f, "/tables");
  ASSERT_EQ(sets.size(), 3u);
  EXPECT_EQ(sets[0].path, "/tables/one/a");  // name order
  EXPECT_EQ(sets[0].unit, "1/s");
  EXPECT_EQ(sets[1].path, "/tables/one/frame");
  EXPECT_EQ(sets[1].unit, "1");  // dimensionless is written "1"
  EXPECT_EQ(sets[1].dims, (std::vector<hsize_t>{4}));
  // The int64 dataset reads as exact integers.
  EXPECT_EQ(h5::read<std::int64_t>(f, "/tables/one/frame"),
            (std::vector<std::int64_t>{0, -7, 9007199254740991, 3}));
}

TEST_F(Hdf5, FramesGrowOneAtATime) {
  const auto p = path("frames.h5");
  {
    h5::File f = h5::File::create(p);
    h5::Handle set = h5::create_frames<double>(f.id(), "/g/value", {2, 3}, "cm");
    for (int t = 0; t < 3; ++t) {
      double frame[6];
      for (int i = 0; i < 6; ++i)
        frame[i] = 10 * t + i;
      h5::append_frame(set.get(), frame);
    }
    set.reset();
    f.close();
  }
  const h5::File f = h5::File::open(p);
  const h5::Handle set = h5::open_dataset(f, "/g/value");
  EXPECT_EQ(h5::shape(set.get()), (std::vector<hsize_t>{3, 2, 3}));
  EXPECT_EQ(h5::shape_text(h5::shape(set.get())), "[3,2,3]");
  double frame[6];
  h5::read_frame(f, set.get(), "/g/value", 1, frame);
  for (int i = 0; i < 6; ++i)
    EXPECT_EQ(frame[i], 10 + i);
  const std::string msg =
      error_message([&] { h5::read_frame(f, set.get(), "/g/value", 3, frame); });
  EXPECT_NE(msg.find(p.string() + ": /g/value has no frame 3"), std::string::npos) << msg;
  EXPECT_EQ(h5::read_string_attribute(set.get(), "unit"), std::string("cm"));
  EXPECT_EQ(h5::read_string_attribute(set.get(), "absent"), std::nullopt);
}

// A full disk, made by a file size limit (writes past 64 KiB fail, as with ENOSPC): closing
// the file must say so in one Error, and the process must end normally. A failed close
// once went on to close the file again, and HDF5's exit handler closed it once more: both
// crashed. In a child process, whose exit is the point.
TEST_F(Hdf5, AFullDiskIsOneErrorAtCloseAndNoCrash) {
  const std::string file = path("full.h5").string();
  const pid_t child = fork();
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);  // the write fails with EFBIG instead
    const rlimit limit{64 << 10, 64 << 10};
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      h5::File f = h5::File::create(file);
      {
        h5::Handle set = h5::create_frames<double>(f.id(), "/g/value", {1000, 3}, "cm");
        std::vector<double> frame(3000, 1.0);
        for (int t = 0; t < 20; ++t)
          h5::append_frame(set.get(), frame.data());
      }
      f.close();
    } catch (const Error& e) {
      const std::string msg = e.what();
      std::exit(msg.find(file + ": writing the HDF5 file failed") == 0 ? 3 : 4);
    }
    std::exit(5);  // no error: the full disk went unnoticed
  }
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status)) << "the child ended by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 3);
}

TEST_F(Hdf5, MissingObjectsNameFileAndPath) {
  const auto p = path("x.h5");
  {
    h5::File f = h5::File::create(p);
    const double v = 1;
    h5::write(f.id(), "/a/b", &v, {1}, "m");
    f.close();
  }
  const h5::File f = h5::File::open(p);
  EXPECT_TRUE(h5::exists(f.id(), "/a/b"));
  EXPECT_FALSE(h5::exists(f.id(), "/a/c"));
  EXPECT_FALSE(h5::exists(f.id(), "/x/y/z"));
  std::string msg = error_message([&] { h5::read<double>(f, "/a/c"); });
  EXPECT_NE(msg.find(p.string() + ": missing dataset /a/c"), std::string::npos) << msg;
  msg = error_message([&] { h5::open_group(f, "/nope"); });
  EXPECT_NE(msg.find(p.string() + ": missing group /nope"), std::string::npos) << msg;
  msg = error_message([&] { h5::open_dataset(f, "/a"); });
  EXPECT_NE(msg.find(p.string() + ": /a is not a dataset"), std::string::npos) << msg;
  EXPECT_EQ(h5::read<double>(f, "/a/b"), (std::vector<double>{1}));
}

}  // namespace
}  // namespace granmem
