// A checkpoint restores the whole state bit for bit: every grain array, the container and lid,
// the physics, the clock, every contact's history (grain pairs and walls) and the protocol's
// place, so that the restored simulation goes on exactly as the original. Files that are not
// checkpoints are refused with a clear Error.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <tuple>

#include "checks.hpp"
#include "granmem/core/hdf5.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "granmem/sim/checkpoint.hpp"
#include "sim_checks.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

using testing::error_message;
using testing::kRadius;
using testing::same_bits;

// A busy state: a squeezed cluster under a lid against a displaced, moving driven wall,
// every friction mode at work, physics away from the defaults.
Simulation busy_simulation() {
  PhysicsOptions p;
  p.contact.k_n = 3500;
  p.contact.restitution_n = 0.3;
  p.contact.k_t_over_k_n = 2.0 / 7.0;
  p.contact.restitution_t = 0.6;
  p.contact.mu_s = 0.4;
  p.contact.mu_r = 0.05;
  p.contact.mu_t = 0.02;
  p.contact.beta = 0.6;
  p.wall = {0.25, 0.03, 0.04};
  p.density = 1190;
  p.gravity = 9.7;
  p.dt = 2e-5;
  p.skin = 4e-4;
  p.background_damping = 0.5;
  p.min_steps_per_collision = 8;
  const double spacing = 0.998;
  auto extent = [&](int n) { return (n - 1) * 2 * kRadius * spacing + 2 * kRadius; };
  Grains g = testing::lattice_cluster(3, 4, 3, spacing, 21);
  for (auto& x : g.x)
    x.y() += 1e-4;
  Container c;
  c.size = {extent(3) - 1e-5, extent(4) + 1e-4 - 1e-5};
  c.y_wall = 1e-4;
  c.y_wall_velocity = 0.003;
  c.lid.present = true;
  c.lid.mass = 0.3;
  c.lid.z = extent(3) - 1e-5;
  Simulation sim(g, c, p);
  sim.set_wall_motion([](double t) { return std::make_pair(1e-4 + 0.003 * t, 0.003); });
  sim.run(300);
  sim.set_wall_motion({});
  return sim;
}

ProtocolState some_protocol() {
  ProtocolState s;
  s.cycles_done = 12;
  s.step_in_cycle = 345;
  s.frames_written = {{"end_of_cycle", 13}, {"full_compression", 12}, {"in_cycle", 250}};
  s.pending = {{"wall_force_full_compression", -0.123456789}};
  s.settings = {{"amplitude", "0.0015"}, {"drive", "asymmetric"}, {"seed", "7"}};
  return s;
}

using PairKey = std::tuple<std::int64_t, std::int64_t>;
std::vector<Simulation::PairRecord> sorted_pairs(const Simulation& sim) {
  std::vector<Simulation::PairRecord> pairs = sim.pair_histories();
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) {
    return PairKey(a.id_a, a.id_b) < PairKey(b.id_a, b.id_b);
  });
  return pairs;
}

bool same_history(const ContactHistory& a, const ContactHistory& b) {
  return same_bits(a.slide, b.slide) && same_bits(a.roll, b.roll) && same_bits(a.twist, b.twist);
}

