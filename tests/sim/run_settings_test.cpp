// How a run that goes on from a checkpoint merges its recorded settings with a new call's.
#include "granmem/sim/run_settings.hpp"

#include <gtest/gtest.h>

#include "granmem/core/error.hpp"

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

}  // namespace
}  // namespace granmem
