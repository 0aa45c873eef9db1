// A cyclic run stopped and resumed from its checkpoint, at the end of a cycle or in the middle
// of one, writes the same outputs, bit for bit, as the run done in one go: end-of-cycle frames
// (positions, orientations, axes), full-compression frames, in-cycle samples, observables,
// and the final state. So does a run on 1 thread and on 2.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <thread>

#include "granmem/core/error.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "granmem/sim/cyclic_protocol.hpp"
#include "granmem/sim/deposit.hpp"
#include "sim_checks.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;
using testing::same_bits;

// A small packing under a lid, deposited once for all the tests here.
const Simulation& small_packing() {
  static const Simulation sim = [] {
    DepositOptions o;
    o.grains = 40;
    o.box_side = 0.02;
    o.lid_mass = 0.02;
    o.seed = 9;
    o.settling_damping = 20;
    o.settled_energy = 1e-11;  // a packing is all the protocol needs
    return deposit(o, PhysicsOptions{});
  }();
  return sim;
}

CyclicOptions cycles_into(const fs::path& dir, std::int64_t cycles, double period = 0.02) {
  CyclicOptions o;
  o.drive.amplitude = 1e-3;
  o.drive.period = period;  // 800 steps by default
  o.cycles = cycles;
  o.out = dir / "run.h5";
  o.full_compression_frames = true;
  o.tracked_grains = {0, 7, 31};
  o.samples_per_cycle = 10;
  o.checkpoint = dir / "run.checkpoint.h5";
  o.parameters = {{"simulate/test", "restart"}};
  return o;
}

::testing::AssertionResult same_array(const double* a, const double* b, std::size_t n,
                                      const std::string& what) {
  if (n == 0 || std::memcmp(a, b, n * sizeof(double)) == 0) return ::testing::AssertionSuccess();
  for (std::size_t i = 0; i < n; ++i) {
    if (!same_bits(a[i], b[i])) {
      return ::testing::AssertionFailure() << what << "[" << i << "]: " << a[i] << " vs " << b[i];
    }
  }
  return ::testing::AssertionFailure() << what;
}

// The two stores hold the same run, bit for bit.
void expect_same_store(const fs::path& a_path, const fs::path& b_path) {
  SCOPED_TRACE(a_path.filename().string());
  const Trajectories a = read_trajectories(a_path), b = read_trajectories(b_path);
  EXPECT_EQ(a.header.id, b.header.id);
  EXPECT_EQ(a.header.sample, b.header.sample);
  EXPECT_EQ(a.header.parameters, b.header.parameters);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t t = 0; t < a.frames.size(); ++t) {
    const Frame &fa = a.frames[t], &fb = b.frames[t];
    const std::string at = "frame " + std::to_string(t) + " ";
    EXPECT_EQ(fa.step, fb.step) << at;
    EXPECT_TRUE(same_bits(fa.time, fb.time)) << at;
    EXPECT_TRUE(same_array(fa.position.data(), fb.position.data(), std::size_t(fa.position.size()),
                           at + "position"));
    EXPECT_TRUE(same_array(fa.orientation.data(), fb.orientation.data(),
                           std::size_t(fa.orientation.size()), at + "orientation"));
    EXPECT_TRUE(
        same_array(fa.axis.data(), fb.axis.data(), std::size_t(fa.axis.size()), at + "axis"));
  }
  ASSERT_EQ(a.observables.size(), b.observables.size());
  for (const auto& [name, oa] : a.observables) {
    ASSERT_EQ(b.observables.count(name), 1u) << name;
    const Observable& ob = b.observables.at(name);
    EXPECT_EQ(oa.step, ob.step) << name;
    ASSERT_EQ(oa.value.size(), ob.value.size()) << name;
    EXPECT_TRUE(same_array(oa.value.data(), ob.value.data(), oa.value.size(), name));
    EXPECT_TRUE(same_array(oa.time.data(), ob.time.data(), oa.time.size(), name + " time"));
  }
}

void expect_same_outputs(const CyclicOptions& a, const CyclicOptions& b) {
  expect_same_store(a.out, b.out);
  expect_same_store(full_compression_path(a.out), full_compression_path(b.out));
  expect_same_store(in_cycle_path(a.out), in_cycle_path(b.out));
}

void expect_same_state(const Simulation& a, const Simulation& b) {
  EXPECT_TRUE(testing::same_grain_state(a.grains(), b.grains()));
  EXPECT_EQ(a.step_count(), b.step_count());
  EXPECT_TRUE(same_bits(a.time(), b.time()));
  EXPECT_TRUE(same_bits(a.container().lid.z, b.container().lid.z));
  EXPECT_TRUE(same_bits(a.container().lid.v, b.container().lid.v));
  EXPECT_TRUE(same_bits(a.container().y_wall, b.container().y_wall));
}

