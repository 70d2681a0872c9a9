// A drive's temperature sensor as RPEM_MEASUREMENT reports it (daemon/sensor_reading.hpp): the newest reading and
// its age in the samples' time; none before the first reading or after the time base starts again.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "rpem/daemon/sensor_reading.hpp"

namespace rpem::daemon {
namespace {

constexpr double kNoReading = std::numeric_limits<double>::quiet_NaN();

TEST(SensorReading, HoldsTheNewestReadingAndSaysHowOldItIs) {
  SensorReading s;
  s.on_sample(kNoReading, 1'000'000);
  EXPECT_TRUE(std::isnan(s.value_C()));
  EXPECT_TRUE(std::isnan(s.age_s(1'000'000)));
  s.on_sample(61.5, 2'000'000);                                                                 // read on the sample at 2 ms
  for (std::int64_t t = 2'125'000; t <= 102'000'000; t += 125'000) s.on_sample(kNoReading, t);  // 100 ms at 8 kHz
  EXPECT_EQ(s.value_C(), 61.5);
  EXPECT_DOUBLE_EQ(s.age_s(102'000'000), 0.1);
  s.on_sample(61.6, 102'125'000);
  EXPECT_EQ(s.value_C(), 61.6);
  EXPECT_EQ(s.age_s(102'125'000), 0.0);
}

TEST(SensorReading, ASampleBeforeTheReadingIsANewTimeBaseAndDropsIt) {
  SensorReading s;
  s.on_sample(70.0, 5'000'000'000);
  s.on_sample(kNoReading, 1'000'000);  // the drive restarted: its clock begins again
  EXPECT_TRUE(std::isnan(s.value_C()));
  EXPECT_TRUE(std::isnan(s.age_s(1'000'000)));
  s.on_sample(71.0, 2'000'000);
  EXPECT_EQ(s.value_C(), 71.0);
}

}  // namespace
}  // namespace rpem::daemon
