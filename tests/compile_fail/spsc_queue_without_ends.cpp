// A queue exists only with its two ends (SpscQueue<T>::make): one cannot be made by hand and reached by
// any number of threads.
#include "rpem/daemon/spsc_queue.hpp"

int main() {
#ifdef RPEM_COMPILE_FAIL
  rpem::daemon::SpscQueue<int> queue(4);
#else
  auto queue = rpem::daemon::SpscQueue<int>::make(4);
#endif
  (void)queue;
  return 0;
}
