// The publisher thread's idle sleep (daemon/include/rpem/daemon/publisher.hpp, publisher_idle_ns):
// clamp(0.5 / fastest publication rate, 1 ms, 20 ms). Each expected value is worked by hand below.
#include <gtest/gtest.h>

#include "rpem/daemon/daemon_config.hpp"
#include "rpem/daemon/publisher.hpp"

namespace rpem::daemon {
namespace {

LcmConfig rates(double estimate_Hz, double measurement_Hz, double diagnostics_Hz) {
  LcmConfig c;
  c.estimate_rate_Hz = estimate_Hz;
  c.measurement_rate_Hz = measurement_Hz;
  c.diagnostics_rate_Hz = diagnostics_Hz;
  return c;
}

TEST(PublisherIdle, HalfTheFastestPublicationPeriodClampedTo1To20Ms) {
  // Defaults 10, 100, 1 Hz: 0.5 / 100 Hz = 5 ms.
  EXPECT_EQ(publisher_idle_ns(LcmConfig{}), 5'000'000);
  // The fastest is whichever rate is highest: estimates at 50 Hz, measurements off: 0.5 / 50 = 10 ms.
  EXPECT_EQ(publisher_idle_ns(rates(50.0, 0.0, 1.0)), 10'000'000);
  // Measurements at 200 Hz: 2.5 ms; at 400 Hz: 1.25 ms (both inside the clamp).
  EXPECT_EQ(publisher_idle_ns(rates(10.0, 200.0, 1.0)), 2'500'000);
  EXPECT_EQ(publisher_idle_ns(rates(10.0, 400.0, 1.0)), 1'250'000);
  // 1 kHz and 8 kHz would be 0.5 ms and 62.5 us: clamped to 1 ms.
  EXPECT_EQ(publisher_idle_ns(rates(10.0, 1000.0, 1.0)), 1'000'000);
  EXPECT_EQ(publisher_idle_ns(rates(10.0, 8000.0, 1.0)), 1'000'000);
  // Many instances per host (docs/rpemd.md): measurements and estimates at 10 Hz: 50 ms, clamped to 20 ms;
  // at 25 Hz exactly 20 ms, at 26 Hz 19.23 ms (0.5e9 / 26 = 19 230 769.2 ns, rounded).
  EXPECT_EQ(publisher_idle_ns(rates(10.0, 10.0, 1.0)), 20'000'000);
  EXPECT_EQ(publisher_idle_ns(rates(10.0, 25.0, 1.0)), 20'000'000);
  EXPECT_EQ(publisher_idle_ns(rates(10.0, 26.0, 1.0)), 19'230'769);
  // The slowest the configuration allows (0.1 Hz estimates, measurements off, 0.1 Hz diagnostics): 20 ms.
  EXPECT_EQ(publisher_idle_ns(rates(0.1, 0.0, 0.1)), 20'000'000);
}

}  // namespace
}  // namespace rpem::daemon