class Restart : public testing::TempDirTest {
 protected:
  // The run in one go, into folder "whole".
  CyclicOptions whole_run(Simulation* end = nullptr) {
    fs::create_directories(path("whole"));
    const CyclicOptions o = cycles_into(path("whole"), 3);
    Simulation sim = small_packing();
    ProtocolState state;
    const CyclicSummary s = run_cycles(sim, o, state);
    EXPECT_EQ(s.cycles_done, 3);
    EXPECT_FALSE(s.interrupted);
    if (end) *end = sim;
    return o;
  }
};

TEST_F(Restart, ResumedAtTheEndOfACycleWritesTheSameRunBitForBit) {
  Simulation whole = small_packing();
  const CyclicOptions a = whole_run(&whole);

  fs::create_directories(path("parts"));
  CyclicOptions b = cycles_into(path("parts"), 1);
  {
    Simulation sim = small_packing();
    ProtocolState state;
    EXPECT_EQ(run_cycles(sim, b, state).cycles_done, 1);
  }
  ProtocolState state;
  Simulation sim = read_checkpoint(b.checkpoint, &state);
  EXPECT_EQ(state.cycles_done, 1);
  EXPECT_EQ(state.step_in_cycle, 0);
  b.cycles = 3;
  EXPECT_EQ(run_cycles(sim, b, state).cycles_done, 3);
  expect_same_outputs(a, b);
  expect_same_state(whole, sim);
  EXPECT_EQ(read_trajectories(b.out).frames.size(), 4u);  // the packing, then 3 cycles
}

// States kept before the first cycle and after cycles 1 and 2 of the run: the first is
// the prepared packing; a new protocol of one more cycle started from the last is the
// run's third cycle, bit for bit (a read-out at the training amplitude continues the
// training); --resume from the one after cycle 1 continues the whole run.
TEST_F(Restart, AKeptStateStartsTheRestOfTheRunBitForBit) {
  Simulation whole = small_packing();
  const CyclicOptions a = whole_run(&whole);

  fs::create_directories(path("kept"));
  CyclicOptions b = cycles_into(path("kept"), 3);
  b.keep_states = {0, 1, 2};
  {
    Simulation sim = small_packing();
    ProtocolState state;
    const CyclicSummary s = run_cycles(sim, b, state);
    EXPECT_EQ(std::count(s.written.begin(), s.written.end(), kept_state_path(b.out, 2)), 1);
    expect_same_state(whole, sim);  // keeping states does not change the run
  }
  ProtocolState kept;
  Simulation from_2 = read_checkpoint(kept_state_path(b.out, 2), &kept);
  EXPECT_EQ(kept.cycles_done, 2);
  EXPECT_EQ(kept.step_in_cycle, 0);
  fs::create_directories(path("next"));
  CyclicOptions next = cycles_into(path("next"), 1);
  ProtocolState fresh;
  run_cycles(from_2, next, fresh);
  expect_same_state(whole, from_2);

  ProtocolState untrained;
  const Simulation from_0 = read_checkpoint(kept_state_path(b.out, 0), &untrained);
  EXPECT_EQ(untrained.cycles_done, 0);
  expect_same_state(small_packing(), from_0);

  ProtocolState resumed;
  Simulation from_1 = read_checkpoint(kept_state_path(b.out, 1), &resumed);
  EXPECT_EQ(run_cycles(from_1, b, resumed).cycles_done, 3);
  expect_same_outputs(a, b);
  expect_same_state(whole, from_1);
}

// A packing started as after cycle 4 (a twin placed where an experiment's frame of cycle 4
// has its grains) runs the same cycles as one started at 0, numbered 4 to 7: its frames'
// and observables' steps are the others' plus 4, all else bit for bit.
TEST_F(Restart, ARunNumberedFromALaterCycleIsTheSameRun) {
  Simulation whole = small_packing();
  const CyclicOptions a = whole_run(&whole);

  fs::create_directories(path("later"));
  CyclicOptions b = cycles_into(path("later"), 7);
  b.first_cycle = 4;
  Simulation sim = small_packing();
  ProtocolState state;
  EXPECT_EQ(run_cycles(sim, b, state).cycles_done, 7);
  expect_same_state(whole, sim);
  const Trajectories ta = read_trajectories(a.out), tb = read_trajectories(b.out);
  ASSERT_EQ(tb.frames.size(), ta.frames.size());
  for (std::size_t t = 0; t < ta.frames.size(); ++t) {
    EXPECT_EQ(tb.frames[t].step, ta.frames[t].step + 4);
    EXPECT_TRUE(same_array(ta.frames[t].position.data(), tb.frames[t].position.data(),
                           std::size_t(ta.frames[t].position.size()), "position"));
  }
  for (const auto& [name, oa] : ta.observables) {
    const Observable& ob = tb.observables.at(name);
    ASSERT_EQ(ob.step.size(), oa.step.size()) << name;
    for (std::size_t k = 0; k < oa.step.size(); ++k)
      EXPECT_EQ(ob.step[k], oa.step[k] + 4) << name;
    EXPECT_TRUE(same_array(oa.value.data(), ob.value.data(), oa.value.size(), name));
  }
  b.keep_states = {3};  // before the run starts
  EXPECT_THROW(b.validate(0.02, 25e-6), Error);
  b.keep_states.clear();
  b.first_cycle = 7;  // no cycle left to run
  EXPECT_THROW(b.validate(0.02, 25e-6), Error);
}

