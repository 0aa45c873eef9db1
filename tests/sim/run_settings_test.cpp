// How a run that goes on from a checkpoint merges its recorded settings with a new call's.
#include "granmem/sim/run_settings.hpp"

#include <gtest/gtest.h>

#include "granmem/core/error.hpp"
#include "granmem/sim/simulate_settings.hpp"

namespace granmem {
namespace {

const RunSettings kRecorded = {{"cycles", "10"}, {"mu-s", "0.2"}, {"out", "run.h5"}};

TEST(RunSettings, AResumedRunKeepsItsSettingsButForThoseThatMayChange) {
  RunSettings recorded = kRecorded;
  const RunSettings current = {
      {"cycles", "20"}, {"mu-s", "0.5"}, {"out", "run.h5"}, {"keep-states", ""}};
  // Given: --cycles 20 (may change); mu-s 0.5 is only a default here.
  const RunSettings v = resumed_settings(recorded, current, {"cycles"}, {"cycles"});
  EXPECT_EQ(v.at("cycles"), "20");
  EXPECT_EQ(recorded.at("cycles"), "20");  // recorded for the next resume
  EXPECT_EQ(v.at("mu-s"), "0.2");          // the run's own
  EXPECT_EQ(v.at("keep-states"), "");      // newer than the checkpoint: the current value
  RunSettings again = kRecorded;
  try {
    resumed_settings(again, current, {"mu-s"}, {"cycles"});
    ADD_FAILURE() << "a changed friction was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--mu-s 0.5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("only --cycles"), std::string::npos) << e.what();
  }
  EXPECT_EQ(again, kRecorded);  // unchanged by the refusal
}

TEST(RunSettings, ANewProtocolTakesThePackingFromTheCheckpointAndTheRestAnew) {
  const RunSettings current = {{"cycles", "3"}, {"mu-s", "0.2"}, {"out", "readout.h5"}};
  const RunSettings v =
      started_from_settings(kRecorded, current, {"cycles", "out"}, {"mu-s"}, {}, "trained.h5");
  EXPECT_EQ(v.at("cycles"), "3");
  EXPECT_EQ(v.at("out"), "readout.h5");
  EXPECT_EQ(v.at("mu-s"), "0.2");
  const RunSettings other = {{"cycles", "3"}, {"mu-s", "0.5"}, {"out", "readout.h5"}};
  EXPECT_THROW(started_from_settings(kRecorded, other, {"mu-s"}, {"mu-s"}, {}, "trained.h5"),
               Error);
  EXPECT_NO_THROW(started_from_settings(kRecorded, other, {}, {"mu-s"}, {}, "trained.h5"));
  EXPECT_THROW(
      started_from_settings(kRecorded, current, {}, {"mu-s", "lid-pressure"}, {}, "trained.h5"),
      Error);  // the checkpoint lacks a packing option
  EXPECT_NO_THROW(started_from_settings(kRecorded, current, {}, {"mu-s", "lid-pressure"},
                                        {"lid-pressure"}, "trained.h5"));
}

// The defaults live in the library's structs; the settings' text of them reads back to the
// same numbers (to the last bit where the unit shown scales exactly).
TEST(RunSettings, TheDefaultSettingsAreTheLibrarysDefaults) {
  const RunSettings v = default_simulate_settings();
  const PhysicsOptions p = physics_from(v), want;
  EXPECT_EQ(p.contact.k_n, want.contact.k_n);
  EXPECT_EQ(p.contact.restitution_n, want.contact.restitution_n);
  EXPECT_EQ(p.contact.restitution_t, want.contact.restitution_t);
  EXPECT_NEAR(p.contact.k_t_over_k_n, want.contact.k_t_over_k_n, 1e-14);
  EXPECT_EQ(p.contact.mu_s, want.contact.mu_s);
  EXPECT_EQ(p.contact.mu_r, want.contact.mu_r);
  EXPECT_EQ(p.contact.mu_t, want.contact.mu_t);
  EXPECT_EQ(p.contact.beta, want.contact.beta);
  EXPECT_EQ(p.wall.mu_s, want.wall.mu_s);  // "same": the grains' friction
  EXPECT_DOUBLE_EQ(p.density, want.density);
  EXPECT_DOUBLE_EQ(p.dt, want.dt);
  EXPECT_DOUBLE_EQ(p.skin, want.skin);
  EXPECT_EQ(p.gravity, want.gravity);
  const DepositOptions d = deposit_from(v), dwant;
  EXPECT_EQ(d.grains, dwant.grains);
  EXPECT_DOUBLE_EQ(d.radius, dwant.radius);
  EXPECT_DOUBLE_EQ(d.box_side, dwant.box_side);
  EXPECT_EQ(d.polydispersity, dwant.polydispersity);
  EXPECT_EQ(d.seed, dwant.seed);
  EXPECT_EQ(d.settled_energy, dwant.settled_energy);
  EXPECT_EQ(d.settling_damping, dwant.settling_damping);
  // The paper's lid: 1 kg on its 15 x 15 cm box, given as the pressure it exerts.
  EXPECT_NEAR(d.lid_mass, dwant.lid_mass, 1e-3);
  EXPECT_EQ(v.at("box"), "15cm");
  EXPECT_EQ(v.at("dt"), "25us");
}

}  // namespace
}  // namespace granmem
