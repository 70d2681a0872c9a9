#include "rpem/can/socketcan.hpp"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <linux/net_tstamp.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "rpem/core/clock.hpp"
#include "rpem/core/errno_text.hpp"

static_assert(rpem::can::kEffFlag == CAN_EFF_FLAG && rpem::can::kRtrFlag == CAN_RTR_FLAG &&
              rpem::can::kEffMask == CAN_EFF_MASK);

namespace rpem::can {
namespace {

std::string errno_text(const char* what) { return std::string(what) + ": " + core::errno_text(errno); }

/// The frame a raw socket read: classic or FD (by the read's size), error, extended or standard.
CanFrame to_can_frame(const canfd_frame& raw, bool fd) {
  CanFrame frame{};
  frame.fd = fd;
  frame.len = std::min<std::uint8_t>(raw.len, frame.fd ? 64 : 8);
  std::memcpy(frame.data.data(), raw.data, frame.len);
  if (raw.can_id & CAN_ERR_FLAG) {
    frame.error = true;
    frame.id = raw.can_id & CAN_ERR_MASK;
  } else if (raw.can_id & CAN_EFF_FLAG) {
    frame.extended = true;
    frame.id = raw.can_id & CAN_EFF_MASK;
  } else {
    frame.id = raw.can_id & CAN_SFF_MASK;
  }
  return frame;
}

}  // namespace

SocketCanChannel::SocketCanChannel(Options options) : options_(std::move(options)) { (void)open(); }

SocketCanChannel::~SocketCanChannel() {
  if (fd_ >= 0) ::close(fd_);
}

bool SocketCanChannel::open() {
  next_open_attempt_ns_ = core::now_ns(CLOCK_MONOTONIC) + static_cast<std::int64_t>(options_.reopen_interval_ms) * 1'000'000;
  const unsigned index = if_nametoindex(options_.interface.c_str());
  if (index == 0) {
    last_error_ = "no interface " + options_.interface;
    ++counters_.open_failures;
    return false;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    last_error_ = errno_text("socket(PF_CAN)");
    ++counters_.open_failures;
    return false;
  }
  const int on = 1;
  if (options_.fd) (void)setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on);
  if (!options_.receive) {
    (void)setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, nullptr, 0);
  } else if (!options_.ids.empty() || !options_.filters.empty()) {
    std::vector<can_filter> filters;
    for (std::uint32_t id : options_.ids) filters.push_back({id, CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG});
    for (const KernelFilter& k : options_.filters) filters.push_back({k.id, k.mask});
    (void)setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter)));
  }
  if (options_.receive_errors) {
    const can_err_mask_t mask = CAN_ERR_TX_TIMEOUT | CAN_ERR_CRTL | CAN_ERR_PROT | CAN_ERR_TRX | CAN_ERR_ACK |
                                CAN_ERR_BUSOFF | CAN_ERR_BUSERROR | CAN_ERR_RESTARTED;
    (void)setsockopt(fd, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &mask, sizeof mask);
  }
  const int tsflags = SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE;
  if (setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPING, &tsflags, sizeof tsflags) != 0) {
    (void)setsockopt(fd, SOL_SOCKET, SO_TIMESTAMP, &on, sizeof on);
  }
  (void)setsockopt(fd, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof on);
  const int buf = options_.receive_buffer_bytes;
  if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &buf, sizeof buf) != 0) {
    (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buf, sizeof buf);
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    last_error_ = errno_text("bind");
    ::close(fd);
    ++counters_.open_failures;
    return false;
  }
  fd_ = fd;
  last_overflow_ = 0;
  if (was_open_) ++counters_.reopens;
  was_open_ = true;
  last_error_.clear();
  return true;
}

void SocketCanChannel::close_socket(const std::string& why) {
  last_error_ = why;
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  next_open_attempt_ns_ = core::now_ns(CLOCK_MONOTONIC) + static_cast<std::int64_t>(options_.reopen_interval_ms) * 1'000'000;
}

void SocketCanChannel::count_error_frame(const CanFrame& f) {
  ++counters_.error_frames;
  const std::uint32_t cls = f.id;
  if (cls & CAN_ERR_BUSOFF) ++counters_.bus_off;
  if (cls & CAN_ERR_RESTARTED) ++counters_.restarted;
  if (cls & CAN_ERR_ACK) ++counters_.no_ack;
  if (cls & CAN_ERR_PROT) ++counters_.protocol_violations;
  if (cls & CAN_ERR_CRTL) {
    const std::uint8_t ctrl = f.data[1];
    if (ctrl & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) ++counters_.error_passive;
    if (ctrl & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) ++counters_.error_warning;
    if (ctrl & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) ++counters_.controller_overflow;
  }
}

