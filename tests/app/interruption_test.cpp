// A run stopped from outside: killed outright (kill -9, the machine's OOM killer, a node
// lost), or asked to stop (SIGTERM from Slurm or a container stop, SIGINT from Ctrl-C).
// What it wrote before stays whole and consistent, --resume finishes it with the same
// result, bit for bit, as a run never stopped, and nothing temporary is left behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "granmem/core/trajectory_store.hpp"
#include "run_granmem.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;
using testing::GranmemTest;
using testing::RunResult;

// 60 grains, cycles of 80,000 steps (about a second each): long enough to be stopped in.
std::vector<std::string> slow_run(const std::string& out) {
  return {"simulate", "--grains", "60", "--box",    "2cm",   "--amplitude",
          "1%",       "--period", "2s", "--cycles", "3",     "--checkpoint-every",
          "1",        "--out",    out,  "--track",  "0,5,9", "--samples-per-cycle",
          "4"};
}

class Interruption : public GranmemTest {
 protected:
  // Starts granmem in the working folder, stdout and stderr to files in the capture folder.
  pid_t start(const std::vector<std::string>& args) {
    fs::create_directories(dir_ / "capture");
    const std::string err = (dir_ / "capture" / "started.err").string();
    const pid_t child = fork();
    if (child == 0) {
      if (chdir(work().c_str()) != 0) _exit(127);
      const int fd = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      dup2(fd, 2);
      const int null = open("/dev/null", O_WRONLY);
      dup2(null, 1);
      std::vector<char*> argv{const_cast<char*>(GRANMEM_EXE)};
      for (const std::string& a : args)
        argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      execv(GRANMEM_EXE, argv.data());
      _exit(127);
    }
    return child;
  }

  // Waits until `name` appears in the working folder (or the child ends: false).
  bool wait_for(pid_t child, const std::string& name) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(2);
    while (!fs::exists(in_work(name))) {
      int status = 0;
      if (waitpid(child, &status, WNOHANG) == child) return false;
      if (std::chrono::steady_clock::now() > give_up) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }

