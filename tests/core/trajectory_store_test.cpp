#include "granmem/core/trajectory_store.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "granmem/core/error.hpp"
#include "granmem/core/hdf5.hpp"
#include "granmem/core/version.hpp"
#include "granmem/core/xdmf.hpp"
#include "temp_dir.hpp"

#include "checks.hpp"

namespace granmem {
namespace {

using testing::error_message;

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A random run with every optional part: axes, orientations, hole_contact, a scan's standard
// errors (position and axis), box, voxel size,
// radii (one unknown), scattered ids, observables, parameters; grain (t+1) % N is missing in
// frame t (NaN position and axis), and a few extreme values are planted.
Trajectories random_run(std::uint64_t seed, std::size_t frames, std::size_t grains) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1e3, 1e3);
  std::normal_distribution<double> g(0, 1);
  Trajectories run;
  RunHeader& h = run.header;
  h.length_unit = "mm";
  h.time_unit = "s";
  h.sample = kSampleFullCompression;
  std::set<std::int64_t> ids;
  std::uniform_int_distribution<std::int64_t> id_dist(-(std::int64_t{1} << 62),
                                                      std::int64_t{1} << 62);
  while (ids.size() < grains)
    ids.insert(id_dist(rng));
  h.id.assign(ids.begin(), ids.end());
  std::shuffle(h.id.begin(), h.id.end(), rng);  // ids need not be sorted
  for (std::size_t i = 0; i < grains; ++i)
    h.radius.push_back(std::abs(u(rng)) + 1e-3);
  h.radius[grains / 2] = kNaN;
  h.box = Box{Eigen::Vector3d(-1.5, 0.25, u(rng)), Eigen::Vector3d(10.0 / 3.0, 7.0, 1e-3)};
  h.voxel_size = Eigen::Vector3d(0.1, 0.1, 0.075);
  h.has_axis = h.has_orientation = h.has_hole_contact = true;
  h.has_position_error = h.has_axis_error = true;
  h.creator_name = "granmem-test";
  h.creator_version = "9.8.7-test";
  h.author = "A. Tester";
  h.parameters = {{"import/length_unit", "voxel"},
                  {"import/voxel_size", "0.1,0.1,0.075mm"},
                  {"analyze/bins", "50"},
                  {"top_level_key", "value with spaces"}};
  for (std::size_t t = 0; t < frames; ++t) {
    Frame f = Frame::unknown(h);
    f.step = 10 * std::int64_t(t) - 3;
    f.time = 0.25 * double(t) + 1e-9 * u(rng);
    for (std::size_t i = 0; i < grains; ++i) {
      const auto r = Eigen::Index(i);
      f.hole_contact[i] = std::uint8_t(rng() & 1);
      Eigen::Vector4d q(g(rng), g(rng), g(rng), g(rng));
      f.orientation.row(r) = q.normalized();
      if (i == (t + 1) % grains) continue;  // missing grain: NaN position and axis
      f.position.row(r) = Eigen::Vector3d(u(rng), u(rng), u(rng));
      f.axis.row(r) = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
      f.position_error.row(r) = Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseAbs() * 1e-5;
      f.axis_error[i] = std::abs(u(rng)) * 1e-5;
    }
    run.frames.push_back(std::move(f));
  }
  if (frames > 0 && grains > 2) {
    run.frames[0].position(2, 0) = std::numeric_limits<double>::denorm_min();
    run.frames[0].position(2, 1) = -0.0;
    run.frames[0].position(2, 2) = std::numeric_limits<double>::max();
    run.frames.back().orientation.row(0) = Eigen::Vector4d(kNaN, kNaN, kNaN, kNaN);
  }
  Observable force;
  force.unit = "N";
  for (std::size_t t = 0; t < frames; ++t) {
    force.value.push_back(u(rng));
    force.step.push_back(run.frames[t].step);
    force.time.push_back(run.frames[t].time);
  }
  if (!force.value.empty()) force.value[0] = kNaN;
  run.observables["wall_force"] = force;
  Observable lid;
  lid.unit = "mm";
  lid.value = {1.5, 1.25, -0.5};
  lid.step = {0, 100, 200};
  lid.time = {0.0, 0.5, 1.0};
  run.observables["lid_height"] = lid;
  return run;
}

// Bit-for-bit comparison of two double arrays (NaN payloads included).
::testing::AssertionResult same_bits(const double* a, const double* b, std::size_t n,
                                     const std::string& what) {
  if (n == 0 || std::memcmp(a, b, n * sizeof(double)) == 0) return ::testing::AssertionSuccess();
  for (std::size_t i = 0; i < n; ++i) {
    if (std::memcmp(a + i, b + i, sizeof(double)) != 0) {
      return ::testing::AssertionFailure()
             << what << " differs at " << i << ": " << a[i] << " vs " << b[i];
    }
  }
  return ::testing::AssertionFailure();
}

