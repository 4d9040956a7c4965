#include "lodforge/core/pipeline_failure.h"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include <tbb/parallel_pipeline.h>

namespace lodforge {
namespace {

// Of several failures, the one nearest the start of the file is kept, whatever their order.
TEST(PipelineFailure, KeepsTheFailureNearestTheStart) {
  PipelineFailure failure;
  EXPECT_FALSE(failure.failed());
  EXPECT_TRUE(failure.status().ok());
  failure.fail(500, Error{ErrorKind::kIo, "at 500"});
  failure.fail(200, Error{ErrorKind::kBadInput, "at 200"});
  failure.fail(900, Error{ErrorKind::kIo, "at 900"});
  EXPECT_TRUE(failure.failed());
  EXPECT_EQ(failure.status().error().kind, ErrorKind::kBadInput);
  EXPECT_EQ(failure.status().error().message, "at 200");
}

// Only failures before a position count for it: a stage that skips its batch when an earlier
// one failed still reports its own when only a later one did.
TEST(PipelineFailure, FailedBeforeCountsOnlyEarlierPositions) {
  PipelineFailure failure;
  EXPECT_FALSE(failure.failedBefore(~std::uint64_t{0}));
  failure.fail(300, Error{ErrorKind::kIo, "at 300"});
  EXPECT_FALSE(failure.failedBefore(300));
  EXPECT_TRUE(failure.failedBefore(301));
  failure.fail(100, Error{ErrorKind::kIo, "at 100"});
  EXPECT_TRUE(failure.failedBefore(101));
  EXPECT_FALSE(failure.failedBefore(100));
}

// A pipeline whose parallel stage skips a batch only after an earlier failure, as the points'
// reading pass does: batch 41 fails first (batch 40 waits for it, up to 2 s where one thread
// runs both in turn), yet batch 40's failure is the one kept, and the first stage stops reading
// once a failure is known.
TEST(PipelineFailure, AnEarlierBatchFailingLaterIsStillTheOneKept) {
  PipelineFailure failure;
  std::uint64_t next = 0;
  std::atomic<bool> laterFailed{false};
  tbb::parallel_pipeline(
      4,
      tbb::make_filter<void, std::uint64_t>(tbb::filter_mode::serial_in_order,
                                            [&](tbb::flow_control& control) -> std::uint64_t {
                                              if (failure.failed() || next == 1000) {
                                                control.stop();
                                                return 0;
                                              }
                                              return next++;
                                            }) &
          tbb::make_filter<std::uint64_t, void>(tbb::filter_mode::parallel, [&](std::uint64_t b) {
            if (b == 40) {
              const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(2);
              while (!laterFailed && std::chrono::steady_clock::now() < until)
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
            }
            if (failure.failedBefore(b)) return;
            if (b == 40 || b == 41) {
              failure.fail(b, Error{ErrorKind::kIo, "batch " + std::to_string(b)});
              if (b == 41) laterFailed = true;
            }
          }));
  ASSERT_TRUE(failure.failed());
  EXPECT_EQ(failure.status().error().message, "batch 40");
  EXPECT_LT(next, 1000u);  // the reading stopped
}

}  // namespace
}  // namespace lodforge