void expect_same_simulation(const Simulation& a, const Simulation& b) {
  EXPECT_TRUE(testing::same_grain_state(a.grains(), b.grains()));
  const Container &ca = a.container(), &cb = b.container();
  EXPECT_TRUE(same_bits(ca.size.x(), cb.size.x()));
  EXPECT_TRUE(same_bits(ca.size.y(), cb.size.y()));
  EXPECT_TRUE(same_bits(ca.y_wall, cb.y_wall));
  EXPECT_TRUE(same_bits(ca.y_wall_velocity, cb.y_wall_velocity));
  EXPECT_EQ(ca.lid.present, cb.lid.present);
  EXPECT_TRUE(same_bits(ca.lid.mass, cb.lid.mass));
  EXPECT_TRUE(same_bits(ca.lid.z, cb.lid.z));
  EXPECT_TRUE(same_bits(ca.lid.v, cb.lid.v));
  EXPECT_TRUE(same_bits(ca.lid.force, cb.lid.force));
  EXPECT_TRUE(same_bits(a.time(), b.time()));
  EXPECT_EQ(a.step_count(), b.step_count());
  const std::vector<Simulation::PairRecord> pa = sorted_pairs(a), pb = sorted_pairs(b);
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t k = 0; k < pa.size(); ++k) {
    EXPECT_EQ(pa[k].id_a, pb[k].id_a);
    EXPECT_EQ(pa[k].id_b, pb[k].id_b);
    EXPECT_TRUE(same_history(pa[k].history, pb[k].history))
        << "contact " << pa[k].id_a << "-" << pa[k].id_b;
  }
  ASSERT_EQ(a.wall_histories().size(), b.wall_histories().size());
  for (std::size_t i = 0; i < a.wall_histories().size(); ++i) {
    for (int w = 0; w < kWallCount; ++w) {
      EXPECT_TRUE(same_history(a.wall_histories()[i][w], b.wall_histories()[i][w]))
          << "grain " << i << " wall " << w;
    }
  }
}

class Checkpoint : public testing::TempDirTest {};

TEST_F(Checkpoint, RoundTripRestoresEveryStateArrayBitForBit) {
  Simulation sim = busy_simulation();
  // The state is as busy as intended: contacts with all three springs, walls touched.
  const std::vector<Simulation::PairRecord> pairs = sim.pair_histories();
  ASSERT_GT(pairs.size(), 20u);
  EXPECT_TRUE(std::any_of(pairs.begin(), pairs.end(), [](const auto& p) {
    return p.history.slide.norm() > 0 && p.history.roll.norm() > 0 && p.history.twist != 0;
  }));
  EXPECT_GT(sim.wall_loads().contacts[int(Wall::lid)], 0);
  EXPECT_GT(sim.wall_loads().contacts[int(Wall::y_low)], 0);

  const ProtocolState protocol = some_protocol();
  write_checkpoint(path("state.h5"), sim, protocol);
  EXPECT_EQ(listing(), std::vector<std::string>{"state.h5"}) << "no temporary files left";
  ProtocolState restored_protocol;
  Simulation restored = read_checkpoint(path("state.h5"), &restored_protocol);
  expect_same_simulation(sim, restored);

  const PhysicsOptions &pa = sim.physics(), &pb = restored.physics();
  for (auto [x, y] : {std::pair{pa.contact.k_n, pb.contact.k_n},
                      {pa.contact.restitution_n, pb.contact.restitution_n},
                      {pa.contact.k_t_over_k_n, pb.contact.k_t_over_k_n},
                      {pa.contact.restitution_t, pb.contact.restitution_t},
                      {pa.contact.mu_s, pb.contact.mu_s},
                      {pa.contact.mu_r, pb.contact.mu_r},
                      {pa.contact.mu_t, pb.contact.mu_t},
                      {pa.contact.beta, pb.contact.beta},
                      {pa.wall.mu_s, pb.wall.mu_s},
                      {pa.wall.mu_r, pb.wall.mu_r},
                      {pa.wall.mu_t, pb.wall.mu_t},
                      {pa.density, pb.density},
                      {pa.gravity, pb.gravity},
                      {pa.dt, pb.dt},
                      {pa.skin, pb.skin},
                      {pa.background_damping, pb.background_damping},
                      {pa.min_steps_per_collision, pb.min_steps_per_collision}}) {
    EXPECT_TRUE(same_bits(x, y)) << x << " vs " << y;
  }

  EXPECT_EQ(restored_protocol.cycles_done, protocol.cycles_done);
  EXPECT_EQ(restored_protocol.step_in_cycle, protocol.step_in_cycle);
  EXPECT_EQ(restored_protocol.frames_written, protocol.frames_written);
  EXPECT_EQ(restored_protocol.pending, protocol.pending);
  EXPECT_EQ(restored_protocol.settings, protocol.settings);

  // And it goes on exactly as the original (the driven wall keeps moving).
  for (Simulation* s : {&sim, &restored}) {
    s->set_wall_motion([](double t) { return std::make_pair(1e-4 + 0.003 * t, 0.003); });
    s->run(300);
  }
  expect_same_simulation(sim, restored);
  for (int w = 0; w < kWallCount; ++w) {
    EXPECT_TRUE(same_bits(sim.wall_loads().force[w], restored.wall_loads().force[w]));
  }
}