void expect_same_header(const RunHeader& a, const RunHeader& b) {
  EXPECT_EQ(a.length_unit, b.length_unit);
  EXPECT_EQ(a.time_unit, b.time_unit);
  EXPECT_EQ(a.sample, b.sample);
  EXPECT_EQ(a.id, b.id);
  ASSERT_EQ(a.radius.size(), b.radius.size());
  EXPECT_TRUE(same_bits(a.radius.data(), b.radius.data(), a.radius.size(), "radius"));
  ASSERT_EQ(a.box.has_value(), b.box.has_value());
  if (a.box) {
    EXPECT_TRUE(same_bits(a.box->lower.data(), b.box->lower.data(), 3, "box lower"));
    EXPECT_TRUE(same_bits(a.box->edges.data(), b.box->edges.data(), 3, "box edges"));
  }
  ASSERT_EQ(a.voxel_size.has_value(), b.voxel_size.has_value());
  if (a.voxel_size) {
    EXPECT_TRUE(same_bits(a.voxel_size->data(), b.voxel_size->data(), 3, "voxel size"));
  }
  EXPECT_EQ(a.has_axis, b.has_axis);
  EXPECT_EQ(a.has_orientation, b.has_orientation);
  EXPECT_EQ(a.has_hole_contact, b.has_hole_contact);
  EXPECT_EQ(a.has_position_error, b.has_position_error);
  EXPECT_EQ(a.has_axis_error, b.has_axis_error);
  EXPECT_EQ(a.creator_name, b.creator_name);
  EXPECT_EQ(a.creator_version, b.creator_version);
  EXPECT_EQ(a.author, b.author);
  EXPECT_EQ(a.parameters, b.parameters);
}

void expect_same_frame(const Frame& a, const Frame& b, std::size_t t) {
  const std::string at = "frame " + std::to_string(t) + " ";
  EXPECT_EQ(a.step, b.step) << at;
  EXPECT_TRUE(same_bits(&a.time, &b.time, 1, at + "time"));
  ASSERT_EQ(a.position.rows(), b.position.rows()) << at;
  EXPECT_TRUE(same_bits(a.position.data(), b.position.data(), std::size_t(a.position.size()),
                        at + "position"));
  ASSERT_EQ(a.axis.rows(), b.axis.rows()) << at;
  EXPECT_TRUE(same_bits(a.axis.data(), b.axis.data(), std::size_t(a.axis.size()), at + "axis"));
  ASSERT_EQ(a.orientation.rows(), b.orientation.rows()) << at;
  EXPECT_TRUE(same_bits(a.orientation.data(), b.orientation.data(),
                        std::size_t(a.orientation.size()), at + "orientation"));
  EXPECT_EQ(a.hole_contact, b.hole_contact) << at;
  ASSERT_EQ(a.position_error.rows(), b.position_error.rows()) << at;
  EXPECT_TRUE(same_bits(a.position_error.data(), b.position_error.data(),
                        std::size_t(a.position_error.size()), at + "position_error"));
  ASSERT_EQ(a.axis_error.size(), b.axis_error.size()) << at;
  EXPECT_TRUE(
      same_bits(a.axis_error.data(), b.axis_error.data(), a.axis_error.size(), at + "axis_error"));
}

void expect_same_observables(const std::map<std::string, Observable>& a,
                             const std::map<std::string, Observable>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (const auto& [name, oa] : a) {
    ASSERT_EQ(b.count(name), 1u) << name;
    const Observable& ob = b.at(name);
    EXPECT_EQ(oa.unit, ob.unit) << name;
    EXPECT_EQ(oa.step, ob.step) << name;
    ASSERT_EQ(oa.value.size(), ob.value.size()) << name;
    ASSERT_EQ(oa.time.size(), ob.time.size()) << name;
    EXPECT_TRUE(same_bits(oa.value.data(), ob.value.data(), oa.value.size(), name + " value"));
    EXPECT_TRUE(same_bits(oa.time.data(), ob.time.data(), oa.time.size(), name + " time"));
  }
}

void expect_same_run(const Trajectories& a, const Trajectories& b) {
  expect_same_header(a.header, b.header);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t t = 0; t < a.frames.size(); ++t)
    expect_same_frame(a.frames[t], b.frames[t], t);
  expect_same_observables(a.observables, b.observables);
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1))
    ++n;
  return n;
}

class TrajectoryStore : public granmem::testing::TempDirTest {
 protected:
  // A good store to damage in the error tests.
  fs::path good_store(const std::string& name = "good.h5") {
    const fs::path p = path(name);
    write_trajectories(p, random_run(7, 4, 5));
    return p;
  }

