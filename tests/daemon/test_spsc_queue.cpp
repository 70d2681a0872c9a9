#include <gtest/gtest.h>

#include <thread>

#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {
namespace {

TEST(SpscQueue, FifoOrderCapacityAndFullQueue) {
  SpscQueue<int> q(5);
  EXPECT_EQ(q.capacity(), 8U);
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(q.push(k));
  EXPECT_FALSE(q.push(99));  // full: refused, not overwritten
  int v = -1;
  for (int k = 0; k < 8; ++k) {
    ASSERT_TRUE(q.pop(v));
    EXPECT_EQ(v, k);
  }
  EXPECT_FALSE(q.pop(v));
}

TEST(SpscQueue, TwoThreadsTransferEveryItemInOrder) {
  SpscQueue<std::uint64_t> q(64);
  constexpr std::uint64_t kItems = 2'000'000;
  std::thread producer([&] {
    for (std::uint64_t k = 1; k <= kItems;) {
      if (q.push(k)) ++k;
    }
  });
  std::uint64_t expected = 1, v = 0;
  while (expected <= kItems) {
    if (q.pop(v)) {
      ASSERT_EQ(v, expected);
      ++expected;
    }
  }
  producer.join();
  EXPECT_EQ(q.size(), 0U);
}

}  // namespace
}  // namespace rpem::daemon