// What the simulation reports about its last step, contact count and wall loads, is part of
// the state a caller sees after resuming (a status line, a first observable). (Before the
// checkpoint stored them, a restored simulation reported 0 contacts and wall loads computed
// with every contact history zeroed until its first step.)
TEST_F(Checkpoint, RestoredSimulationReportsTheLastStepsContactsAndWallLoads) {
  const Simulation sim = busy_simulation();
  write_checkpoint(path("state.h5"), sim, ProtocolState{});
  const Simulation restored = read_checkpoint(path("state.h5"));
  EXPECT_EQ(restored.contact_count(), sim.contact_count());
  for (int w = 0; w < kWallCount; ++w) {
    EXPECT_EQ(restored.wall_loads().contacts[w], sim.wall_loads().contacts[w]) << "wall " << w;
    EXPECT_TRUE(same_bits(restored.wall_loads().force[w], sim.wall_loads().force[w]))
        << "wall " << w << ": " << restored.wall_loads().force[w].transpose() << " vs "
        << sim.wall_loads().force[w].transpose();
  }
}

TEST_F(Checkpoint, EmptyProtocolAndNoLidRoundTrip) {
  Grains g = testing::lattice_cluster(2, 2, 2, 1.05, 3);
  Simulation sim(g, testing::wide_box(0.1), PhysicsOptions{});
  sim.run(10);
  write_checkpoint(path("plain.h5"), sim, ProtocolState{});
  ProtocolState p;
  p.cycles_done = 99;
  p.settings["stale"] = "x";
  const Simulation restored = read_checkpoint(path("plain.h5"), &p);
  expect_same_simulation(sim, restored);
  EXPECT_EQ(p.cycles_done, 0);
  EXPECT_TRUE(p.frames_written.empty());
  EXPECT_TRUE(p.settings.empty());
  EXPECT_FALSE(restored.container().lid.present);
}

TEST_F(Checkpoint, FilesThatAreNotCheckpointsAreRefused) {
  // A trajectory store: HDF5, but not a checkpoint.
  Trajectories run;
  run.header.id = {1, 2};
  run.header.radius = {kRadius, kRadius};
  write_trajectories(path("run.h5"), run);
  std::string message = error_message([&] { read_checkpoint(path("run.h5")); });
  EXPECT_NE(message.find("run.h5"), std::string::npos) << message;
  EXPECT_NE(message.find("not a granmem checkpoint"), std::string::npos) << message;

  // A checkpoint of another format version.
  {
    h5::File f = h5::File::create(path("future.h5"));
    h5::Handle root = h5::create_group(f.id(), "/checkpoint");
    h5::write_attribute(root.get(), "format", "granmem checkpoint 99");
    f.close();
  }
  message = error_message([&] { read_checkpoint(path("future.h5")); });
  EXPECT_NE(message.find("granmem checkpoint 99"), std::string::npos) << message;

  // Not HDF5 at all, and no file.
  write_text(path("notes.h5"), "not hdf5\n");
  message = error_message([&] { read_checkpoint(path("notes.h5")); });
  EXPECT_NE(message.find("notes.h5"), std::string::npos) << message;
  message = error_message([&] { read_checkpoint(path("missing.h5")); });
  EXPECT_NE(message.find("missing.h5"), std::string::npos) << message;
}

TEST_F(Checkpoint, TruncatedCheckpointIsRefused) {
  Simulation sim = busy_simulation();
  write_checkpoint(path("state.h5"), sim, some_protocol());
  // The same checkpoint without its wall contact histories.
  {
    h5::File f = h5::File::open_for_writing(path("state.h5"));
    h5::remove(f.id(), "/checkpoint/wall_contacts");
    f.close();
  }
  const std::string message = error_message([&] { read_checkpoint(path("state.h5")); });
  EXPECT_NE(message.find("wall_contacts"), std::string::npos) << message;
}

}  // namespace
}  // namespace granmem
