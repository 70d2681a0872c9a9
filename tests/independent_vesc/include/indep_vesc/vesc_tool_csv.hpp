#pragma once
// The realtime-data CSV exactly as VESC Tool writes it (vedderb/vesc_tool vescinterface.cpp: openRtLogFile writes
// the header, the valuesReceived handler one row per COMM_GET_VALUES reply; README "The CSV"). Versions:
//   0  2323a806 (2019-05-06)  no header, 22 values, local time
//   1  95f18604 (2019-09-03)  header of 22 columns, local time
//   2  5986063b (2019-09-17)  32 columns: + d/q-axis voltage and 8 GNSS columns, UTC
//   3  408f78fc (2019-09-27) … 426a4f8e (2026-07-29, newest)  55 columns: + setup and IMU columns, UTC
// Every value is followed by ';' (so is the header's last name), the line by '\n'. Numbers are QTextStream's:
// doubles in its default SmartNotation with precision 6 (printf's %g in the C locale), integers in decimal; in
// versions 2 and 3 the stream is switched to fixed notation with 8 decimals at the latitude and stays so to the
// row's end.
#include <cstdint>
#include <string>

#include "indep_vesc/values.hpp"

namespace indep::vesc {

inline constexpr int kNewestHeaderVersion = 3;

/// The header line without its line end ("" for version 0); throws std::invalid_argument for another version.
std::string header_line(int version);
/// The number of values in a row.
int column_count(int version);
/// Whether the version's ms_today is UTC (else the host's local time).
bool clock_is_utc(int version);

/// QTextStream << double with default settings.
std::string qt_number(double v);
/// QTextStream << double after Qt::fixed and qSetRealNumberPrecision(8).
std::string qt_fixed8(double v);

/// ms_today: milliseconds since the logger clock's midnight, truncated (QTime::msecsSinceStartOfDay), wrapping.
std::int64_t ms_today(double start_ms_today, double t_s);

struct RowContext {
  std::int64_t ms_today = 0;
  McValues values;
  std::int64_t ms_setup = -1;  // when the last COMM_GET_VALUES_SETUP reply came; −1 before the first
  SetupValues setup;
};

/// One row without its line end.
std::string row_line(int version, const RowContext& r);

}  // namespace indep::vesc
