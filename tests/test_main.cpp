// The main of every unit-test executable. An executable holds the tests of one folder (several
// modules compiled in batches, cmake/Batches.cmake); `--module=io/mesh/ply` runs only the tests
// written in io/mesh/ply_test.cpp, so ctest still runs, times and reports each module alone.
// A module without a test is an error, never an empty pass.
#include <cstdio>
#include <string>
#include <string_view>

#include <gtest/gtest.h>

namespace {

// "Suite.Name:Suite.Name…" for every test defined in a file ending in /MODULE_test.cpp.
std::string filterForModule(std::string_view module) {
  const std::string ending = "/" + std::string(module) + "_test.cpp";
  std::string filter;
  const testing::UnitTest& all = *testing::UnitTest::GetInstance();
  for (int s = 0; s < all.total_test_suite_count(); ++s) {
    const testing::TestSuite& suite = *all.GetTestSuite(s);
    for (int t = 0; t < suite.total_test_count(); ++t) {
      const testing::TestInfo& test = *suite.GetTestInfo(t);
      if (!std::string_view(test.file()).ends_with(ending)) continue;
      filter +=
          (filter.empty() ? "" : ":") + std::string(test.test_suite_name()) + "." + test.name();
    }
  }
  return filter;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  constexpr std::string_view kModule = "--module=";
  for (int a = 1; a < argc; ++a) {
    const std::string_view arg = argv[a];
    if (!arg.starts_with(kModule)) continue;
    const std::string filter = filterForModule(arg.substr(kModule.size()));
    if (filter.empty()) {
      std::fprintf(stderr, "no tests for module %s in this executable\n", argv[a] + kModule.size());
      return 1;
    }
    GTEST_FLAG_SET(filter, filter);
  }
  return RUN_ALL_TESTS();
}