  // Copies `from` to `to` and deletes the link `object` in the copy with the HDF5 C API.
  static void copy_without(const fs::path& from, const fs::path& to, const std::string& object) {
    fs::copy_file(from, to, fs::copy_options::overwrite_existing);
    const hid_t f = H5Fopen(to.string().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    EXPECT_GE(H5Ldelete(f, object.c_str(), H5P_DEFAULT), 0) << object;
    H5Fclose(f);
  }

  // A hand-made minimal store: /h5md (optional) and position/{value,step,time}.
  struct Minimal {
    bool h5md = true;
    std::vector<hsize_t> dims{2, 3, 3};
    std::size_t steps = 2;
    std::size_t times = 2;
    std::string unit = "mm";
    std::size_t ids = 3;
  };
  static void write_minimal(const fs::path& p, const Minimal& m) {
    h5::File f = h5::File::create(p);
    if (m.h5md) h5::create_group(f.id(), "/h5md");
    h5::Handle pos = h5::create_group(f.id(), "/particles/grains/position");
    std::size_t n = 1;
    for (hsize_t d : m.dims)
      n *= d;
    std::vector<double> value(n);
    for (std::size_t i = 0; i < n; ++i)
      value[i] = 0.5 * double(i);
    h5::write(pos.get(), "value", value.data(), m.dims, m.unit);
    std::vector<std::int64_t> step(m.steps);
    for (std::size_t i = 0; i < m.steps; ++i)
      step[i] = std::int64_t(i) * 5;
    h5::write(pos.get(), "step", step.data(), {m.steps}, "1");
    std::vector<double> time(m.times, 1.0);
    h5::write(pos.get(), "time", time.data(), {m.times}, "s");
    std::vector<std::int64_t> id(m.ids, 4);
    for (std::size_t i = 0; i < m.ids; ++i)
      id[i] = 100 + std::int64_t(i);
    h5::write(f.id(), "/particles/grains/id", id.data(), {m.ids}, "1");
    f.close();
  }
};

TEST_F(TrajectoryStore, RoundTripIsBitForBit) {
  const Trajectories run = random_run(42, 6, 9);
  const fs::path p = path("run.h5");
  write_trajectories(p, run);
  EXPECT_EQ(listing(), (std::vector<std::string>{"run.h5", "run.xmf"}));  // no temp left
  const Trajectories back = read_trajectories(p);
  expect_same_run(run, back);
  // Spot checks against the planted values, so that a reader returning the input cannot pass.
  EXPECT_EQ(back.frames[0].position(2, 0), std::numeric_limits<double>::denorm_min());
  EXPECT_TRUE(std::signbit(back.frames[0].position(2, 1)));
  EXPECT_TRUE(std::isnan(back.frames[0].position(1, 0)));  // grain 1 missing in frame 0
  EXPECT_TRUE(std::isnan(back.frames[3].axis(4, 2)));      // grain 4 missing in frame 3
  EXPECT_EQ(back.frames[5].step, 47);
  EXPECT_TRUE(std::isnan(back.header.radius[4]));
  EXPECT_EQ(back.header.parameters.at("top_level_key"), "value with spaces");
  EXPECT_EQ(back.header.parameters.at("import/voxel_size"), "0.1,0.1,0.075mm");
  EXPECT_EQ(back.observables.at("lid_height").step, (std::vector<std::int64_t>{0, 100, 200}));
}

TEST_F(TrajectoryStore, MinimalRunWithoutOptionalPartsRoundTrips) {
  Trajectories run;
  run.header.length_unit = "voxel";
  run.header.time_unit = "cycle";
  run.header.id = {3, 1, 2};
  run.header.radius = {kNaN, kNaN, kNaN};
  run.header.author = "someone";
  for (int t = 0; t < 3; ++t) {
    Frame f = Frame::unknown(run.header);
    f.step = t;
    f.time = t;
    f.position.row(t) = Eigen::Vector3d(t, 2 * t, -t);
    run.frames.push_back(f);
  }
  const fs::path p = path("plain.h5");
  write_trajectories(p, run);
  const Trajectories back = read_trajectories(p);
  // The writer fills in its own version when the header names none.
  EXPECT_EQ(back.header.creator_version, std::string(kVersion));
  run.header.creator_version = kVersion;
  expect_same_run(run, back);
  EXPECT_FALSE(back.header.box.has_value());
  EXPECT_FALSE(back.header.voxel_size.has_value());
  EXPECT_FALSE(back.header.has_axis || back.header.has_orientation || back.header.has_hole_contact);
  EXPECT_EQ(back.frames[2].position(2, 1), 4.0);
  EXPECT_EQ(back.header.creator_name, "granmem");
}

TEST_F(TrajectoryStore, RunWithoutFramesRoundTrips) {
  Trajectories run = random_run(3, 0, 4);
  const fs::path p = path("empty.h5");
  write_trajectories(p, run);
  const Trajectories back = read_trajectories(p);
  EXPECT_TRUE(back.frames.empty());
  expect_same_run(run, back);
}

TEST_F(TrajectoryStore, ReaderStreamsTheWrittenFrames) {
  const Trajectories run = random_run(99, 7, 6);
  const fs::path p = path("stream.h5");
  {
    TrajectoryWriter w(p, run.header);
    for (std::size_t t = 0; t < run.frames.size(); ++t) {
      EXPECT_EQ(w.frame_count(), t);
      w.append(run.frames[t]);
    }
    for (const auto& [name, obs] : run.observables)
      w.set_observable(name, obs);
    EXPECT_FALSE(fs::exists(p));  // nothing under the real name before commit
    w.commit();
  }
  const TrajectoryReader r(p);
  EXPECT_EQ(r.file_name(), p.string());
  EXPECT_EQ(r.particles_group(), "/particles/grains");
  expect_same_header(run.header, r.header());
  ASSERT_EQ(r.frame_count(), run.frames.size());
  for (std::size_t t = 0; t < run.frames.size(); ++t) {
    EXPECT_EQ(r.steps()[t], run.frames[t].step);
    EXPECT_TRUE(same_bits(&r.times()[t], &run.frames[t].time, 1, "time"));
  }
  // Out of order too: each frame is read on its own.
  for (std::size_t t : {6u, 0u, 3u, 3u, 1u, 5u, 2u, 4u})
    expect_same_frame(run.frames[t], r.read_frame(t), t);
  expect_same_observables(run.observables, r.observables());
  const std::string msg = error_message([&] { (void)r.read_frame(7); });
  EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("no frame 7"), std::string::npos) << msg;
}

