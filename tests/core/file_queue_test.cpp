#include "lodforge/core/file_queue.h"

#include <atomic>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.h"

namespace lodforge {
namespace {

// Consumers on several threads (as ranks' threads would be) against a producer that publishes
// while they wait: every item is claimed once, by one of them, and all stop once it closes.
TEST(FileQueue, EveryItemIsClaimedExactlyOnceWhileItIsProduced) {
  const test::TempDir dir;
  const FileQueue queue(dir.file("queue"));
  ASSERT_TRUE(queue.create().ok());
  constexpr int kItems = 60, kConsumers = 3;
  std::mutex mutex;
  std::multiset<std::string> claimed;
  std::vector<int> perConsumer(kConsumers, 0);
  std::vector<std::thread> consumers;
  for (int c = 0; c < kConsumers; ++c) {
    consumers.emplace_back([&, c] {
      std::uint64_t cursor = 0;
      for (;;) {
        Result<std::optional<std::string>> item = queue.claim(cursor);
        ASSERT_TRUE(item.ok()) << item.status().message();
        if (!*item) return;
        const std::lock_guard lock(mutex);
        claimed.insert(**item);
        ++perConsumer[static_cast<std::size_t>(c)];
      }
    });
  }
  for (int i = 0; i < kItems; ++i) {
    ASSERT_TRUE(queue.publish(static_cast<std::uint64_t>(i), "item " + std::to_string(i)).ok());
    if (i % 10 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(queue.close(kItems).ok());
  for (std::thread& t : consumers) t.join();
  ASSERT_EQ(claimed.size(), static_cast<std::size_t>(kItems));
  for (int i = 0; i < kItems; ++i) EXPECT_EQ(claimed.count("item " + std::to_string(i)), 1u) << i;
}

// A producer that failed closes the queue as failed: a waiting consumer stops at once, without
// the items it would otherwise wait for.
TEST(FileQueue, AFailedProducerStopsTheConsumers) {
  const test::TempDir dir;
  const FileQueue queue(dir.file("queue"));
  ASSERT_TRUE(queue.create().ok());
  std::atomic<bool> stopped{false};
  std::thread consumer([&] {
    std::uint64_t cursor = 0;
    Result<std::optional<std::string>> item = queue.claim(cursor);
    EXPECT_TRUE(item.ok());
    EXPECT_FALSE(item.ok() && item->has_value());
    stopped = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(stopped) << "the consumer must wait while the queue is open";
  ASSERT_TRUE(queue.close(5, /*failed=*/true).ok());
  consumer.join();
  EXPECT_TRUE(stopped);
}

// An item the closing note counts but nobody holds is an error, not a silent end.
TEST(FileQueue, AMissingItemAfterTheCloseIsAnError) {
  const test::TempDir dir;
  const FileQueue queue(dir.file("queue"));
  ASSERT_TRUE(queue.create().ok());
  ASSERT_TRUE(queue.publish(0, "a").ok());
  ASSERT_TRUE(queue.close(2).ok());  // item 1 never published
  std::uint64_t cursor = 0;
  Result<std::optional<std::string>> first = queue.claim(cursor);
  ASSERT_TRUE(first.ok() && first->has_value());
  EXPECT_EQ(**first, "a");
  Result<std::optional<std::string>> second = queue.claim(cursor);
  ASSERT_FALSE(second.ok());
  EXPECT_NE(second.status().message().find("a queued item is missing"), std::string::npos);
}

}  // namespace
}  // namespace lodforge
