#include "rpem/daemon/socketcan_source.hpp"

#include <cstdio>

namespace rpem::daemon {

void ChannelNotices::check(const can::SocketCanChannel& channel, const std::string& interface) {
  if (channel.is_open()) {
    if (!said_.empty()) std::fprintf(stderr, "rpemd: %s: open again; reading\n", interface.c_str());
    said_.clear();
    return;
  }
  const std::string& problem = channel.last_error();
  if (problem.empty() || problem == said_) return;
  std::fprintf(stderr, "rpemd: %s: cannot read CAN: %s; retrying (diagnostics can_open_failures counts the tries)\n",
               interface.c_str(), problem.c_str());
  said_ = problem;
}

}  // namespace rpem::daemon
