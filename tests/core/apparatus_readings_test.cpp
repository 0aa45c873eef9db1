// The apparatus' readings beside the scans: read, checked, stored with an imported run
// under the names a simulation's store gives them, and read back.
#include "granmem/core/apparatus_readings.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "checks.hpp"
#include "granmem/core/error.hpp"
#include "granmem/core/import_table.hpp"
#include "granmem/core/trajectory_store.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

class ApparatusReadings : public testing::TempDirTest {
 protected:
  // The Error message read_apparatus_readings gives for `csv`.
  std::string error_of(const std::string& csv) {
    write_text(path("readings.csv"), csv);
    try {
      read_apparatus_readings(path("readings.csv"));
    } catch (const Error& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected granmem::Error for:\n" << csv;
    return "";
  }
};

TEST_F(ApparatusReadings, AreTheWallsForcesUnderTheSimulationsNames) {
  write_text(path("readings.csv"),
             "# load cell\ncycle,wall_force_full_compression,wall_force_unloaded,note\n"
             "20,12.5,3.25,a\n21,12.75,,b\n22,13,3.5,c\n");
  const auto r = read_apparatus_readings(path("readings.csv"));
  ASSERT_EQ(r.size(), 2u);
  const Observable& full = r.at("wall_force_full_compression");
  EXPECT_EQ(full.unit, "N");
  EXPECT_EQ(full.step, (std::vector<std::int64_t>{20, 21, 22}));
  EXPECT_EQ(full.value, (std::vector<double>{12.5, 12.75, 13}));
  EXPECT_EQ(full.time, (std::vector<double>{20, 21, 22}));
  const Observable& unloaded = r.at("wall_force");  // not read at cycle 21
  EXPECT_EQ(unloaded.step, (std::vector<std::int64_t>{20, 22}));
  EXPECT_EQ(unloaded.value, (std::vector<double>{3.25, 3.5}));
}

TEST_F(ApparatusReadings, BadReadingsAreRefusedNamingFileAndLine) {
  const std::string file = path("readings.csv").string();
  for (const auto& [csv, part] : std::vector<std::pair<std::string, std::string>>{
           {"cycle,lid\n1,2\n", "no column wall_force_full_compression or wall_force_unloaded"},
           {"wall_force_unloaded\n1\n", "cycle"},
           {"cycle,wall_force_unloaded\n1,2\n1,3\n", "line 3: cycle 1 read twice"},
           {"cycle,wall_force_unloaded\n-1,2\n", "line 2, column 'cycle'"},
           {"cycle,wall_force_unloaded\n1.5,2\n", "line 2, column 'cycle'"},
           {"cycle,wall_force_unloaded\n1,-2\n", "line 2, column 'wall_force_unloaded'"},
           {"cycle,wall_force_full_compression\n1,inf\n", "expected a force >= 0 in N"},
           {"cycle,wall_force_unloaded\n1,x\n", "line 2"}}) {
    const std::string msg = error_of(csv);
    EXPECT_NE(msg.find(file), std::string::npos) << msg;
    EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
  }
}

TEST_F(ApparatusReadings, StoredWithAnImportedRunAndReadBack) {
  write_text(path("tracks.csv"), "frame,particle,x,y,z\n1,7,1,2,3\n2,7,1.1,2,3\n3,7,1.2,2,3\n");
  write_text(path("readings.csv"), "cycle,wall_force_unloaded\n2,4.5\n3,4.25\n");
  ImportOptions o;
  o.length_unit = "mm";
  o.radius = 0.5;
  o.readings = path("readings.csv");
  ImportSummary summary;
  write_trajectories(path("run.h5"), import_table(path("tracks.csv"), o, &summary));
  ASSERT_FALSE(summary.notes.empty());
  EXPECT_NE(summary.notes.back().find("the wall's force unloaded at 2 cycles"), std::string::npos)
      << summary.notes.back();
  const TrajectoryReader run(path("run.h5"));
  const Observable& w = run.observables().at("wall_force");
  EXPECT_EQ(w.unit, "N");
  EXPECT_EQ(w.step, (std::vector<std::int64_t>{2, 3}));
  EXPECT_EQ(w.value, (std::vector<double>{4.5, 4.25}));
  // A bad file is refused before the table is read.
  write_text(path("readings.csv"), "cycle\n2\n");
  EXPECT_THROW(import_table(path("nothing.csv"), o), Error);
  try {
    import_table(path("nothing.csv"), o);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("readings.csv"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace granmem
