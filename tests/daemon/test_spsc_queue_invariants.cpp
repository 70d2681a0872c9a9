// The queue's invariants that no type can state (rpem/daemon/spsc_queue.hpp), asserted where assertions
// are on — forced on in this file, whatever the build: an end of no queue is not used, and each end is
// used by one thread. Its items are a type of this file only, so no other file shares these
// instantiations (rpem/core/assert.hpp).
#undef RPEM_ASSERTIONS
#define RPEM_ASSERTIONS 1
#include <gtest/gtest.h>

#include <thread>
#include <utility>

#include "rpem/daemon/spsc_queue.hpp"

namespace rpem::daemon {
namespace {

struct Item {
  int value = 0;
};
using Queue = SpscQueue<Item>;

TEST(SpscQueueInvariants, AMovedFromEndIsTheEndOfNoQueue) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  auto q = Queue::make(4);
  Queue::Producer producer = std::move(q.producer);
  EXPECT_TRUE(producer.push({1}));
  EXPECT_DEATH((void)q.producer.push({2}), "invariant violated: queue_ != nullptr");
  Item item;
  Queue::Consumer none;
  EXPECT_DEATH((void)none.pop(item), "invariant violated: queue_ != nullptr");
}

TEST(SpscQueueInvariants, AnEndIsUsedByOneThread) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(
      {
        auto q = Queue::make(4);
        (void)q.producer.push({1});
        std::thread second([&] { (void)q.producer.push({2}); });  // a second producing thread
        second.join();
      },
      "used by one thread");
  // Handed over, an end belongs to the thread that uses it next.
  auto q = Queue::make(4);
  Queue::Producer producer = std::move(q.producer);
  std::thread first([&] { EXPECT_TRUE(producer.push({1})); });
  first.join();
  Queue::Producer handed_over = std::move(producer);
  EXPECT_TRUE(handed_over.push({2}));
  Item item;
  EXPECT_TRUE(q.consumer.pop(item));
  EXPECT_EQ(item.value, 1);
}

}  // namespace
}  // namespace rpem::daemon
