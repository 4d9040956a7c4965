#include "lodforge/core/progress.h"

#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace lodforge {
namespace {

TEST(Cancel, RequestTurnsIntoACancelledStatus) {
  clearCancel();
  EXPECT_TRUE(checkCancelled().ok());
  requestCancel();
  const Status status = checkCancelled();
  ASSERT_FALSE(status.ok());
  EXPECT_EQ(status.kind(), ErrorKind::kCancelled);
  EXPECT_EQ(exitCodeFor(status), 1);
  clearCancel();
  EXPECT_TRUE(checkCancelled().ok());
}

TEST(Progress, QuickWorkPrintsNothing) {
  setProgressMode(ProgressMode::kLines);
  testing::internal::CaptureStderr();
  {
    Progress progress("quick", 100);
    for (int i = 0; i < 100; ++i) progress.advance(1);
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");
  setProgressMode(ProgressMode::kAuto);
}

TEST(Progress, SlowWorkPrintsLinesAndAFinalOne) {
  setProgressMode(ProgressMode::kLines);
  testing::internal::CaptureStderr();
  {
    Progress progress("slow", 4);
    std::vector<std::thread> workers;
    for (int t = 0; t < 2; ++t) {
      workers.emplace_back([&] {
        for (int i = 0; i < 2; ++i) {
          std::this_thread::sleep_for(std::chrono::milliseconds(600));
          progress.advance(1);
        }
      });
    }
    for (auto& w : workers) w.join();
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  EXPECT_NE(printed.find("slow: "), std::string::npos) << printed;
  EXPECT_NE(printed.find("100% (4/4)"), std::string::npos) << printed;
  EXPECT_NE(printed.find(" done"), std::string::npos) << printed;
  setProgressMode(ProgressMode::kAuto);
}

}  // namespace
}  // namespace lodforge
