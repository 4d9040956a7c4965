#include "lodforge/core/cluster.h"

#include <filesystem>

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

// A process not started by mpirun or srun is a job of one: every collective step is its own
// outcome, and nothing is written for other ranks. (Several ranks: tests/mpi_tiles.sh.)
TEST(Cluster, AProcessNotStartedAsAJobIsAJobOfOne) {
  ASSERT_TRUE(joinCluster().ok());
  EXPECT_EQ(clusterRank(), 0);
  EXPECT_EQ(clusterSize(), 1);
  EXPECT_FALSE(clustered());
  EXPECT_TRUE(agreeAcrossRanks({}).ok());
  const Status failed = agreeAcrossRanks(Error{ErrorKind::kBadInput, "x.ply: cut short"});
  ASSERT_FALSE(failed.ok());
  EXPECT_EQ(failed.kind(), ErrorKind::kBadInput);
  EXPECT_EQ(failed.message(), "x.ply: cut short") << "no rank named in a job of one";
  Result<std::uint64_t> sum = sumAcrossRanks(41);
  ASSERT_TRUE(sum.ok());
  EXPECT_EQ(*sum, 41u);
  const std::vector<std::uint64_t> mine = {7, 0, 9};
  Result<std::vector<std::uint64_t>> gathered = gatherAcrossRanks(mine);
  ASSERT_TRUE(gathered.ok());
  EXPECT_EQ(*gathered, mine);
  EXPECT_FALSE(clusterFailureAgreed());
  EXPECT_NE(describeRank().find("rank 0 of 1"), std::string::npos) << describeRank();

  const test::TempDir dir;
  setActivityDirectory(dir.file("ranks"));
  reportActivity("chunking");
  reportProgress("nodes", 3);
  EXPECT_FALSE(std::filesystem::exists(dir.file("ranks"))) << "nothing to tell other ranks";
  EXPECT_EQ(otherRanksActivities(), "");
  EXPECT_FALSE(clusterAbandoned());
  leaveCluster(1);  // a failure in a job of one aborts nothing
}

// srun's tasks with no MPI plugin each work alone: said, naming the cure. A batch script (no
// step) or a step of one task is a job of one, and says nothing.
TEST(Cluster, SrunTasksWithoutAnMpiPluginAreWarnedOf) {
  EXPECT_FALSE(tasksNotJoined(nullptr));
  EXPECT_FALSE(tasksNotJoined("1"));
  const std::optional<std::string> alone = tasksNotJoined("4");
  ASSERT_TRUE(alone);
  EXPECT_NE(alone->find("one of 4 tasks"), std::string::npos) << *alone;
  EXPECT_NE(alone->find("each task works alone"), std::string::npos) << *alone;
}

// A job's ranks ask for OpenMPI's shared-memory layer only when mpirun put them all on this
// machine and nothing chose a layer: --mca pml (or -x), a parameter file named, or one of the
// standard files.
TEST(Cluster, OnlyAJobOnOneMachineWithNoLayerChosenAsksForSharedMemory) {
  EXPECT_TRUE(ob1SharedMemoryWanted({"4", "4", nullptr, nullptr, false}));
  EXPECT_FALSE(ob1SharedMemoryWanted({"8", "4", nullptr, nullptr, false})) << "two machines";
  EXPECT_FALSE(ob1SharedMemoryWanted({nullptr, nullptr, nullptr, nullptr, false})) << "srun";
  EXPECT_FALSE(ob1SharedMemoryWanted({"4", nullptr, nullptr, nullptr, false}));
  EXPECT_FALSE(ob1SharedMemoryWanted({"4", "4", "ucx", nullptr, false})) << "--mca pml ucx";
  EXPECT_FALSE(ob1SharedMemoryWanted({"4", "4", nullptr, "/site/mca.conf", false}));
  EXPECT_FALSE(ob1SharedMemoryWanted({"4", "4", nullptr, nullptr, true})) << "pml = in a file";
}

// A parameter file chooses a layer with `pml = NAME`, not with a list of layers ruled out
// (Debian's own file), a comment, another parameter or no file at all.
TEST(Cluster, AParameterFileChoosesALayerOnlyByNamingIt) {
  const test::TempDir dir;
  const auto chooses = [&](const std::string& text) {
    test::writeFile(dir.file("mca-params.conf"), text);
    return paramFileChoosesPml(dir.file("mca-params.conf"));
  };
  EXPECT_TRUE(chooses("btl = ^openib\npml = ucx\n"));
  EXPECT_TRUE(chooses("  pml=ob1"));
  EXPECT_FALSE(chooses("mtl = ^ofi\npml = ^ucx\n"));
  EXPECT_FALSE(chooses("# pml = ucx\npml_ucx_verbose = 1\n"));
  EXPECT_FALSE(paramFileChoosesPml(dir.file("none.conf")));
}

// Largest first to the least loaded rank, ties by order: the same deal on every rank, within
// 4/3 of the best busiest rank.
TEST(Cluster, WorkIsDealtLargestFirstToTheLeastLoadedRank) {
  const std::vector<std::uint64_t> work = {5, 9, 2, 9, 7, 1};
  const std::vector<int> owner = dealLargestFirst(work, 2);
  // 9→0, 9→1, 7→0 (a tie: the lower rank), 5→1, 2→1, 1→0 (a tie again).
  EXPECT_EQ(owner, (std::vector<int>{1, 0, 1, 1, 0, 0}));
  std::vector<std::uint64_t> load(2, 0);
  for (std::size_t i = 0; i < work.size(); ++i) load[static_cast<std::size_t>(owner[i])] += work[i];
  EXPECT_EQ(load[0], 17u);
  EXPECT_EQ(load[1], 16u);
  EXPECT_EQ(dealLargestFirst(work, 1), std::vector<int>(work.size(), 0));
  EXPECT_TRUE(dealLargestFirst({}, 3).empty());
}

}  // namespace
}  // namespace lodforge
