// SocketCAN on a real vcan0 (run inside the PREEMPT_RT VM by tests/vm/run_vcan_suite.sh, or natively
// where the host has vcan): CAN FD frames with kernel timestamps, the kernel ID filter, the kernel drop
// counter, error frames, and recovery when the interface goes down and up or is recreated.
#include <gtest/gtest.h>

#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <thread>

#include "rpem/can/protocol.hpp"
#include "rpem/can/socketcan.hpp"
#include "rpem/core/clock.hpp"

namespace rpem::can {
namespace {

const char* kIface = std::getenv("RPEM_VCAN") ? std::getenv("RPEM_VCAN") : "vcan0";

CanFrame fd_frame(std::uint32_t id, std::uint8_t fill) {
  CanFrame f;
  f.id = id;
  f.fd = true;
  f.len = 64;
  f.data.fill(fill);
  return f;
}

std::size_t receive_for(SocketCanChannel& ch, std::vector<ReceivedFrame>& out, int ms) {
  std::size_t total = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
  std::vector<ReceivedFrame> buf(256);
  while (std::chrono::steady_clock::now() < end) {
    const std::size_t n = ch.receive(buf, 20);
    out.insert(out.end(), buf.begin(), buf.begin() + static_cast<long>(n));
    total += n;
  }
  return total;
}

std::int64_t realtime_ns() { return core::now_ns(CLOCK_REALTIME); }

TEST(SocketCan, FdFramesArriveWithKernelTimestamps) {
  SocketCanChannel rx(SocketCanChannel::Options::receiver(kIface, {protocol::kFdId}));
  SocketCanChannel tx(SocketCanChannel::Options::sender(kIface));
  ASSERT_TRUE(rx.is_open()) << rx.last_error();
  ASSERT_TRUE(tx.is_open()) << tx.last_error();
  const std::int64_t before = realtime_ns();
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(tx.send(fd_frame(protocol::kFdId, static_cast<std::uint8_t>(k))));
  std::vector<ReceivedFrame> got;
  receive_for(rx, got, 300);
  ASSERT_EQ(got.size(), 10U);
  for (int k = 0; k < 10; ++k) {
    EXPECT_TRUE(got[static_cast<std::size_t>(k)].frame.fd);
    EXPECT_EQ(got[static_cast<std::size_t>(k)].frame.len, 64);
    EXPECT_EQ(got[static_cast<std::size_t>(k)].frame.data[63], k);
    const std::int64_t ts = got[static_cast<std::size_t>(k)].kernel_rx_ns;
    EXPECT_GE(ts, before);
    EXPECT_LE(ts, realtime_ns());
  }
  EXPECT_EQ(rx.counters().rx_frames, 10U);
  EXPECT_EQ(tx.counters().tx_frames, 10U);
}

TEST(SocketCan, KernelFilterPassesOnlyTelemetryIds) {
  SocketCanChannel rx(SocketCanChannel::Options::receiver(kIface, {protocol::kFdId, 0x110}));
  SocketCanChannel tx(SocketCanChannel::Options::sender(kIface));
  tx.send(fd_frame(0x101, 1));
  tx.send(fd_frame(protocol::kFdId, 2));
  CanFrame classic;
  classic.id = 0x110;
  classic.len = 8;
  tx.send(classic);
  classic.id = 0x7FF;
  tx.send(classic);
  std::vector<ReceivedFrame> got;
  receive_for(rx, got, 200);
  ASSERT_EQ(got.size(), 2U);
  EXPECT_EQ(got[0].frame.id, protocol::kFdId);
  EXPECT_EQ(got[1].frame.id, 0x110U);
  EXPECT_FALSE(got[1].frame.fd);
}

TEST(SocketCan, KernelDropCounterCountsWhatTheSocketQueueLost) {
  auto o = SocketCanChannel::Options::receiver(kIface, {protocol::kFdId});
  o.receive_buffer_bytes = 4096;  // tiny: the queue overflows while nobody reads
  SocketCanChannel rx(o);
  SocketCanChannel tx(SocketCanChannel::Options::sender(kIface));
  constexpr int kSent = 2000;
  for (int k = 0; k < kSent; ++k) ASSERT_TRUE(tx.send(fd_frame(protocol::kFdId, 0)));
  std::vector<ReceivedFrame> got;
  receive_for(rx, got, 300);
  tx.send(fd_frame(protocol::kFdId, 0));  // a frame after the overflow carries the drop count
  receive_for(rx, got, 200);
  EXPECT_GT(rx.counters().kernel_drops, 0U);
  EXPECT_EQ(got.size() + rx.counters().kernel_drops, static_cast<std::size_t>(kSent + 1));
}

TEST(SocketCan, ErrorFramesAreDecodedIntoCounters) {
  // A raw socket may put error frames on a virtual bus; the receiver subscribed to them decodes them.
  SocketCanChannel rx(SocketCanChannel::Options::receiver(kIface, {protocol::kFdId}));
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  ASSERT_GE(fd, 0);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(if_nametoindex(kIface));
  ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  can_frame busoff{};
  busoff.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  busoff.len = CAN_ERR_DLC;
  can_frame passive{};
  passive.can_id = CAN_ERR_FLAG | CAN_ERR_CRTL;
  passive.len = CAN_ERR_DLC;
  passive.data[1] = CAN_ERR_CRTL_RX_PASSIVE;
  const bool sent =
      ::write(fd, &busoff, sizeof busoff) == sizeof busoff && ::write(fd, &passive, sizeof passive) == sizeof passive;
  ::close(fd);
  if (!sent) GTEST_SKIP() << "this kernel does not pass error frames from a raw socket";
  std::vector<ReceivedFrame> got;
  receive_for(rx, got, 200);
  EXPECT_EQ(rx.counters().error_frames, 2U);
  EXPECT_EQ(rx.counters().bus_off, 1U);
  EXPECT_EQ(rx.counters().error_passive, 1U);
  ASSERT_EQ(got.size(), 2U);
  EXPECT_TRUE(got[0].frame.error);
}

TEST(SocketCan, SurvivesTheInterfaceGoingDownAndUp) {
  SocketCanChannel rx(SocketCanChannel::Options::receiver(kIface, {protocol::kFdId}));
  SocketCanChannel tx(SocketCanChannel::Options::sender(kIface));
  std::vector<ReceivedFrame> got;
  tx.send(fd_frame(protocol::kFdId, 1));
  receive_for(rx, got, 100);
  ASSERT_EQ(got.size(), 1U);
  ASSERT_EQ(std::system((std::string("ip link set ") + kIface + " down").c_str()), 0);
  receive_for(rx, got, 300);  // sees ENETDOWN, closes, keeps trying
  EXPECT_FALSE(tx.send(fd_frame(protocol::kFdId, 2)));
  ASSERT_EQ(std::system((std::string("ip link set ") + kIface + " up").c_str()), 0);
  receive_for(rx, got, 300);
  got.clear();
  ASSERT_TRUE(tx.send(fd_frame(protocol::kFdId, 3)) || tx.send(fd_frame(protocol::kFdId, 3)));
  receive_for(rx, got, 300);
  ASSERT_GE(got.size(), 1U);
  EXPECT_EQ(got.back().frame.data[0], 3);
  EXPECT_GE(rx.counters().reopens, 1U);
}

TEST(SocketCan, ReopensWhenTheInterfaceIsRecreated) {
  ASSERT_EQ(std::system("ip link add dev rpemtest0 type vcan && ip link set rpemtest0 mtu 72 && ip link set rpemtest0 up"),
            0);
  SocketCanChannel rx(SocketCanChannel::Options::receiver("rpemtest0", {protocol::kFdId}));
  ASSERT_TRUE(rx.is_open());
  ASSERT_EQ(std::system("ip link del rpemtest0"), 0);
  std::vector<ReceivedFrame> got;
  receive_for(rx, got, 300);
  EXPECT_FALSE(rx.is_open());
  ASSERT_EQ(std::system("ip link add dev rpemtest0 type vcan && ip link set rpemtest0 mtu 72 && ip link set rpemtest0 up"),
            0);
  receive_for(rx, got, 400);
  EXPECT_TRUE(rx.is_open());
  SocketCanChannel tx(SocketCanChannel::Options::sender("rpemtest0"));
  tx.send(fd_frame(protocol::kFdId, 9));
  receive_for(rx, got, 200);
  ASSERT_EQ(got.size(), 1U);
  EXPECT_GE(rx.counters().reopens, 1U);
  (void)std::system("ip link del rpemtest0");
}

}  // namespace
}  // namespace rpem::can
