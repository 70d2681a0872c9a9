// The bus budget of docs/can-protocol.md, recomputed from the bit counts of ISO 11898-1.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace rpem::can
