// Send-to-receive latency through a SocketCAN interface: one thread sends 64-byte CAN FD frames at a
// fixed rate (paced with clock_nanosleep), each carrying its sequence number; the receiver (this
// process, another socket) matches them and reports the latency from the moment of write(2) to the
// kernel receive timestamp and to the return of recvmsg(2), as percentiles, plus losses and kernel
// drops.   vcan_latency IFACE FRAMES_PER_S SECONDS
#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <thread>
#include <vector>

#include "rpem/can/socketcan.hpp"
#include "rpem/core/clock.hpp"

namespace {

using rpem::core::now_ns;
using rpem::core::sleep_until_ns;

void report(const char* what, std::vector<double> v) {
  if (v.empty()) return;
  std::sort(v.begin(), v.end());
  auto pct = [&](double q) { return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]; };
  std::printf("%s [us]: p50 %.1f, p99 %.1f, p99.9 %.1f, max %.1f\n", what, pct(0.5), pct(0.99), pct(0.999), v.back());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: vcan_latency IFACE FRAMES_PER_S SECONDS\n");
    return 2;
  }
  const std::string iface = argv[1];
  const double rate = std::atof(argv[2]);
  const auto total = static_cast<std::size_t>(rate * std::atof(argv[3]));
  rpem::can::SocketCanChannel rx(rpem::can::SocketCanChannel::Options::receiver(iface, {0x100}));
  rpem::can::SocketCanChannel tx(rpem::can::SocketCanChannel::Options::sender(iface));
  std::vector<std::int64_t> sent_at(total, 0);
  std::atomic<bool> done{false};

  std::thread sender([&] {
    const auto period = static_cast<std::int64_t>(1e9 / rate);
    std::int64_t next = now_ns(CLOCK_MONOTONIC);
    for (std::size_t k = 0; k < total; ++k) {
      next += period;
      sleep_until_ns(CLOCK_MONOTONIC, next);
      rpem::can::CanFrame f;
      f.id = 0x100;
      f.fd = true;
      f.len = 64;
      for (int b = 0; b < 4; ++b) f.data[static_cast<std::size_t>(b)] = static_cast<std::uint8_t>(k >> (8 * b));
      sent_at[k] = now_ns(CLOCK_REALTIME);
      tx.send(f, 50);
    }
    done = true;
  });

  std::vector<double> kernel_us, user_us;
  std::vector<rpem::can::ReceivedFrame> buf(64);
  std::size_t received = 0;
  std::int64_t idle_since = 0;
  while (true) {
    const std::size_t n = rx.receive(buf, 50);
    const std::int64_t t_user = now_ns(CLOCK_REALTIME);
    for (std::size_t i = 0; i < n; ++i) {
      std::size_t k = 0;
      for (int b = 0; b < 4; ++b) k |= static_cast<std::size_t>(buf[i].frame.data[static_cast<std::size_t>(b)]) << (8 * b);
      if (k >= total || sent_at[k] == 0) continue;
      kernel_us.push_back(1e-3 * static_cast<double>(buf[i].kernel_rx_ns - sent_at[k]));
      user_us.push_back(1e-3 * static_cast<double>(t_user - sent_at[k]));
      ++received;
    }
    if (n == 0 && done) {
      if (idle_since == 0) idle_since = now_ns(CLOCK_MONOTONIC);
      if (now_ns(CLOCK_MONOTONIC) - idle_since > 500'000'000) break;
    } else {
      idle_since = 0;
    }
  }
  sender.join();
  std::printf("vcan_latency: %zu frames sent at %.0f/s, %zu received, %zu lost, kernel drops %llu, tx dropped %llu\n", total,
              rate, received, total - received, static_cast<unsigned long long>(rx.counters().kernel_drops),
              static_cast<unsigned long long>(tx.counters().tx_dropped));
  report("write(2) -> kernel receive timestamp", kernel_us);
  report("write(2) -> recvmsg(2) returned", user_us);
  return received == total ? 0 : 1;
}
