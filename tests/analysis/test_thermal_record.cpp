// What a log's coolant column gives the thermal fit (analysis/thermal/thermal_record.hpp): the coolant is measured
// where the column has a reading, not merely where the header names it — `rpem record --out` writes T_coolant for
// every drive on the native protocol, `nan` on every row of one without the sensor (docs/drive-log.md).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>

#include "rpem/analysis/thermal/thermal_record.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/log_source.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/thermal_config.hpp"
#include "support/paper_thermal.hpp"
#include "support/temp_file.hpp"

namespace rpem::analysis {
namespace {

/// A quarter second of standstill at 8 kHz; the coolant read on the row `reading_row` only (none: no reading).
bool coolant_of(bool column, std::optional<int> reading_row) {
  test::TempFile f("log.csv");
  io::DriveLogLayout layout;
  layout.t_coolant = column;
  {
    io::DriveLogWriter w(f.path(), layout);
    for (int k = 0; k < 2000; ++k) {
      io::DriveLogRow row;
      row.sample.t_ns = 125'000LL * k;
      row.sample.u_dc_V = 300.0;
      row.sample.t_coolant_C = reading_row == k ? 40.0 : std::numeric_limits<double>::quiet_NaN();
      w.write(row);
    }
  }
  io::ThermalConfig thermal;
  thermal.fusion = test::paper_thermal_fusion();
  return record_thermal(io::log_source(f.path()), io::builtin_paper_config(), thermal).coolant;
}

TEST(ThermalRecord, ACoolantColumnWithoutAReadingIsNoCoolant) {
  EXPECT_FALSE(coolant_of(false, std::nullopt));
  EXPECT_FALSE(coolant_of(true, std::nullopt));  // the header names it, no row reads it
  EXPECT_TRUE(coolant_of(true, 1000));           // one reading is a measured coolant from there on
}

}  // namespace
}  // namespace rpem::analysis
