#include "granmem/core/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "granmem/core/error.hpp"
#include "temp_dir.hpp"

namespace granmem {
namespace {

namespace fs = std::filesystem;

class AtomicFileTest : public granmem::testing::TempDirTest {};

TEST_F(AtomicFileTest, CommitRenamesTheTemporaryFileIntoPlace) {
  const fs::path target = path("out.txt");
  AtomicFile f(target);
  EXPECT_EQ(f.target(), target);
  EXPECT_EQ(f.temp_path().parent_path(), dir_);  // same folder: the rename is atomic
  EXPECT_NE(f.temp_path(), target);
  EXPECT_EQ(f.temp_path().filename().string().rfind(".out.txt.tmp-", 0), 0u);
  write_text(f.temp_path(), "hello\n");
  EXPECT_FALSE(fs::exists(target));  // nothing under the real name before commit
  f.commit();
  EXPECT_EQ(read_text(target), "hello\n");
  EXPECT_FALSE(fs::exists(f.temp_path()));
  EXPECT_EQ(listing(), (std::vector<std::string>{"out.txt"}));
  f.commit();  // a second commit does nothing
  EXPECT_EQ(read_text(target), "hello\n");
}

TEST_F(AtomicFileTest, CommitReplacesAnExistingFile) {
  const fs::path target = path("out.txt");
  write_text(target, "old");
  {
    AtomicFile f(target);
    write_text(f.temp_path(), "new contents");
    f.commit();
  }
  EXPECT_EQ(read_text(target), "new contents");
  EXPECT_EQ(listing(), (std::vector<std::string>{"out.txt"}));
}

TEST_F(AtomicFileTest, WithoutCommitTheTempGoesAndTheTargetIsUntouched) {
  const fs::path target = path("data.bin");
  const std::string original("original\0\x01\xff bytes\n", 19);
  write_text(target, original);
  fs::path temp;
  {
    AtomicFile f(target);
    temp = f.temp_path();
    write_text(temp, "half-written junk");
    ASSERT_TRUE(fs::exists(temp));
  }
  EXPECT_FALSE(fs::exists(temp));
  EXPECT_EQ(read_text(target), original);
  EXPECT_EQ(fs::file_size(target), original.size());
  EXPECT_EQ(listing(), (std::vector<std::string>{"data.bin"}));

  // Also when the scope is left by an exception.
  try {
    AtomicFile f(target);
    write_text(f.temp_path(), "junk");
    throw Error("failure while writing");
  } catch (const Error&) {
  }
  EXPECT_EQ(read_text(target), original);
  EXPECT_EQ(listing(), (std::vector<std::string>{"data.bin"}));
}

TEST_F(AtomicFileTest, WithoutCommitNoFileAppears) {
  { AtomicFile f(path("new.txt")); }  // no temp written at all
  {
    AtomicFile f(path("new.txt"));
    write_text(f.temp_path(), "x");
  }
  EXPECT_TRUE(listing().empty());
}

TEST_F(AtomicFileTest, MovedFromObjectNeitherRemovesNorCommits) {
  const fs::path target = path("moved.txt");
  AtomicFile a(target);
  write_text(a.temp_path(), "payload");
  AtomicFile b(std::move(a));
  EXPECT_TRUE(fs::exists(b.temp_path()));
  b.commit();
  EXPECT_EQ(read_text(target), "payload");
}

TEST_F(AtomicFileTest, DistinctTempNamesForTheSameTarget) {
  AtomicFile a(path("x.txt"));
  AtomicFile b(path("x.txt"));
  EXPECT_NE(a.temp_path(), b.temp_path());
}

TEST_F(AtomicFileTest, MissingFolderOrFolderTargetIsAnError) {
  try {
    AtomicFile f(path("missing") / "out.txt");
    FAIL() << "expected granmem::Error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos) << e.what();
  }
  fs::create_directory(path("sub"));
  EXPECT_THROW(AtomicFile f(path("sub")), Error);
  EXPECT_EQ(listing(), (std::vector<std::string>{"sub"}));
}

// A process that has ended: its id.
pid_t ended_process() {
  const pid_t child = fork();
  if (child == 0) _exit(0);
  int status = 0;
  waitpid(child, &status, 0);
  return child;
}

TEST_F(AtomicFileTest, TemporariesOfAKilledWriterAreRemovedByTheNext) {
  const std::string dead = ".run.h5.tmp-" + std::to_string(ended_process()) + "-0";
  const std::string live = ".run.h5.tmp-" + std::to_string(getpid()) + "-7";
  const std::string other = ".other.h5.tmp-" + std::to_string(ended_process()) + "-0";
  for (const std::string& name : {dead, live, other, std::string("run.h5")})
    write_text(path(name), "x");
  {
    AtomicFile f(path("run.h5"));
    write_text(f.temp_path(), "new");
    f.commit();
  }
  // The killed writer's temporary of run.h5 is gone; a running writer's, another target's
  // and the target itself are not touched but by the commit.
  std::vector<std::string> expected{live, other, "run.h5"};
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(listing(), expected);
  EXPECT_EQ(read_text(path("run.h5")), "new");
}

// The message of check_outputs, or "" when it accepts.
std::string refusal(const std::vector<NamedPath>& outputs, const std::vector<NamedPath>& inputs) {
  try {
    check_outputs(outputs, inputs);
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

TEST_F(AtomicFileTest, AnOutputThatIsAnInputByAnyNameIsRefused) {
  write_text(path("t.csv"), "x,y,z\n");
  fs::create_directory(path("sub"));
  fs::create_symlink(path("t.csv"), path("link.csv"));
  fs::create_hard_link(path("t.csv"), path("sub") / "hard.csv");
  const std::vector<NamedPath> in{{"table", path("t.csv")}};
  for (const fs::path& out :
       {path("t.csv"), path("sub") / ".." / "t.csv", path("link.csv"), path("sub") / "hard.csv"}) {
    const std::string why = refusal({{"--out", out}}, in);
    EXPECT_NE(why.find("is the input table"), std::string::npos) << out << ": " << why;
  }
  // Relative and absolute names of one file, the output not there yet.
  const fs::path cwd = fs::current_path();
  fs::current_path(dir_);
  EXPECT_NE(refusal({{"--out", "new.h5"}}, {{"run", dir_ / "new.h5"}}), "");
  EXPECT_EQ(refusal({{"--out", "other.h5"}}, {{"run", dir_ / "new.h5"}}), "");
  fs::current_path(cwd);
  EXPECT_EQ(read_text(path("t.csv")), "x,y,z\n");
}

TEST_F(AtomicFileTest, TwoOutputsThatAreOneFileOrAMissingFolderAreRefused) {
  fs::create_directory(path("sub"));
  const std::string twice = refusal({{"--out", path("a.h5")}, {"--csv", path("sub/../a.h5")}}, {});
  EXPECT_NE(twice.find("are one file"), std::string::npos) << twice;
  const std::string missing = refusal({{"--out", path("missing") / "a.h5"}}, {});
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;
  EXPECT_EQ(
      refusal({{"--out", path("a.h5")}, {"--csv", path("a.csv")}}, {{"table", path("t.csv")}}), "");
  EXPECT_EQ(listing(), (std::vector<std::string>{"sub"}));
}

}  // namespace
}  // namespace granmem
