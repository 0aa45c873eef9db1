#pragma once

// Runs the real `granmem` binary for the end-to-end tests: arguments in, exit code,
// stdout and stderr out (captured separately through files, via std::system).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "granmem/core/table.hpp"
#include "temp_dir.hpp"

namespace granmem::testing {

struct RunResult {
  int exit_code = -1;  // the program's exit status; 128 + n if killed by signal n
  std::string out;     // stdout
  std::string err;     // stderr

  // stderr split into lines (a final newline does not start another line).
  std::vector<std::string> err_lines() const {
    std::vector<std::string> lines;
    std::istringstream s(err);
    for (std::string line; std::getline(s, line);)
      lines.push_back(line);
    return lines;
  }
};

inline std::string read_file(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// 'text' for /bin/sh, whatever it holds.
inline std::string shell_quote(const std::string& text) {
  std::string q = "'";
  for (char c : text) {
    if (c == '\'')
      q += "'\\''";
    else
      q += c;
  }
  return q + "'";
}

// Runs `granmem args...` in folder `cwd`; stdout and stderr go to files in `capture`
// (a folder other than `cwd`, so that they never look like the program's output).
inline RunResult run_granmem(const std::vector<std::string>& args, const std::filesystem::path& cwd,
                             const std::filesystem::path& capture) {
  std::filesystem::create_directories(capture);
  const std::filesystem::path out = capture / "stdout.txt", err = capture / "stderr.txt";
  std::string cmd = "cd " + shell_quote(cwd.string()) + " && " + shell_quote(GRANMEM_EXE);
  for (const std::string& a : args)
    cmd += " " + shell_quote(a);
  cmd += " > " + shell_quote(out.string()) + " 2> " + shell_quote(err.string()) + " < /dev/null";
  const int status = std::system(cmd.c_str());
  RunResult r;
  if (status != -1 && WIFEXITED(status))
    r.exit_code = WEXITSTATUS(status);
  else if (status != -1 && WIFSIGNALED(status))
    r.exit_code = 128 + WTERMSIG(status);
  r.out = read_file(out);
  r.err = read_file(err);
  return r;
}

// Every regular file under `dir` (relative path -> contents), to see that a failed run
// left nothing behind and changed nothing.
inline std::map<std::string, std::string> snapshot(const std::filesystem::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    const std::string rel = std::filesystem::relative(e.path(), dir).string();
    files[rel] = e.is_regular_file() ? read_file(e.path()) : "<folder>";
  }
  return files;
}

// A temp folder per test with a working folder `work/` in which granmem runs, and
// stdout/stderr captured beside it.
class GranmemTest : public TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    std::filesystem::create_directories(work());
  }
  std::filesystem::path work() const { return dir_ / "work"; }
  std::filesystem::path in_work(const std::string& name) const { return work() / name; }

  RunResult granmem(const std::vector<std::string>& args) const {
    return run_granmem(args, work(), dir_ / "capture");
  }

  // Runs granmem and expects success; returns the result for further checks.
  RunResult granmem_ok(const std::vector<std::string>& args) const {
    RunResult r = granmem(args);
    std::string cmd;
    for (const std::string& a : args)
      cmd += " " + a;
    EXPECT_EQ(r.exit_code, 0) << "granmem" << cmd << "\nstderr: " << r.err;
    return r;
  }

  // Runs granmem expecting a clean failure whose single stderr line holds every `expected`.
  void expect_clean_failure(const std::vector<std::string>& args,
                            const std::vector<std::string>& expected) {
    std::string cmd = "granmem";
    for (const std::string& a : args)
      cmd += " " + a;
    SCOPED_TRACE(cmd);
    const auto before = snapshot(work());
    const RunResult r = granmem(args);
    EXPECT_NE(r.exit_code, 0);
    EXPECT_LT(r.exit_code, 128) << "killed by a signal";
    EXPECT_EQ(r.out, "");
    const std::vector<std::string> lines = r.err_lines();
    EXPECT_EQ(lines.size(), 1u) << "stderr:\n" << r.err;
    EXPECT_TRUE(!r.err.empty() && r.err.back() == '\n') << r.err;
    const std::string first = lines.empty() ? "" : lines[0];
    log_bad_input(cmd, r.exit_code, first);
    EXPECT_EQ(first.rfind("granmem: error: ", 0), 0u) << first;
    for (const std::string& e : expected)
      EXPECT_NE(first.find(e), std::string::npos) << "expected '" << e << "' in: " << first;
    // Nothing written, nothing left behind (no .<name>.tmp-*), nothing changed.
    const auto after = snapshot(work());
    for (const auto& [name, text] : after) {
      EXPECT_TRUE(before.count(name)) << "left behind: " << name;
    }
    for (const auto& [name, text] : before) {
      const auto it = after.find(name);
      if (it == after.end())
        ADD_FAILURE() << "removed: " << name;
      else
        EXPECT_TRUE(it->second == text) << "changed: " << name;
    }
  }

  // With GRANMEM_BAD_INPUT_LOG set, every refused input is appended to that file (test,
  // command, exit status, message; tab-separated): scripts/bad_input_table.sh makes
  // docs/BAD_INPUT.md from it, so that the table lists what the tests assert.
  static void log_bad_input(const std::string& cmd, int code, const std::string& message) {
    const char* log = std::getenv("GRANMEM_BAD_INPUT_LOG");
    if (!log || !*log) return;
    const ::testing::TestInfo* test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::ofstream(log, std::ios::app) << test->test_suite_name() << "." << test->name() << "\t"
                                      << cmd << "\t" << code << "\t" << message << "\n";
  }

  // Reads `columns` of a CSV written by granmem.
  static Table read_columns(const std::filesystem::path& csv,
                            const std::vector<std::string>& columns) {
    return read_csv(csv, columns).table;
  }

  // The header line of a CSV (first line that is not a '#' comment).
  static std::string csv_header(const std::filesystem::path& csv) {
    std::istringstream s(read_text(csv));
    for (std::string line; std::getline(s, line);) {
      if (!line.empty() && line.front() != '#') return line;
    }
    return "";
  }
};

}  // namespace granmem::testing
