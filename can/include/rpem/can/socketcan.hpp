#pragma once
// SocketCAN transport: a raw CAN socket with CAN FD enabled, kernel ID and error filters, kernel
// receive timestamps, the kernel's dropped-frame counter (SO_RXQ_OVFL), error frames decoded into
// counters, non-blocking reads with poll(2), and automatic reopening when the interface goes down and
// up (or disappears and returns). Not real-time code: it runs on the receive thread.

#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "rpem/can/frame.hpp"
#include "rpem/can/kernel_filter.hpp"

struct msghdr;  // <sys/socket.h>, kept out of this header

namespace rpem::can {

struct ReceivedFrame {
  CanFrame frame;
  std::int64_t kernel_rx_ns = 0;  ///< kernel receive timestamp (CLOCK_REALTIME), 0 if unavailable
};

/// When a frame arrived: the kernel's receive stamp (CLOCK_REALTIME), else `fallback_ns` (read by the caller
/// from CLOCK_REALTIME once per batch).
[[nodiscard]] inline std::int64_t receive_time_ns(const ReceivedFrame& f, std::int64_t fallback_ns) noexcept {
  return f.kernel_rx_ns != 0 ? f.kernel_rx_ns : fallback_ns;
}

struct ChannelCounters {
  std::uint64_t rx_frames = 0;
  std::uint64_t tx_frames = 0;
  std::uint64_t tx_dropped = 0;    ///< send queue full or interface down
  std::uint64_t kernel_drops = 0;  ///< SO_RXQ_OVFL: frames the kernel dropped for this socket
  std::uint64_t reopens = 0;       ///< successful reopen after a failure
  std::uint64_t open_failures = 0;
  std::uint64_t error_frames = 0;
  std::uint64_t bus_off = 0;
  std::uint64_t error_passive = 0;  ///< controller reported rx or tx error-passive
  std::uint64_t error_warning = 0;
  std::uint64_t controller_overflow = 0;
  std::uint64_t protocol_violations = 0;
  std::uint64_t restarted = 0;  ///< controller restarted after bus-off
  std::uint64_t no_ack = 0;
};

class SocketCanChannel {
 public:
  struct Options {
    std::string interface;
    bool fd = true;                      ///< enable CAN FD frames
    bool receive = true;                 ///< false: a send-only socket (empty kernel filter)
    std::vector<std::uint32_t> ids;      ///< kernel filter: accept these 11-bit IDs only (empty: all)
    std::vector<KernelFilter> filters;   ///< further kernel filters (a frame passing any filter or id is read)
    bool receive_errors = true;          ///< subscribe to error frames
    int receive_buffer_bytes = 1 << 20;  ///< SO_RCVBUFFORCE, falling back to SO_RCVBUF
    int reopen_interval_ms = 100;

    /// A CAN FD socket reading only `ids` (and error frames).
    static Options receiver(std::string interface, std::vector<std::uint32_t> ids) {
      Options o;
      o.interface = std::move(interface);
      o.ids = std::move(ids);
      return o;
    }
    /// A send-only CAN FD socket: it reads nothing, error frames included.
    static Options sender(std::string interface) {
      Options o;
      o.interface = std::move(interface);
      o.receive = false;
      o.receive_errors = false;
      return o;
    }
  };

  explicit SocketCanChannel(Options options);
  ~SocketCanChannel();
  SocketCanChannel(const SocketCanChannel&) = delete;
  SocketCanChannel& operator=(const SocketCanChannel&) = delete;

  /// Waits up to timeout_ms for frames and reads what is available (up to out.size()). Error frames
  /// are counted and also returned (frame.error). Returns 0 on timeout or while the interface is down
  /// (reopening in the background of these calls).
  [[nodiscard]] std::size_t receive(std::span<ReceivedFrame> out, int timeout_ms) {
    return receive_for(out, static_cast<std::int64_t>(timeout_ms) * 1'000'000);
  }
  /// As receive(), waiting up to timeout_ns (ppoll(2): sub-millisecond waits for a poll schedule).
  [[nodiscard]] std::size_t receive_for(std::span<ReceivedFrame> out, std::int64_t timeout_ns);

  /// Sends one frame; waits up to timeout_ms for room in the queue. False if dropped.
  bool send(const CanFrame& frame, int timeout_ms = 10);

  [[nodiscard]] bool is_open() const noexcept { return fd_ >= 0; }
  [[nodiscard]] const ChannelCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const std::string& last_error() const noexcept { return last_error_; }
  /// The socket, for callers that multiplex; −1 while closed.
  [[nodiscard]] int native_handle() const noexcept { return fd_; }

 private:
  bool open();
  void close_socket(const std::string& why);
  void count_error_frame(const CanFrame& f);
  /// The kernel's receive time from a received message's ancillary data (0 without one); counts the
  /// socket's overflow drops (SO_RXQ_OVFL) on the way.
  std::int64_t read_ancillary(::msghdr& msg);

  Options options_;
  int fd_ = -1;
  bool was_open_ = false;
  std::int64_t next_open_attempt_ns_ = 0;
  std::uint32_t last_overflow_ = 0;
  ChannelCounters counters_;
  std::string last_error_;
};

/// An interface that cannot be opened: absent, or a kernel without SocketCAN (the tools exit 74 on it).
class InterfaceError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws InterfaceError with the reason if the interface cannot be opened now (start-up check).
void require_interface(const std::string& interface);

}  // namespace rpem::can