TEST(KeptStates, NegativeCyclesAreRefused) {
  CyclicOptions o;
  o.drive.amplitude = 1e-3;
  o.drive.period = 0.02;
  o.keep_states = {-1};
  EXPECT_THROW(o.validate(0.02, 25e-6), Error);
  o.keep_states = {0};
  EXPECT_NO_THROW(o.validate(0.02, 25e-6));
}

// Runs the cycles with a stop request from another thread shortly after cycle `after`
// ends: it lands at some step of the next cycle (which one does not matter: every step must
// resume). Returns the summary; `sim` is left where it stopped.
CyclicSummary run_until_stopped(Simulation& sim, const CyclicOptions& o, ProtocolState& state,
                                std::int64_t after) {
  std::atomic<bool> stop{false}, cycle_done{false};
  std::thread stopper([&] {
    while (!cycle_done.load())
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
    stop = true;
  });
  const CyclicSummary s = run_cycles(
      sim, o, state, [&](const CyclicProgress& p) { cycle_done = cycle_done || p.cycle >= after; },
      &stop);
  cycle_done = true;
  stopper.join();
  return s;
}

// Stopped twice (the second time in a run that was itself resumed), resumed each time from the
// checkpoint; eight cycles, so that a stop request the loaded machine delays by a few cycles
// still finds the run going. The symmetric drive reaches full compression a quarter into the cycle,
// so a stop lands before or after the full-compression frame and force are recorded.
TEST_F(Restart, StoppedInCyclesAndResumedTwiceWritesTheSameRunBitForBit) {
  fs::create_directories(path("whole"));
  CyclicOptions a = cycles_into(path("whole"), 8);
  a.drive.symmetry = DriveSymmetry::symmetric;
  Simulation whole = small_packing();
  ProtocolState whole_state;
  run_cycles(whole, a, whole_state);

  fs::create_directories(path("parts"));
  CyclicOptions b = cycles_into(path("parts"), 8);
  b.drive.symmetry = DriveSymmetry::symmetric;
  Simulation sim = small_packing();
  ProtocolState state;
  for (std::int64_t after : {1, 2}) {
    const std::int64_t steps_before = sim.step_count();
    const CyclicSummary s = run_until_stopped(sim, b, state, after);
    ASSERT_TRUE(s.interrupted) << "the run ended before the stop request";
    EXPECT_GT(sim.step_count(), steps_before);
    const std::int64_t stopped_at = sim.step_count();
    state = ProtocolState{};
    sim = read_checkpoint(b.checkpoint, &state);
    EXPECT_EQ(sim.step_count(), stopped_at);
    RecordProperty("stop_" + std::to_string(after),
                   "cycle " + std::to_string(state.cycles_done + 1) + " step " +
                       std::to_string(state.step_in_cycle));
  }
  EXPECT_EQ(run_cycles(sim, b, state).cycles_done, 8);
  expect_same_outputs(a, b);
  expect_same_state(whole, sim);
}

// The same run on one thread and on two (a small system runs on one by default: ask for two).
TEST_F(Restart, OneAndTwoThreadsWriteTheSameRunBitForBit) {
  fs::create_directories(path("one"));
  const CyclicOptions a = cycles_into(path("one"), 2, 0.005);
  Simulation one = small_packing();
  one.set_threads(1);
  ProtocolState state_one;
  run_cycles(one, a, state_one);
  fs::create_directories(path("two"));
  const CyclicOptions b = cycles_into(path("two"), 2, 0.005);
  Simulation two = small_packing();
  two.set_threads(2);
  ASSERT_EQ(two.threads(), 2);
  ProtocolState state_two;
  run_cycles(two, b, state_two);
  expect_same_outputs(a, b);
  expect_same_state(one, two);
}

}  // namespace
}  // namespace granmem
