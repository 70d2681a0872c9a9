#include "rpem/daemon/realtime.hpp"

#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>

#include <cerrno>
#include <cstring>

#include "rpem/core/errno_text.hpp"

namespace rpem::daemon {

std::string apply_thread_policy(const ThreadPolicy& p) {
  std::string problems;
  if (p.cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(p.cpu, &set);
    if (const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set); rc != 0) {
      problems += std::string("cpu ") + std::to_string(p.cpu) + ": " + core::errno_text(rc) + "; ";
    }
  }
  sched_param param{};
  param.sched_priority = p.fifo ? p.priority : 0;
  if (const int rc = pthread_setschedparam(pthread_self(), p.fifo ? SCHED_FIFO : SCHED_OTHER, &param); rc != 0) {
    problems += std::string("SCHED_FIFO ") + std::to_string(p.priority) + ": " + core::errno_text(rc) +
                (rc == EPERM ? " (needs LimitRTPRIO or CAP_SYS_NICE)" : "") + "; ";
  }
  return problems;
}

std::string lock_memory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    return std::string("mlockall: ") + core::errno_text(errno) +
           (errno == ENOMEM || errno == EPERM ? " (needs LimitMEMLOCK)" : "");
  }
  return "";
}

int request_cpu_dma_latency(int us, std::string& problem) {
  const int fd = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  if (fd < 0) {
    problem = std::string("/dev/cpu_dma_latency: ") + core::errno_text(errno);
    return -1;
  }
  const std::int32_t value = us;
  if (::write(fd, &value, sizeof value) != static_cast<ssize_t>(sizeof value)) {
    problem = std::string("/dev/cpu_dma_latency: ") + core::errno_text(errno);
    ::close(fd);
    return -1;
  }
  return fd;
}

void prefault_stack(std::size_t bytes) {
  volatile unsigned char* block = static_cast<volatile unsigned char*>(__builtin_alloca(bytes));
  for (std::size_t k = 0; k < bytes; k += 4096) block[k] = 0;
}

void name_thread(const char* name) { pthread_setname_np(pthread_self(), name); }

}  // namespace rpem::daemon
