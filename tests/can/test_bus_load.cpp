// The bus budget of docs/can-protocol.md, recomputed from the bit counts of ISO 11898-1.
#include <gtest/gtest.h>

#include "rpem/can/bus_load.hpp"

#include <cstdio>
#include <string>

#include "rpem/can/signal_map.hpp"
#include "rpem/can/vesc.hpp"
#include "rpem/io/signal_map_config.hpp"

namespace rpem::can {
namespace {

TEST(BusLoad, ClassicFrameBitsWithWorstCaseStuffing) {
  // 8 data bytes: 47 + 64 = 111 bits, 98 of them stuffable → 24 stuff bits: 135 bits.
  EXPECT_NEAR(frame_time_s(false, 8, {1e6, 1e6}), 135e-6, 1e-12);
}

TEST(BusLoad, FdFrameBitsWithWorstCaseStuffing) {
  // Nominal: 17 + 4 stuff + 13 = 34 bits; data: 517 + 129 dynamic + 4 SBC + 21 CRC + 8 fixed = 679.
  EXPECT_NEAR(frame_time_s(true, 64, {1e6, 5e6}), 34e-6 + 679 / 5e6, 1e-12);
}

TEST(BusLoad, DefaultConfigurationStaysBelowSeventyPercentOnOneFiveFd) {
  const BusBudget fd = telemetry_budget(true, 8000.0, 3, {1e6, 5e6});
  EXPECT_NEAR(fd.frames_per_s, 2666.67, 0.01);
  EXPECT_LT(fd.load, 0.70);
  EXPECT_GT(fd.load, 0.40);
  // 500k/2M cannot carry 8 kHz; 4 kHz fits.
  EXPECT_GT(telemetry_budget(true, 8000.0, 3, {500e3, 2e6}).load, 1.0);
  EXPECT_LT(telemetry_budget(true, 4000.0, 3, {500e3, 2e6}).load, 0.70);
  // Classic CAN at 1 Mbit/s: the reduced 1 kHz rate.
  EXPECT_LT(telemetry_budget(false, 1000.0, 1, {1e6, 1e6}).load, 0.70);
}

}  // namespace
}  // namespace rpem::can

