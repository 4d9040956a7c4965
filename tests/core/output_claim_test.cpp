// What a run killed before it could clean up left at its output is removed by the next run to
// the same output, and nothing else is: not a running process's temporaries, not another
// output's, not a name lodforge does not make.
#include "lodforge/core/output_claim.h"

#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

// The PID of a process that has ended (a child that exits at once, reaped).
int deadProcess() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(OutputClaim, TellsTheTemporaryNamesOfAnOutput) {
  EXPECT_EQ(leftoverProcess("a.ply.tmp-123-0", "a.ply"), 123);
  EXPECT_EQ(leftoverProcess("a.ply.tmp-123-17.bin", "a.ply"), 123);
  EXPECT_EQ(leftoverProcess("tiles.work.tmp-9-2", "tiles"), 9);
  for (const char* other : {"a.ply", "a.ply.tmp-", "a.ply.tmp-123", "a.ply.tmp-123-",
                            "a.ply.tmp-x-1", "a.ply.tmp-123-4x", "b.ply.tmp-123-0",
                            "a.plyx.tmp-123-0", "a.ply.tmp-0-1", "a.ply.old.tmp-5-1"})
    EXPECT_FALSE(leftoverProcess(other, "a.ply").has_value()) << other;
}

TEST(OutputClaim, RemovesTheLeftoversOfADeadRunAtItsOutputOnly) {
  test::TempDir dir;
  const int dead = deadProcess(), alive = static_cast<int>(::getppid());
  const auto name = [&](const std::string& rest) { return dir.file("out.glb" + rest); };
  const std::vector<std::string> gone = {name(fmt::format(".tmp-{}-0", dead)),
                                         name(fmt::format(".tmp-{}-3.bin", dead))};
  const std::vector<std::string> kept = {
      name(fmt::format(".tmp-{}-1", alive)),  // a run still going
      name(".tmp-notes"),                     // not a name lodforge makes
      dir.file(fmt::format("other.glb.tmp-{}-0", dead)),
  };
  for (const std::string& path : gone) test::writeFile(path, "partial");
  for (const std::string& path : kept) test::writeFile(path, "keep");
  const std::string work = name(fmt::format(".work.tmp-{}-2", dead));
  std::filesystem::create_directories(work + "/chunks");
  test::writeFile(work + "/chunks/0.bin", "partial");
  const std::string inputPath = dir.file("in.ply");
  test::writeFile(inputPath, "ply\n");
  const OutputKind kind{"a GLB file", false, [](const std::string&) { return true; }};
  ASSERT_TRUE(claimOutput(dir.file("out.glb"), kind, std::vector<std::string>{inputPath}).ok());
  for (const std::string& path : gone) EXPECT_FALSE(std::filesystem::exists(path)) << path;
  EXPECT_FALSE(std::filesystem::exists(work));
  for (const std::string& path : kept) EXPECT_TRUE(std::filesystem::exists(path)) << path;
  EXPECT_EQ(removeDeadLeftovers(dir.file("out.glb")), 0u);  // nothing left to remove
}

// One run at a time writes a work directory: a second lock is refused, naming the holder, until
// the first is released (a second open of the lock file conflicts even within one process).
TEST(OutputClaim, AWorkDirectoryIsWrittenByOneRunAtATime) {
  const test::TempDir dir;
  const std::string work = dir.file("t.work");
  ASSERT_TRUE(claimWorkDirectory(work).ok());
  {
    Result<WorkLock> first = lockWorkDirectory(work);
    ASSERT_TRUE(first.ok()) << first.status().message();
    Result<WorkLock> second = lockWorkDirectory(work);
    ASSERT_FALSE(second.ok());
    EXPECT_EQ(second.status().kind(), ErrorKind::kUsage);
    EXPECT_NE(
        second.status().message().find(fmt::format("another lodforge run (pid {} on", ::getpid())),
        std::string::npos)
        << second.status().message();
    WorkLock moved = std::move(*first);  // the lock goes with it
    EXPECT_FALSE(lockWorkDirectory(work).ok());
    EXPECT_TRUE(workDirectoryLocked(work));
  }
  EXPECT_FALSE(workDirectoryLocked(work)) << "released with the last holder";
  EXPECT_TRUE(lockWorkDirectory(work).ok());
  EXPECT_FALSE(workDirectoryLocked(dir.file("elsewhere"))) << "and creates nothing";
  EXPECT_FALSE(std::filesystem::exists(dir.file("elsewhere")));
}

}  // namespace
}  // namespace lodforge
