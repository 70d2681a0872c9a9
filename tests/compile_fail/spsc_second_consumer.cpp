// A queue has one consumer: its consumer end cannot be copied (nor copy-assigned), only handed over.
#include <utility>

#include "rpem/daemon/spsc_queue.hpp"

int main() {
  auto queue = rpem::daemon::SpscQueue<int>::make(4);
  rpem::daemon::SpscQueue<int>::Consumer second;
#ifdef RPEM_COMPILE_FAIL
  second = queue.consumer;  // a second consumer
#else
  second = std::move(queue.consumer);  // the one consumer, handed over
#endif
  int item = 0;
  return second.pop(item) ? 1 : 0;
}