// ---- Several drives per bus (issue 12, item 6): frame bits by hand, then the table. ----
namespace rpem::can {
namespace {

TEST(BusLoad, ExtendedAndEmptyFramesByHand) {
  // 29-bit ID, 8 bytes: SOF, 11 ID, SRR, IDE, 18 ID, RTR, r1, r0, DLC 4 = 39, data 64, CRC 15 → 118 stuffable,
  // (118 − 1)/4 = 29 stuff bits, + 13 tail: 160.
  EXPECT_EQ(frame_bits({false, true, 8, 1.0}).nominal, 160);
  EXPECT_EQ(frame_bits({false, true, 0, 1.0}).nominal, 54 + 13 + 13);  // 80
  EXPECT_EQ(frame_bits({false, false, 0, 1.0}).nominal, 34 + 8 + 13);  // SYNC: 55
  // FD, 29-bit ID: 36 stuffable nominal bits (+ 8 stuff + 13 tail); the data phase as for 11 bits.
  EXPECT_EQ(frame_bits({true, true, 64, 1.0}).nominal, 57);
  EXPECT_EQ(frame_bits({true, true, 64, 1.0}).data, 679);
  // 26 bytes travel as 32: 5 + 256 = 261 dynamic, 65 stuff, SBC 4, CRC 21 with 8 fixed stuff bits: 359.
  EXPECT_EQ(fd_padded_length(26), 32);
  EXPECT_EQ(fd_padded_length(9), 12);
  EXPECT_EQ(fd_padded_length(6), 6);
  EXPECT_EQ(frame_bits({true, false, 26, 1.0}).data, 359);
}

TEST(BusLoad, VescPollAndReplyByHand) {
  // Poll 7 bytes; the 31-byte reply of the estimator's mask: fills of 8, 8, 8, 8, 4 bytes, process 6.
  const Traffic t = vesc_poll_traffic(0x001801B3);
  ASSERT_EQ(t.per_drive.size(), 7U);
  const int want_bytes[] = {7, 8, 8, 8, 8, 4, 6};
  int bits = 0;
  for (std::size_t k = 0; k < 7; ++k) {
    EXPECT_EQ(t.per_drive[k].payload_bytes, want_bytes[k]);
    EXPECT_TRUE(t.per_drive[k].extended);
    bits += frame_bits(t.per_drive[k]).nominal;
  }
  // 7 bytes: 123 + (109 − 1)/4 = 150; 8: 160 (×4); 4: 99 + 21 = 120; 6: 115 + 25 = 140.
  EXPECT_EQ(bits, 150 + 4 * 160 + 120 + 140);
  // 12 drives on classic 1 Mbit/s at 70 %: 0.7e6 / (12·1050) = 55.6 Hz each.
  EXPECT_NEAR(max_sample_rate_Hz(t, 12, 0.7, {1e6, 1e6}), 0.7e6 / 12600.0, 1e-9);
}

TEST(BusLoad, NativeAndCia402ByHand) {
  // Native classic: 5 × 135 bits per sample → 0.7e6 / (12·675) = 86.4 Hz.
  EXPECT_NEAR(max_sample_rate_Hz(native_traffic(false, 3), 12, 0.7, {1e6, 1e6}), 0.7e6 / 8100.0, 1e-9);
  // Native FD 1/5: a 169.8 µs frame per 3 samples → 0.7 / (12·56.6 µs) = 1030.6 Hz.
  EXPECT_NEAR(max_sample_rate_Hz(native_traffic(true, 3), 12, 0.7, {1e6, 5e6}), 0.7 / (12 * 169.8e-6 / 3), 1e-6);
  // The AX8000 map's four PDOs (4, 8, 8, 8 bytes: 95 + 135 + 135 + 135 bits) and one SYNC (55) per bus:
  //   4 bytes: 47 + 32 = 79 bits + (34 + 32 − 1)/4 = 16 stuff bits = 95; 8 bytes: 111 + 97/4 = 24 → 135;
  //   SYNC (no data): 47 + (34 − 1)/4 = 8 → 55. 12 drives: 12·500 + 55 = 6055 µs per sample period, at 70 %
  //   0.7/6055 µs = 115.6 Hz.
  const Traffic t = signal_map_traffic(
      io::load_signal_map(std::string(RPEM_TEST_SOURCE_DIR) + "/config/signal-maps/beckhoff-ax8000-cia402.yaml"), false,
      true);
  EXPECT_NEAR(time_per_sample_s(t, 12, {1e6, 1e6}), (12 * 500 + 55) * 1e-6, 1e-12);
  EXPECT_NEAR(max_sample_rate_Hz(t, 12, 0.7, {1e6, 1e6}), 0.7e6 / 6055.0, 1e-9);
}

/// The table of docs/benchmarks.md ("Several drives per bus"), printed.
TEST(BusLoad, TwelveDrivesUnderSeventyPercent) {
  const auto map =
      io::load_signal_map(std::string(RPEM_TEST_SOURCE_DIR) + "/config/signal-maps/beckhoff-ax8000-cia402.yaml");
  struct Bus {
    const char* name;
    bool fd;
    BusTiming timing;
  };
  const Bus buses[] = {
      {"classic 1 Mbit/s", false, {1e6, 1e6}}, {"FD 1M/1M", true, {1e6, 1e6}}, {"FD 1M/5M", true, {1e6, 5e6}}};
  std::printf(
      "| source (12 drives, 70 %% load, worst-case stuffing) | classic 1 Mbit/s | CAN FD 1 Mbit/s data | CAN FD 5 Mbit/s data |\n|---|---|---|---|\n");
  int map_bytes = 0;  // every PDO of the map in one FD frame
  for (const FrameSpec& f : map.frames) map_bytes += f.length;
  EXPECT_EQ(map_bytes, 4 + 8 + 8 + 8);
  const std::string packed = "CiA 402, the map's " + std::to_string(map_bytes) +
                             " bytes packed in one PDO (CANopen FD: one " + std::to_string(fd_padded_length(map_bytes)) +
                             "-byte FD frame)";
  const char* names[] = {"rpem native telemetry (classic: 5×8 B/sample; FD: 64 B per 3 samples)",
                         "VESC COMM_GET_VALUES_SELECTIVE poll + reply (7 classic 29-bit frames)",
                         "CiA 402 PDO set (AX8000 map: 4 PDOs + 1 SYNC per bus)",
                         "VESC, averages and ERPM only (mask 0x1800B0: 25-byte reply, 6 frames)", packed.c_str()};
  double vesc_1m = 0;
  for (int s = 0; s < 5; ++s) {
    std::printf("| %s |", names[s]);
    for (const Bus& b : buses) {
      Traffic t = s == 0   ? native_traffic(b.fd, 3)
                  : s == 1 ? vesc_poll_traffic(vesc::kEstimatorMask)
                  : s == 2 ? signal_map_traffic(map, b.fd, true)
                  : s == 3 ? vesc_poll_traffic(vesc::bit(vesc::kId) | vesc::bit(vesc::kIq) | vesc::bit(vesc::kRpm) |
                                               vesc::bit(vesc::kVd) | vesc::bit(vesc::kVq))
                           : signal_map_traffic(map, b.fd, true);
      if (s == 4) t.per_drive = {{b.fd, false, map_bytes, 1.0}};
      if (s == 4 && !b.fd) {
        std::printf(" — (8 bytes at most) |");
        continue;
      }
      const double f = max_sample_rate_Hz(t, 12, 0.7, b.timing);
      if (s == 1 && !b.fd) vesc_1m = f;
      std::printf(" %.0f Hz |", f);
    }
    std::printf("\n");
  }
  EXPECT_NEAR(vesc_1m, 55.6, 0.1);
}

}  // namespace
}  // namespace rpem::can