TEST_F(TrajectoryStore, UncommittedWriterLeavesNothingBehind) {
  const Trajectories run = random_run(5, 3, 4);
  const fs::path p = path("new.h5");
  {
    TrajectoryWriter w(p, run.header);
    w.append(run.frames[0]);
    w.append(run.frames[1]);
  }
  EXPECT_TRUE(listing().empty());
  EXPECT_THROW(TrajectoryReader{p}, Error);
}

TEST_F(TrajectoryStore, UncommittedWriterLeavesAnExistingFileIntact) {
  const fs::path p = path("run.h5");
  const Trajectories first = random_run(1, 3, 4);
  write_trajectories(p, first);
  const std::string h5_before = read_text(p);
  const std::string xmf_before = read_text(xdmf_path(p));
  ASSERT_FALSE(h5_before.empty());
  {
    const Trajectories second = random_run(2, 5, 8);
    TrajectoryWriter w(p, second.header);
    for (const Frame& f : second.frames)
      w.append(f);
    w.set_observable("other", second.observables.at("lid_height"));
  }
  EXPECT_EQ(read_text(p), h5_before);
  EXPECT_EQ(read_text(xdmf_path(p)), xmf_before);
  EXPECT_EQ(listing(), (std::vector<std::string>{"run.h5", "run.xmf"}));
  expect_same_run(first, read_trajectories(p));
}

