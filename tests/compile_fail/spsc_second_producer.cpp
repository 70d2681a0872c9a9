// A queue has one producer: its producer end cannot be copied, only handed over (moved).
#include <utility>

#include "rpem/daemon/spsc_queue.hpp"

int main() {
  auto queue = rpem::daemon::SpscQueue<int>::make(4);
#ifdef RPEM_COMPILE_FAIL
  rpem::daemon::SpscQueue<int>::Producer second = queue.producer;  // a second producer
#else
  rpem::daemon::SpscQueue<int>::Producer second = std::move(queue.producer);  // the one producer, handed over
#endif
  return second.push(1) ? 0 : 1;
}
