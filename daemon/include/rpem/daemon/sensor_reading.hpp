#pragma once
// A drive's temperature sensor as RPEM_MEASUREMENT reports it: its newest reading and how long before the newest
// sample that reading was taken. A sensor reads far more slowly than the samples come (the native protocol's
// temperature frame every 100 ms beside phase samples at 8 kHz, a signal map's coolant frame at 4 Hz): the sample a
// measurement is decimated from rarely carries one, and "NaN: no reading in this sample" would show a working sensor
// as absent. The age says whether it still reads (docs/rpemd.md, "The drive's own temperatures"). Real-time safe.

#include <cmath>
#include <cstdint>
#include <limits>

namespace rpem::daemon {

class SensorReading {
 public:
  /// The sample at `t_ns` (its time base: drive or window time) carries `reading_C` (NaN: none). A sample earlier
  /// than the reading's is a new time base (a drive restarted): the reading's age is unknown, and it is dropped.
  void on_sample(double reading_C, std::int64_t t_ns) noexcept {
    if (has_ && t_ns < at_ns_) has_ = false;
    if (std::isnan(reading_C)) return;
    value_C_ = reading_C;
    at_ns_ = t_ns;
    has_ = true;
  }
  /// The newest reading; NaN where none came since the start (or since the time base changed).
  [[nodiscard]] double value_C() const noexcept { return has_ ? value_C_ : std::numeric_limits<double>::quiet_NaN(); }
  /// Seconds from the reading's sample to the sample at `t_ns`; NaN without a reading.
  [[nodiscard]] double age_s(std::int64_t t_ns) const noexcept {
    return has_ ? 1e-9 * static_cast<double>(t_ns - at_ns_) : std::numeric_limits<double>::quiet_NaN();
  }

 private:
  double value_C_ = 0.0;
  std::int64_t at_ns_ = 0;
  bool has_ = false;
};

}  // namespace rpem::daemon