TEST_F(TrajectoryStore, FrameThatDoesNotMatchTheHeaderIsRejected) {
  const Trajectories run = random_run(11, 2, 5);
  const fs::path p = path("bad.h5");
  {
    TrajectoryWriter w(p, run.header);
    w.append(run.frames[0]);
    Frame short_frame = run.frames[1];
    short_frame.position.conservativeResize(4, 3);
    const std::string msg = error_message([&] { w.append(short_frame); });
    EXPECT_NE(msg.find(p.string() + " frame 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("4 rows, expected 5"), std::string::npos) << msg;

    Frame no_axis = run.frames[1];
    no_axis.axis.resize(0, 3);
    EXPECT_THROW(w.append(no_axis), Error);
    Frame bad_orientation = run.frames[1];
    bad_orientation.orientation.conservativeResize(6, 4);
    EXPECT_THROW(w.append(bad_orientation), Error);
    Frame bad_flags = run.frames[1];
    bad_flags.hole_contact.pop_back();
    EXPECT_THROW(w.append(bad_flags), Error);
    Frame bad_errors = run.frames[1];
    bad_errors.position_error.conservativeResize(4, 3);
    EXPECT_THROW(w.append(bad_errors), Error);
    Frame bad_axis_errors = run.frames[1];
    bad_axis_errors.axis_error.push_back(0);
    EXPECT_THROW(w.append(bad_axis_errors), Error);
    EXPECT_EQ(w.frame_count(), 1u);  // rejected frames are not counted
    Observable bad;
    bad.value = {1, 2};
    bad.step = {1};
    bad.time = {1, 2};
    EXPECT_THROW(w.set_observable("bad", bad), Error);
  }
  EXPECT_TRUE(listing().empty());

  // Fields the run does not declare are rejected too.
  RunHeader plain;
  plain.id = {1, 2};
  plain.radius = {1, 1};
  TrajectoryWriter w(path("plain.h5"), plain);
  Frame f = Frame::unknown(plain);
  f.hole_contact = {0, 1};
  EXPECT_THROW(w.append(f), Error);
  f.hole_contact.clear();
  f.axis = Vectors3::Zero(2, 3);
  EXPECT_THROW(w.append(f), Error);
  f.axis.resize(0, 3);
  f.position_error = Vectors3::Zero(2, 3);
  EXPECT_THROW(w.append(f), Error);
  f.position_error.resize(0, 3);
  f.axis_error = {0, 0};
  EXPECT_THROW(w.append(f), Error);
}

TEST_F(TrajectoryStore, AppendAfterCommitIsAnErrorAndLeavesTheFileIntact) {
  const Trajectories run = random_run(13, 2, 3);
  const fs::path p = path("done.h5");
  TrajectoryWriter w(p, run.header);
  w.append(run.frames[0]);
  w.commit();
  const std::string before = read_text(p);
  const std::string msg = error_message([&] { w.append(run.frames[1]); });  // crashed before
  EXPECT_NE(msg.find(p.string() + ": cannot append after commit()"), std::string::npos) << msg;
  EXPECT_THROW(w.set_observable("late", run.observables.at("lid_height")), Error);
  EXPECT_EQ(w.frame_count(), 1u);
  EXPECT_THROW(w.commit(), Error);  // a second commit is refused, not half done
  EXPECT_EQ(read_text(p), before);
  EXPECT_EQ(read_trajectories(p).frames.size(), 1u);
}

TEST_F(TrajectoryStore, InvalidHeaderIsRejectedBeforeAnythingIsWritten) {
  RunHeader h;
  h.id = {1, 2, 1};
  h.radius = {1, 1, 1};
  const std::string msg = error_message([&] { TrajectoryWriter w(path("x.h5"), h); });
  EXPECT_NE(msg.find("grain id 1 appears twice"), std::string::npos) << msg;
  EXPECT_TRUE(listing().empty());
  EXPECT_THROW(TrajectoryWriter(path("sub/x.h5"), RunHeader{}), Error);  // missing folder
}

// Units as H5MD's units module has them: a `unit` on every quantity with a physical
// dimension (an SI symbol), none on steps, ids, directions, orientations and flags.
TEST_F(TrajectoryStore, EveryDatasetHasTheExpectedShapeAndUnit) {
  const fs::path p = path("units.h5");
  write_trajectories(p, random_run(8, 3, 4));
  const h5::File f = h5::File::open(p);
  std::map<std::string, std::pair<std::vector<hsize_t>, std::string>> got;
  for (const h5::DatasetInfo& d : h5::list_datasets(f))
    got[d.path] = {d.dims, d.unit};
  using V = std::vector<hsize_t>;
  const std::map<std::string, std::pair<V, std::string>> expected = {
      {"/observables/lid_height/step", {V{3}, ""}},
      {"/observables/lid_height/time", {V{3}, "s"}},
      {"/observables/lid_height/value", {V{3}, "mm"}},
      {"/observables/wall_force/step", {V{3}, ""}},
      {"/observables/wall_force/time", {V{3}, "s"}},
      {"/observables/wall_force/value", {V{3}, "N"}},
      {"/parameters/voxel_size", {V{3}, "mm"}},
      {"/particles/grains/axis/step", {V{3}, ""}},
      {"/particles/grains/axis/time", {V{3}, "s"}},
      {"/particles/grains/axis/value", {V{3, 4, 3}, ""}},
      {"/particles/grains/axis_error/step", {V{3}, ""}},
      {"/particles/grains/axis_error/time", {V{3}, "s"}},
      {"/particles/grains/axis_error/value", {V{3, 4}, "rad"}},
      {"/particles/grains/box/edges", {V{3}, "mm"}},
      {"/particles/grains/box/offset", {V{3}, "mm"}},
      {"/particles/grains/hole_contact/step", {V{3}, ""}},
      {"/particles/grains/hole_contact/time", {V{3}, "s"}},
      {"/particles/grains/hole_contact/value", {V{3, 4}, ""}},
      {"/particles/grains/id", {V{4}, ""}},
      {"/particles/grains/orientation/step", {V{3}, ""}},
      {"/particles/grains/orientation/time", {V{3}, "s"}},
      {"/particles/grains/orientation/value", {V{3, 4, 4}, ""}},
      {"/particles/grains/position/step", {V{3}, ""}},
      {"/particles/grains/position/time", {V{3}, "s"}},
      {"/particles/grains/position/value", {V{3, 4, 3}, "mm"}},
      {"/particles/grains/position_error/step", {V{3}, ""}},
      {"/particles/grains/position_error/time", {V{3}, "s"}},
      {"/particles/grains/position_error/value", {V{3, 4, 3}, "mm"}},
      {"/particles/grains/radius", {V{4}, "mm"}},
  };
  EXPECT_EQ(got, expected);
  // The H5MD header: version attribute and sample attribute.
  const h5::Handle pos = h5::open_group(f, "/particles/grains/position");
  EXPECT_EQ(h5::read_string_attribute(pos.get(), "sample"), std::string(kSampleFullCompression));
  const h5::Handle creator = h5::open_group(f, "/h5md/creator");
  EXPECT_EQ(h5::read_string_attribute(creator.get(), "name"), std::string("granmem-test"));
  const h5::Handle h5md = h5::open_group(f, "/h5md");
  EXPECT_EQ(h5::attribute_names(h5md.get()), (std::vector<std::string>{"version"}));
}

TEST_F(TrajectoryStore, XdmfSidecarDescribesEveryFrame) {
  const Trajectories run = random_run(21, 4, 7);
  const fs::path p = path("run.h5");
  write_trajectories(p, run);
  ASSERT_EQ(xdmf_path(p), path("run.xmf"));
  ASSERT_TRUE(fs::exists(path("run.xmf")));
  const std::string x = read_text(path("run.xmf"));
  EXPECT_EQ(x.rfind("<?xml", 0), 0u);
  EXPECT_EQ(count(x, "<Xdmf"), 1u);
  EXPECT_EQ(count(x, "</Xdmf>"), 1u);
  // One temporal collection holding one uniform grid per frame.
  EXPECT_EQ(count(x, "<Grid "), 5u);
  EXPECT_EQ(count(x, "</Grid>"), 5u);
  EXPECT_EQ(count(x, "GridType=\"Uniform\""), 4u);
  EXPECT_EQ(count(x, "CollectionType=\"Temporal\""), 1u);
  EXPECT_EQ(count(x, "<DataItem"), count(x, "</DataItem>"));
  EXPECT_EQ(count(x, "<Attribute "), count(x, "</Attribute>"));
  EXPECT_EQ(count(x, "<Geometry "), 4u);
  for (const Frame& f : run.frames) {
    EXPECT_NE(x.find("<Grid Name=\"step " + std::to_string(f.step) + "\""), std::string::npos);
  }
  EXPECT_EQ(count(x, "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"7\"/>"), 4u);
  // Referenced by file name only, so that the pair can be moved together.
  EXPECT_EQ(x.find(dir_.string()), std::string::npos);
  EXPECT_EQ(count(x, ">run.h5:/particles/grains/position/value</DataItem>"), 4u);
  EXPECT_EQ(count(x, ">run.h5:/particles/grains/axis/value</DataItem>"), 4u);
  EXPECT_EQ(count(x, ">run.h5:/particles/grains/hole_contact/value</DataItem>"), 4u);
  EXPECT_EQ(count(x, ">run.h5:/particles/grains/position_error/value</DataItem>"), 4u);
  EXPECT_EQ(count(x, ">run.h5:/particles/grains/axis_error/value</DataItem>"), 4u);
  EXPECT_EQ(count(x, ">run.h5:/particles/grains/radius</DataItem>"), 4u);
  EXPECT_EQ(count(x, ">run.h5:/particles/grains/id</DataItem>"), 4u);
  // Frame 2's coordinates: start (2,0,0), stride 1, count (1,7,3) of a [4,7,3] dataset.
  EXPECT_NE(x.find("<DataItem Dimensions=\"3 3\" Format=\"XML\">2 0 0  1 1 1  1 7 3</DataItem>\n"
                   "  <DataItem Dimensions=\"4 7 3\" NumberType=\"Float\" Precision=\"8\" "
                   "Format=\"HDF\">run.h5:/particles/grains/position/value</DataItem>"),
            std::string::npos);
  for (const Frame& f : run.frames) {
    std::ostringstream time;
    time.precision(17);
    time << "<Time Value=\"" << f.time << "\"/>";
    EXPECT_EQ(count(x, time.str()), 1u) << time.str();
  }

  // A run without axes or flags has no such attributes; the sidecar of x.store is x.xmf.
  Trajectories plain;
  plain.header.id = {1};
  plain.header.radius = {1};
  plain.frames.push_back(Frame::unknown(plain.header));
  write_trajectories(path("x.store"), plain);
  const std::string y = read_text(path("x.xmf"));
  EXPECT_EQ(count(y, "<Grid "), 2u);
  EXPECT_EQ(y.find("axis"), std::string::npos);
  EXPECT_EQ(y.find("hole_contact"), std::string::npos);
  EXPECT_NE(y.find(">x.store:/particles/grains/position/value<"), std::string::npos);

  // A file name with XML's special characters is escaped, so the sidecar stays XML.
  write_trajectories(path("a&b<c>.h5"), plain);
  const std::string z = read_text(path("a&b<c>.xmf"));
  EXPECT_NE(z.find(">a&amp;b&lt;c&gt;.h5:/particles/grains/position/value<"), std::string::npos);
  EXPECT_EQ(z.find("a&b"), std::string::npos);
}

TEST_F(TrajectoryStore, HandMadeMinimalStoreIsRead) {
  // The positive control for the damaged files below.
  const fs::path p = path("minimal.h5");
  write_minimal(p, {});
  const Trajectories run = read_trajectories(p);
  EXPECT_EQ(run.header.length_unit, "mm");
  EXPECT_EQ(run.header.time_unit, "s");
  EXPECT_EQ(run.header.id, (std::vector<std::int64_t>{100, 101, 102}));
  ASSERT_EQ(run.header.radius.size(), 3u);
  EXPECT_TRUE(std::isnan(run.header.radius[0]));
  ASSERT_EQ(run.frames.size(), 2u);
  EXPECT_EQ(run.frames[1].step, 5);
  EXPECT_EQ(run.frames[1].position(2, 2), 0.5 * 17);
  EXPECT_EQ(run.header.sample, kSampleEndOfCycle);
}

TEST_F(TrajectoryStore, NonHdf5FileIsAnError) {
  const fs::path p = path("notes.h5");
  write_text(p, "this is a text file, not HDF5\n");
  const std::string msg = error_message([&] { TrajectoryReader r(p); });
  EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("not an HDF5 file"), std::string::npos) << msg;
  const std::string missing = error_message([&] { read_trajectories(path("absent.h5")); });
  EXPECT_NE(missing.find(path("absent.h5").string()), std::string::npos) << missing;
  EXPECT_NE(missing.find("no such file"), std::string::npos) << missing;
  write_text(p, "");
  EXPECT_THROW(read_trajectories(p), Error);
}

TEST_F(TrajectoryStore, TruncatedFileIsAnError) {
  const fs::path good = good_store();
  const fs::path cut = path("cut.h5");
  fs::copy_file(good, cut);
  fs::resize_file(cut, fs::file_size(good) / 2);
  const std::string msg = error_message([&] { read_trajectories(cut); });
  EXPECT_NE(msg.find(cut.string()), std::string::npos) << msg;
  // Cut just after the superblock as well.
  fs::resize_file(cut, 200);
  const std::string msg2 = error_message([&] { read_trajectories(cut); });
  EXPECT_NE(msg2.find(cut.string()), std::string::npos) << msg2;
}

TEST_F(TrajectoryStore, FileWithoutH5mdIsAnError) {
  const fs::path p = path("no_h5md.h5");
  Minimal m;
  m.h5md = false;
  write_minimal(p, m);
  const std::string msg = error_message([&] { TrajectoryReader r(p); });
  EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("/h5md"), std::string::npos) << msg;

  const fs::path q = path("no_h5md_copy.h5");
  copy_without(good_store(), q, "/h5md");
  const std::string msg2 = error_message([&] { TrajectoryReader r(q); });
  EXPECT_NE(msg2.find(q.string()), std::string::npos) << msg2;
  EXPECT_NE(msg2.find("/h5md"), std::string::npos) << msg2;
}