  // The exit status, 128 + n when ended by signal n.
  static int wait_exit(pid_t child) {
    int status = 0;
    waitpid(child, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

  // Kills `child` with SIGKILL once a finished store named `prefix`*.h5 is in `folder`
  // (a sweep's first finished run); false if none appears within two minutes.
  bool kill_after_a_finished_run(pid_t child, const fs::path& folder, const std::string& prefix) {
    bool finished_one = false;
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::minutes(2);
    while (!finished_one && std::chrono::steady_clock::now() < give_up) {
      std::error_code ec;
      for (const auto& e : fs::directory_iterator(folder, ec)) {
        finished_one = finished_one || (e.path().filename().string().rfind(prefix, 0) == 0 &&
                                        e.path().extension() == ".h5");
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (!finished_one) return false;
    kill(child, SIGKILL);
    EXPECT_EQ(wait_exit(child), 128 + SIGKILL);
    return true;
  }

  std::vector<std::string> temporaries() const {
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(work())) {
      const std::string name = e.path().filename().string();
      if (name.find(".tmp-") != std::string::npos) left.push_back(name);
    }
    return left;
  }
};

// The two stores hold the same frames, bit for bit.
void expect_same_frames(const fs::path& a_path, const fs::path& b_path) {
  SCOPED_TRACE(a_path.filename().string() + " vs " + b_path.filename().string());
  const Trajectories a = read_trajectories(a_path), b = read_trajectories(b_path);
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (std::size_t t = 0; t < a.frames.size(); ++t) {
    const Frame &fa = a.frames[t], &fb = b.frames[t];
    EXPECT_EQ(fa.step, fb.step);
    ASSERT_EQ(fa.position.size(), fb.position.size());
    EXPECT_EQ(std::memcmp(fa.position.data(), fb.position.data(),
                          fa.position.size() * sizeof(fa.position[0])),
              0)
        << "positions of frame " << t;
    ASSERT_EQ(fa.orientation.size(), fb.orientation.size());
    EXPECT_EQ(std::memcmp(fa.orientation.data(), fb.orientation.data(),
                          fa.orientation.size() * sizeof(fa.orientation[0])),
              0)
        << "orientations of frame " << t;
  }
}

TEST_F(Interruption, KilledOrStoppedRunsResumeToTheSameResultBitForBit) {
  granmem_ok(slow_run("whole.h5"));
  struct Case {
    int signal;
    std::string out;
  };
  for (const Case& c :
       {Case{SIGKILL, "killed.h5"}, Case{SIGTERM, "termed.h5"}, Case{SIGINT, "interrupted.h5"}}) {
    SCOPED_TRACE(strsignal(c.signal));
    const std::string stem = fs::path(c.out).stem().string();
    const std::string checkpoint = stem + ".checkpoint.h5";
    const pid_t child = start(slow_run(c.out));
    ASSERT_TRUE(wait_for(child, checkpoint)) << "no checkpoint after the first cycle";
    kill(child, c.signal);
    const int status = wait_exit(child);
    EXPECT_EQ(status, 128 + c.signal);
    if (c.signal != SIGKILL) {
      const std::string err = testing::read_file(dir_ / "capture" / "started.err");
      EXPECT_NE(err.find("stopped after cycle"), std::string::npos) << err;
      EXPECT_TRUE(temporaries().empty()) << temporaries().front();
    }
    // What was published is whole: the store, its sidecar and the checkpoint read.
    EXPECT_GE(TrajectoryReader(in_work(c.out)).frame_count(), 2u);
    EXPECT_TRUE(fs::exists(in_work(stem + ".xmf")));
    granmem_ok({"simulate", "--resume", checkpoint, "--cycles", "3"});
    EXPECT_TRUE(temporaries().empty()) << temporaries().front();
    expect_same_frames(in_work("whole.h5"), in_work(c.out));
    expect_same_frames(in_work("whole_in_cycle.h5"), in_work(stem + "_in_cycle.h5"));
  }
}

// A read-out sweep killed outright after its first finished run: called again, it reuses
// the runs that finished, redoes the others (their temporaries removed) and writes the
// same table as a sweep never stopped.
TEST_F(Interruption, AKilledReadoutSweepReusesItsFinishedRunsAndEndsTheSame) {
  granmem_ok({"simulate", "--grains", "60", "--box", "2cm", "--amplitude", "2%",
              "--inertial-number", "1e-2", "--cycles", "2", "--keep-states", "1", "--out",
              "train.h5"});
  // Slow read-out cycles (inertial number 3e-4: ~1 s a run), eight of them.
  auto sweep = [](const std::string& out) {
    return std::vector<std::string>{"readout",
                                    "--from",
                                    "train_state_cycle1.h5",
                                    "--amplitudes",
                                    "0.5%,1%,1.5%,2.5%,3%,3.5%,4%,5%",
                                    "--inertial-number",
                                    "3e-4",
                                    "--out",
                                    out};
  };
  granmem_ok(sweep("whole"));
  const pid_t child = start(sweep("killed"));
  ASSERT_TRUE(kill_after_a_finished_run(child, in_work("killed"), "readout_")) << "no run finished";
  EXPECT_FALSE(fs::exists(in_work("killed") / "readout.csv"));  // killed before the end

  const RunResult again = granmem_ok(sweep("killed"));
  const std::size_t at = again.out.find(" runs reused)");
  ASSERT_NE(at, std::string::npos) << again.out;
  const int reused = std::stoi(again.out.substr(again.out.rfind('(', at) + 1));
  EXPECT_GE(reused, 1) << again.out;
  EXPECT_LT(reused, 8) << again.out;
  const std::vector<std::string> columns{"amplitude_pct", "dr_d", "msd_d2", "rot_single_d",
                                         "rot_full_d"};
  const Table whole = read_columns(in_work("whole") / "readout.csv", columns),
              resumed = read_columns(in_work("killed") / "readout.csv", columns);
  for (const std::string& c : columns)
    EXPECT_EQ(whole[c].values, resumed[c].values) << c;
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(in_work("killed"))) {
    const fs::path file = e.path();
    if (file.filename().string().find(".tmp-") != std::string::npos)
      left.push_back(file.filename().string());
    // Every store has its sidecar, those of the killed call too (it renames the sidecar
    // first: a kill between the two renames leaves no store without one).
    if (file.extension() == ".h5") {
      EXPECT_TRUE(fs::exists(fs::path(file).replace_extension(".xmf"))) << file;
    }
  }
  EXPECT_TRUE(left.empty()) << left.front();
}

// A calibration killed while its twin runs: the next call reuses the runs that finished,
// redoes the rest, and fits what an unstopped call fits, to the last digit.
TEST_F(Interruption, AKilledCalibrationReusesItsFinishedRunsAndFitsTheSame) {
  const std::vector<std::string> twin{"--grains",    "60", "--box",    "2cm",
                                      "--amplitude", "2%", "--period", "0.5s"};
  std::vector<std::string> experiment{"simulate", "--cycles", "2",      "--seed",    "7", "--mu-s",
                                      "0.2",      "--out",    "exp.h5", "--threads", "1"};
  experiment.insert(experiment.end(), twin.begin(), twin.end());
  granmem_ok(experiment);
  auto calibrate = [&](const std::string& out) {
    std::vector<std::string> a{
        "calibrate",        "--experiment",  "exp.h5",       "--out",      out,        "--mu-s",
        "0.05,0.1,0.2,0.4", "--observables", "steady-state", "--fit-only", "--window", "1:2"};
    a.insert(a.end(), {"--replicas", "2"});
    a.insert(a.end(), twin.begin(), twin.end());
    return a;
  };
  granmem_ok(calibrate("whole"));
  const pid_t child = start(calibrate("killed"));
  ASSERT_TRUE(kill_after_a_finished_run(child, in_work("killed") / "runs", "mu_s_"))
      << "no run finished";
  EXPECT_FALSE(fs::exists(in_work("killed") / "summary.json"));  // killed before the fit

  const RunResult again = granmem_ok(calibrate("killed"));
  const std::size_t at = again.err.find("reusing ");
  ASSERT_NE(at, std::string::npos) << again.err;
  const int reused = std::stoi(again.err.substr(at + 8));
  EXPECT_GE(reused, 1) << again.err;
  EXPECT_LT(reused, 8) << again.err;
  const std::string fitted = again.out.substr(again.out.find("mu_s = "));
  const RunResult whole_again = granmem_ok(calibrate("whole"));  // every run reused
  EXPECT_EQ(fitted.substr(0, fitted.find('\n')),
            whole_again.out.substr(whole_again.out.find("mu_s = ")).substr(0, fitted.find('\n')));
  std::vector<std::string> left;
  for (const auto& e : fs::recursive_directory_iterator(in_work("killed"))) {
    if (e.path().filename().string().find(".tmp-") != std::string::npos)
      left.push_back(e.path().filename().string());
  }
  EXPECT_TRUE(left.empty()) << left.front();
}

// The protocol on LAMMPS stopped (Ctrl-C, SIGTERM, kill -9): LAMMPS ends with granmem, the
// frames up to its newest restart are those of a run never stopped, bit for bit, and
// --resume goes on from that restart to every cycle. LAMMPS's own restart is not bit for
// bit (it rebuilds its neighbour lists), so later frames agree as two runs of one packing
// do over a few cycles.
TEST_F(Interruption, AStoppedLammpsRunResumesFromItsNewestRestart) {
#ifndef GRANMEM_LAMMPS_EXE
  GTEST_SKIP() << "no lmp when the build was configured (Debian's lammps)";
#else
  auto run = [](const std::string& out) {
    return std::vector<std::string>{"simulate",
                                    "--grains",
                                    "150",
                                    "--box",
                                    "2.5cm",
                                    "--cycles",
                                    "8",
                                    "--checkpoint-every",
                                    "2",
                                    "--engine",
                                    "lammps",
                                    "--lammps",
                                    GRANMEM_LAMMPS_EXE,
                                    "--out",
                                    out};
  };
  granmem_ok(run("whole.h5"));
  for (int signal : {SIGINT, SIGTERM, SIGKILL}) {
    SCOPED_TRACE(strsignal(signal));
    const std::string out = signal == SIGINT    ? "interrupted.h5"
                            : signal == SIGTERM ? "termed.h5"
                                                : "killed.h5";
    const std::string stem = fs::path(out).stem().string();
    const pid_t child = start(run(out));
    ASSERT_TRUE(wait_for(child, stem + ".lammps/cycle2.restart")) << "no restart after cycle 2";
    kill(child, signal);
    EXPECT_EQ(wait_exit(child), 128 + signal);
    const std::string err = testing::read_file(dir_ / "capture" / "started.err");
    if (signal != SIGKILL) {
      EXPECT_NE(err.find("stopped after cycle"), std::string::npos) << err;
    } else {
      // LAMMPS ends with granmem (PR_SET_PDEATHSIG), or it would go on writing beside
      // the resumed run.
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    const RunResult resumed = granmem_ok({"simulate", "--resume", stem + ".checkpoint.h5"});
    const Trajectories a = read_trajectories(in_work("whole.h5"));
    const Trajectories b = read_trajectories(in_work(out));
    ASSERT_EQ(b.frames.size(), 9u);
    for (std::size_t t = 0; t <= 2; ++t) {
      EXPECT_EQ((a.frames[t].position - b.frames[t].position).cwiseAbs().maxCoeff(), 0.0)
          << "frame " << t;
    }
    const double whole_path = (a.frames[8].position - a.frames[0].position).rowwise().norm().mean();
    const double resumed_path =
        (b.frames[8].position - b.frames[0].position).rowwise().norm().mean();
    EXPECT_NEAR(resumed_path / whole_path, 1.0, 0.1);
    // One restart is left, the newest, and nothing half-written.
    std::vector<std::string> restarts, partial;
    for (const auto& e : fs::directory_iterator(in_work(stem + ".lammps"))) {
      const std::string name = e.path().filename().string();
      if (e.path().extension() == ".restart") restarts.push_back(name);
      if (e.path().extension() == ".part") partial.push_back(name);
    }
    EXPECT_EQ(restarts, std::vector<std::string>{"cycle8.restart"});
    EXPECT_TRUE(partial.empty()) << partial.front();
    EXPECT_TRUE(temporaries().empty()) << temporaries().front();
  }
#endif
}

}  // namespace
}  // namespace granmem
