// The bus budget of docs/can-protocol.md, recomputed from the bit counts of ISO 11898-1.
#include <gtest/gtest.h>

#include <cstdio>

#include "rpem/can/bus_load.hpp"

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

// A VESC poll with the estimator's 31-byte reply (docs/can-vesc.md), classic extended frames: request
// 7 bytes (123 bits + 27 stuff = 150); FILL_RX_BUFFER 4 × 8 bytes (131 + 29 = 160 each) and 1 × 4 bytes
// (99 + 21 = 120); PROCESS_RX_BUFFER 6 bytes (115 + 25 = 140): 1050 bits, 1.05 ms at 1 Mbit/s.
TEST(BusLoad, AVescPollWithTheEstimatorsReplyTakes1050Bits) {
  EXPECT_NEAR(extended_frame_time_s(8, {1e6, 1e6}), 160e-6, 1e-12);
  EXPECT_NEAR(vesc_poll_time_s(31, {1e6, 1e6}), 1050e-6, 1e-12);
  EXPECT_NEAR(vesc_poll_time_s(4, {1e6, 1e6}), 150e-6 + 115e-6 + 25e-6, 1e-12);  // one short buffer of 6 bytes
}

// docs/rpemd.md, "Several drives on one bus": the highest per-drive sample rate 12 drives can share under
// 70 % bus load (worst-case stuffing), per source and bit rate. Printed for the documentation; the VESC
// and native figures asserted.
TEST(BusLoad, TwelveDrivesPerSourceUnderSeventyPercent) {
  constexpr double kDrives = 12.0, kLoad = 0.70;
  struct Row {
    const char* source;
    const char* bus;
    double per_sample_s;  ///< bus time per drive and sample
    double shared_s;      ///< bus time per sample period shared by all drives (a SYNC)
  };
  const BusTiming classic{1e6, 1e6}, fd1{1e6, 1e6}, fd5{1e6, 5e6};
  // CiA 402 (config/signal-maps/beckhoff-ax8000-cia402.yaml): TxPDOs of 4, 8, 8 and 6 bytes per drive,
  // one SYNC (0 bytes) for all.
  const double pdos = frame_time_s(false, 4, classic) + 2 * frame_time_s(false, 8, classic) + frame_time_s(false, 6, classic);
  const Row rows[] = {
      {"native (rpem telemetry)", "classic 1 Mbit/s", telemetry_budget(false, 1.0, 1, classic).load, 0.0},
      {"native (rpem telemetry)", "CAN FD 1/1 Mbit/s", telemetry_budget(true, 1.0, 3, fd1).load, 0.0},
      {"native (rpem telemetry)", "CAN FD 1/5 Mbit/s", telemetry_budget(true, 1.0, 3, fd5).load, 0.0},
      {"vesc (31-byte reply)", "classic 1 Mbit/s (VESC has no CAN FD)", vesc_poll_time_s(31, classic), 0.0},
      {"signal_map (CiA 402 PDOs)", "classic 1 Mbit/s", pdos, frame_time_s(false, 0, classic)},
  };
  double rate[5] = {};
  for (int k = 0; k < 5; ++k) {
    const Row& r = rows[k];
    rate[k] = kLoad / (kDrives * r.per_sample_s + r.shared_s);
    std::printf("| %s | %s | %.1f µs | %.0f Hz |\n", r.source, r.bus, r.per_sample_s * 1e6, rate[k]);
  }
  EXPECT_NEAR(rate[0], 86.4, 0.1);   // 5 × 135 bits per sample
  EXPECT_NEAR(rate[3], 55.6, 0.1);   // 1050 bits per poll
  EXPECT_GT(rate[2], 1000.0);        // a third of a 64-byte FD frame per sample
}

}  // namespace
}  // namespace rpem::can