TEST_F(TrajectoryStore, MissingPositionValueIsAnError) {
  const fs::path p = path("no_position.h5");
  copy_without(good_store(), p, "/particles/grains/position/value");
  const std::string msg = error_message([&] { TrajectoryReader r(p); });
  EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("/particles/grains/position/value"), std::string::npos) << msg;
}

TEST_F(TrajectoryStore, PositionOfWrongShapeIsAnError) {
  for (const std::vector<hsize_t>& dims :
       {std::vector<hsize_t>{2, 3, 2}, std::vector<hsize_t>{2, 9},
        std::vector<hsize_t>{2, 3, 3, 1}}) {
    const fs::path p = path("shape.h5");
    Minimal m;
    m.dims = dims;
    write_minimal(p, m);
    const std::string msg = error_message([&] { TrajectoryReader r(p); });
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("/particles/grains/position/value has shape " + h5::shape_text(dims)),
              std::string::npos)
        << msg;
  }
}

TEST_F(TrajectoryStore, StepOrTimeOfWrongLengthIsAnError) {
  const fs::path p = path("steps.h5");
  Minimal m;
  m.steps = 3;
  write_minimal(p, m);
  const std::string msg = error_message([&] { TrajectoryReader r(p); });
  EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("/particles/grains/position/step"), std::string::npos) << msg;

  m.steps = 2;
  m.times = 1;
  write_minimal(p, m);
  const std::string msg2 = error_message([&] { TrajectoryReader r(p); });
  EXPECT_NE(msg2.find("/particles/grains/position/step and /time"), std::string::npos) << msg2;

  const fs::path q = path("no_step.h5");
  copy_without(good_store(), q, "/particles/grains/position/step");
  const std::string msg3 = error_message([&] { TrajectoryReader r(q); });
  EXPECT_NE(msg3.find(q.string() + ": missing dataset /particles/grains/position/step"),
            std::string::npos)
      << msg3;
}