std::int64_t SocketCanChannel::read_ancillary(msghdr& msg) {
  std::int64_t kernel_rx_ns = 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level != SOL_SOCKET) continue;
    if (c->cmsg_type == SO_TIMESTAMPING) {
      timespec ts[3];
      std::memcpy(ts, CMSG_DATA(c), sizeof ts);
      kernel_rx_ns = core::to_ns(ts[0]);
    } else if (c->cmsg_type == SO_TIMESTAMP) {
      timeval tv{};
      std::memcpy(&tv, CMSG_DATA(c), sizeof tv);
      kernel_rx_ns = core::to_ns(tv);
    } else if (c->cmsg_type == SO_RXQ_OVFL) {
      std::uint32_t overflow = 0;
      std::memcpy(&overflow, CMSG_DATA(c), sizeof overflow);
      counters_.kernel_drops += static_cast<std::uint32_t>(overflow - last_overflow_);  // wraps with it
      last_overflow_ = overflow;
    }
  }
  return kernel_rx_ns;
}

std::size_t SocketCanChannel::receive_for(std::span<ReceivedFrame> out, std::int64_t timeout_ns) {
  timeout_ns = std::max<std::int64_t>(timeout_ns, 0);
  if (fd_ < 0) {
    if (core::now_ns(CLOCK_MONOTONIC) < next_open_attempt_ns_ || !open()) {
      const std::int64_t pause_ns =
          std::min<std::int64_t>(timeout_ns, std::int64_t{options_.reopen_interval_ms} * 1'000'000);
      timespec pause{static_cast<time_t>(pause_ns / 1'000'000'000), static_cast<long>(pause_ns % 1'000'000'000)};
      nanosleep(&pause, nullptr);
      return 0;
    }
  }
  pollfd pfd{fd_, POLLIN, 0};
  const timespec wait{static_cast<time_t>(timeout_ns / 1'000'000'000), static_cast<long>(timeout_ns % 1'000'000'000)};
  const int ready = ::ppoll(&pfd, 1, &wait, nullptr);
  if (ready <= 0) return 0;
  if (pfd.revents & (POLLERR | POLLHUP | POLLNVAL)) {
    int err = 0;
    socklen_t len = sizeof err;
    (void)getsockopt(fd_, SOL_SOCKET, SO_ERROR, &err, &len);
    close_socket(std::string("socket error: ") + core::errno_text(err));
    return 0;
  }
  std::size_t n = 0;
  while (n < out.size()) {
    canfd_frame raw{};
    char control[CMSG_SPACE(sizeof(timespec) * 3) + CMSG_SPACE(sizeof(std::uint32_t)) + 64];
    iovec iov{&raw, sizeof raw};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    const ssize_t got = ::recvmsg(fd_, &msg, 0);
    if (got < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) break;
      if (errno == EINTR) continue;
      close_socket(errno_text("recvmsg"));  // ENETDOWN, ENODEV…: reopen later
      break;
    }
    ReceivedFrame& r = out[n];
    r.kernel_rx_ns = read_ancillary(msg);
    r.frame = to_can_frame(raw, got == static_cast<ssize_t>(CANFD_MTU));
    if (r.frame.error) count_error_frame(r.frame);
    ++counters_.rx_frames;
    ++n;
  }
  return n;
}

bool SocketCanChannel::send(const CanFrame& frame, int timeout_ms) {
  if (fd_ < 0 && (core::now_ns(CLOCK_MONOTONIC) < next_open_attempt_ns_ || !open())) {
    ++counters_.tx_dropped;
    return false;
  }
  canfd_frame raw{};
  raw.can_id = frame.extended ? (frame.id & CAN_EFF_MASK) | CAN_EFF_FLAG : frame.id & CAN_SFF_MASK;
  raw.len = frame.len;
  if (frame.fd) raw.flags = CANFD_BRS;
  std::memcpy(raw.data, frame.data.data(), frame.len);
  const std::size_t size = frame.fd ? CANFD_MTU : CAN_MTU;
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (::write(fd_, &raw, size) == static_cast<ssize_t>(size)) {
      ++counters_.tx_frames;
      return true;
    }
    if (errno == ENOBUFS || errno == EAGAIN) {
      pollfd pfd{fd_, POLLOUT, 0};
      if (::poll(&pfd, 1, timeout_ms) > 0) continue;
      break;
    }
    close_socket(errno_text("write"));
    break;
  }
  ++counters_.tx_dropped;
  return false;
}

void require_interface(const std::string& interface) {
  if (if_nametoindex(interface.c_str()) == 0) {
    throw InterfaceError("CAN interface '" + interface + "' does not exist (bring it up first, docs/can-protocol.md)");
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) throw InterfaceError(errno_text("socket(PF_CAN): this kernel has no SocketCAN"));
  ::close(fd);
}

}  // namespace rpem::can
