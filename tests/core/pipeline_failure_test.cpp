#include "lodforge/core/pipeline_failure.h"

#include <atomic>
#include <cstdint>
#include <string>

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

// A failure in a later stage stops the first: no batch is read after the failure is seen, and
// the kept failure is the earliest batch's even when a later batch failed first.
TEST(PipelineFailure, StopsThePipelineAndKeepsTheEarliestBatch) {
  PipelineFailure failure;
  std::uint64_t next = 0;
  std::atomic<std::uint64_t> readAfterFailure{0};
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
            if (failure.failed()) ++readAfterFailure;
            if (b == 40 || b == 41)
              failure.fail(b, Error{ErrorKind::kIo, "batch " + std::to_string(b)});
          }));
  ASSERT_TRUE(failure.failed());
  EXPECT_EQ(failure.status().error().message, "batch 40");
  EXPECT_LT(next, 1000u);                  // stopped early
  EXPECT_LE(readAfterFailure.load(), 4u);  // at most the batches already in flight
}

}  // namespace
}  // namespace lodforge