TEST_F(TrajectoryStore, OtherInconsistenciesAreErrors) {
  const fs::path p = path("bad.h5");
  Minimal m;
  m.unit = "furlong";
  write_minimal(p, m);
  std::string msg = error_message([&] { TrajectoryReader r(p); });
  EXPECT_NE(msg.find("/particles/grains/position/value has unit 'furlong'"), std::string::npos)
      << msg;

  m = Minimal{};
  m.ids = 2;
  write_minimal(p, m);
  msg = error_message([&] { TrajectoryReader r(p); });
  EXPECT_NE(msg.find("/particles/grains/id"), std::string::npos) << msg;

  // An axis element whose frame count differs from the positions'.
  const fs::path q = path("axis.h5");
  fs::copy_file(good_store(), q);
  {
    const hid_t f = H5Fopen(q.string().c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "/particles/grains/axis/value", H5P_DEFAULT), 0);
    const hid_t g = H5Gopen2(f, "/particles/grains/axis", H5P_DEFAULT);
    const std::vector<double> v(3 * 5 * 3, 0.0);
    h5::write(g, "value", v.data(), {3, 5, 3}, "1");
    H5Gclose(g);
    H5Fclose(f);
  }
  msg = error_message([&] { TrajectoryReader r(q); });
  EXPECT_NE(msg.find(q.string() + ": dataset /particles/grains/axis/value has shape [3,5,3], "
                                  "expected [4,5,3]"),
            std::string::npos)
      << msg;
}

// publish(): a complete, readable copy of what is written so far goes into place, and the
// writer goes on; the final commit() gives the same run as a writer that never published.
TEST_F(TrajectoryStore, PublishedFileIsCompleteAndReadableWhileWritingGoesOn) {
  const Trajectories run = random_run(11, 6, 5);
  fs::create_directories(path("a"));
  fs::create_directories(path("b"));
  const fs::path p = path("a/run.h5"), whole = path("b/run.h5");
  write_trajectories(whole, run);
  TrajectoryWriter w(p, run.header);
  // The observables measured up to each frame.
  auto observables_until = [&](std::size_t frames) {
    std::map<std::string, Observable> out;
    for (const auto& [name, obs] : run.observables) {
      Observable o;
      o.unit = obs.unit;
      for (std::size_t k = 0; k < obs.value.size(); ++k) {
        if (obs.step[k] > run.frames[frames - 1].step) continue;
        o.value.push_back(obs.value[k]);
        o.step.push_back(obs.step[k]);
        o.time.push_back(obs.time[k]);
      }
      out[name] = o;
    }
    return out;
  };
  for (std::size_t t = 0; t < run.frames.size(); ++t) {
    w.append(run.frames[t]);
    if (t != 1 && t != 4) continue;
    for (const auto& [name, obs] : observables_until(t + 1))
      w.set_observable(name, obs);
    w.publish();
    // The file in place holds exactly the frames so far, and opens in ParaView.
    Trajectories part = run;
    part.frames.resize(t + 1);
    part.observables = observables_until(t + 1);
    expect_same_run(part, read_trajectories(p));
    EXPECT_TRUE(fs::exists(xdmf_path(p)));
    EXPECT_EQ(count(read_text(xdmf_path(p)), "<Grid Name=\"step "), t + 1);
  }
  for (const auto& [name, obs] : run.observables)
    w.set_observable(name, obs);
  w.commit();
  expect_same_run(run, read_trajectories(p));
  EXPECT_EQ(read_text(xdmf_path(p)), read_text(xdmf_path(whole)));
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(path("a")))
    left.push_back(e.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"run.h5", "run.xmf"})) << "temporary files left";
}

