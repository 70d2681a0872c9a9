#pragma once
// The loop thread's three queues as the Daemon wires them, with the test in the other threads' places: it
// pushes samples as the source thread, commands as the control thread, and pops reports as the publisher.

#include <cstddef>
#include <utility>

#include "rpem/daemon/loop_thread.hpp"

namespace rpem::test {

struct LoopQueues {
  daemon::SpscQueue<daemon::SourceSample>::Producer input;  ///< the source thread's end
  daemon::SpscQueue<daemon::Command>::Producer commands;    ///< the control thread's end
  daemon::SpscQueue<daemon::Report>::Consumer output;       ///< the publisher's end
  daemon::LoopThread::Queues loop;                          ///< the loop's ends, for its constructor
};

inline LoopQueues loop_queues(std::size_t samples, std::size_t commands, std::size_t reports) {
  auto in = daemon::SpscQueue<daemon::SourceSample>::make(samples);
  auto to_loop = daemon::SpscQueue<daemon::Command>::make(commands);
  auto out = daemon::SpscQueue<daemon::Report>::make(reports);
  return {std::move(in.producer),
          std::move(to_loop.producer),
          std::move(out.consumer),
          {std::move(in.consumer), std::move(to_loop.consumer), std::move(out.producer)}};
}

}  // namespace rpem::test
