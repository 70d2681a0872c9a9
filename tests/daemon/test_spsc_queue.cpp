#include <gtest/gtest.h>

#include <thread>

#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {
namespace {

TEST(SpscQueue, FifoOrderCapacityAndFullQueue) {
  auto [in, out] = SpscQueue<int>::make(5);
  EXPECT_EQ(in.capacity(), 8U);
  for (int k = 0; k < 8; ++k) EXPECT_TRUE(in.push(k));
  EXPECT_FALSE(in.push(99));  // full: refused, not overwritten
  int v = -1;
  for (int k = 0; k < 8; ++k) {
    ASSERT_TRUE(out.pop(v));
    EXPECT_EQ(v, k);
  }
  EXPECT_FALSE(out.pop(v));
}

TEST(SpscQueue, TwoThreadsTransferEveryItemInOrder) {
  auto q = SpscQueue<std::uint64_t>::make(64);
  constexpr std::uint64_t kItems = 2'000'000;
  std::thread producer([&] {
    for (std::uint64_t k = 1; k <= kItems;) {
      if (q.producer.push(k)) ++k;
    }
  });
  std::uint64_t expected = 1, v = 0;
  while (expected <= kItems) {
    if (q.consumer.pop(v)) {
      ASSERT_EQ(v, expected);
      ++expected;
    }
  }
  producer.join();
  EXPECT_EQ(q.consumer.size(), 0U);
}

}  // namespace
}  // namespace rpem::daemon