// resume(path, k) keeps exactly the first k frames and the observables of steps up to the k-th
// frame's; appending the rest and committing gives the run written in one go.
TEST_F(TrajectoryStore, ResumedRunKeepsItsFirstFramesAndEndsAsAnUninterruptedOne) {
  const Trajectories run = random_run(12, 6, 5);  // frame steps -3, 7, 17, 27, 37, 47
  fs::create_directories(path("a"));
  fs::create_directories(path("b"));
  const fs::path p = path("a/run.h5"), whole = path("b/run.h5");
  write_trajectories(whole, run);
  for (std::size_t keep : {0u, 3u, 6u}) {
    SCOPED_TRACE("keep " + std::to_string(keep));
    write_trajectories(p, run);
    const std::string before = read_text(p);
    TrajectoryWriter w = TrajectoryWriter::resume(p, keep);
    EXPECT_EQ(w.frame_count(), keep);
    expect_same_header(run.header, w.header());
    // Observables: those of steps up to the last kept frame's.
    const std::int64_t last =
        keep ? run.frames[keep - 1].step : std::numeric_limits<std::int64_t>::min();
    for (const auto& [name, obs] : run.observables) {
      const Observable& kept = w.observables().at(name);
      std::vector<std::int64_t> steps;
      for (std::int64_t s : obs.step) {
        if (s <= last) steps.push_back(s);
      }
      EXPECT_EQ(kept.step, steps) << name;
      EXPECT_EQ(kept.unit, obs.unit) << name;
      ASSERT_EQ(kept.value.size(), steps.size()) << name;
      EXPECT_TRUE(same_bits(kept.value.data(), obs.value.data(), steps.size(), name));
    }
    EXPECT_EQ(read_text(p), before) << "the file changed before publish() or commit()";
    for (std::size_t t = keep; t < run.frames.size(); ++t)
      w.append(run.frames[t]);
    for (const auto& [name, obs] : run.observables)
      w.set_observable(name, obs);
    w.commit();
    expect_same_run(run, read_trajectories(p));
    EXPECT_EQ(read_text(xdmf_path(p)), read_text(xdmf_path(whole)));
  }
  // Observables of the steps kept, explicitly: lid_height has steps 0, 100, 200, and the
  // third frame is step 17.
  write_trajectories(p, run);
  const TrajectoryWriter w = TrajectoryWriter::resume(p, 3);
  EXPECT_EQ(w.observables().at("lid_height").step, (std::vector<std::int64_t>{0}));
  EXPECT_EQ(w.observables().at("wall_force").step, (std::vector<std::int64_t>{-3, 7, 17}));
}

TEST_F(TrajectoryStore, PublishedRunLeftUnfinishedCanBeResumed) {
  const Trajectories run = random_run(13, 6, 5);
  fs::create_directories(path("a"));
  fs::create_directories(path("b"));
  const fs::path p = path("a/run.h5"), whole = path("b/run.h5");
  write_trajectories(whole, run);
  {
    TrajectoryWriter w(p, run.header);
    for (std::size_t t = 0; t < 4; ++t)
      w.append(run.frames[t]);
    w.publish();
    w.append(run.frames[4]);  // lost: the writer is dropped without publishing again
  }
  EXPECT_EQ(read_trajectories(p).frames.size(), 4u);
  TrajectoryWriter w = TrajectoryWriter::resume(p, 2);
  for (std::size_t t = 2; t < run.frames.size(); ++t)
    w.append(run.frames[t]);
  for (const auto& [name, obs] : run.observables)
    w.set_observable(name, obs);
  w.commit();
  expect_same_run(run, read_trajectories(p));
  EXPECT_EQ(read_text(xdmf_path(p)), read_text(xdmf_path(whole)));
}

TEST_F(TrajectoryStore, ResumingAfterMoreFramesThanTheFileHoldsIsAnError) {
  const fs::path p = good_store();  // 4 frames
  const std::string msg = error_message([&] { TrajectoryWriter::resume(p, 5); });
  EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("has 4 frames"), std::string::npos) << msg;
  EXPECT_THROW(TrajectoryWriter::resume(path("missing.h5"), 0), Error);
}

}  // namespace
}  // namespace granmem
