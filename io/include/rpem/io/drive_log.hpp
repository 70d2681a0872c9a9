#pragma once
// The drive-log CSV: the project's measured-data format (docs/drive-log.md).
// One header row; SI units; required columns t, theta_el, omega_el, u_dc, a voltage command
// (u_a,u_b,u_c and/or u_d,u_q) and a measured current (i_a,i_b,i_c and/or i_d,i_q); optional
// T_winding, T_magnet, T_coolant [°C], torque_cmd [Nm]. Extra columns are ignored. A log whose voltage and current
// are both in the rotor frame only may omit theta_el and u_dc. A log must hold at least one row, and every
// cell must lie within the plausibility limits below.

#include <cstdint>
#include <fstream>
#include <istream>
#include <optional>
#include <string>
#include <vector>

#include "rpem/core/drive_sample.hpp"
#include "rpem/io/errors.hpp"

namespace rpem::io {

struct DriveLogRow {
  core::DriveSample sample;
  std::optional<double> t_winding_C;
  std::optional<double> t_magnet_C;
  std::optional<double> t_coolant_C;
  std::optional<double> torque_cmd_Nm;
};

/// Which column groups a log holds (the reader prefers abc where both are present).
struct DriveLogLayout {
  bool angle = true;  ///< theta_el present (a rotor-frame-only log may omit it: 0 is used)
  bool u_dc = true;   ///< u_dc present (a rotor-frame-only log may omit it: 0, i.e. unknown)
  bool voltage_abc = true;
  bool voltage_dq = false;
  bool current_abc = true;
  bool current_dq = false;
  bool t_winding = false;
  bool t_magnet = false;
  bool t_coolant = false;
  bool torque_cmd = false;
};

/// A magnitude no drive produces, and where the figure comes from (quoted in the error message).
struct Bound {
  double max_abs = 0.0;
  std::string why;
};

/// What a drive-log cell may hold (docs/drive-log.md, "Plausibility limits"). The defaults are absolute:
/// no drive, whatever its machine, produces a value beyond them. A tool that knows the machine narrows
/// them to a multiple of its name plate (io::machine_limits). A cell beyond its bound, like a NaN, stops
/// the reader with file:line:column.
struct DriveLogLimits {
  Bound time_s{9.0e9, "t is kept in integer nanoseconds, which 64 bits hold up to 9.2e9 s"};
  Bound angle_rad{1.0e9, "beyond 1e9 rad a double resolves the angle no finer than 1.2e-7 rad"};
  Bound speed_rad_s{1.0e6, "10x the fastest electric machines (1e5 rad/s electrical)"};
  Bound voltage_V{1.0e5, "beyond the highest drive DC links (tens of kV)"};
  Bound current_A{1.0e5, "beyond the largest drives' phase currents (tens of kA)"};
  Bound torque_Nm{1.0e7, "beyond the largest machines' torque (MN m)"};
  double temperature_min_C = -273.15;  ///< absolute zero
  double temperature_max_C = 1000.0;   ///< every winding insulation and magnet has failed long before
  /// A voltage command may be at most this multiple of the same row's u_dc (when u_dc ≥ 1 V): a two-level
  /// inverter applies at most u_dc/2 from the link's midpoint, and 2·u_dc/π as a six-step fundamental.
  double command_per_dc_link = 2.0;
};

/// Streams a drive log row by row. Every problem throws DriveLogError naming file, line and column;
/// a log without a single row is refused ("no samples") when its end is reached.
class DriveLogReader {
 public:
  explicit DriveLogReader(const std::string& path, DriveLogLimits limits = {});
  /// Reads from `in`, which must outlive the reader; `name` stands for the file in messages.
  DriveLogReader(std::istream& in, std::string name, DriveLogLimits limits = {});

  /// Reads the next row; false at end of file (after at least one row: an empty log throws).
  bool next(DriveLogRow& row);

  [[nodiscard]] const DriveLogLayout& layout() const noexcept { return layout_; }
  [[nodiscard]] std::size_t line() const noexcept { return line_; }
  [[nodiscard]] std::uint64_t bytes_total() const noexcept { return bytes_total_; }
  [[nodiscard]] std::uint64_t bytes_read() const noexcept { return bytes_read_; }

 private:
  struct Column {
    int index = -1;
    [[nodiscard]] bool present() const noexcept { return index >= 0; }
  };
  void read_header();
  [[nodiscard]] double cell(const Column& c, const char* name) const;
  [[nodiscard]] double cell(const Column& c, const char* name, const Bound& bound, const char* unit) const;
  [[nodiscard]] double temperature(const Column& c, const char* name) const;
  [[nodiscard]] double command(const Column& c, const char* name, double u_dc_V) const;
  [[noreturn]] void fail(const std::string& column, const std::string& reason) const;
  [[noreturn]] void fail(const Column& c, const char* name, const std::string& reason) const;

  std::string path_;
  std::ifstream file_;
  std::istream& in_;
  DriveLogLimits limits_;
  std::size_t line_ = 0;
  std::uint64_t rows_ = 0;
  std::uint64_t bytes_total_ = 0;
  std::uint64_t bytes_read_ = 0;
  DriveLogLayout layout_;
  std::vector<std::string> header_;
  std::vector<std::string> cells_;
  Column t_, theta_, omega_, udc_, ua_, ub_, uc_, ud_, uq_, ia_, ib_, ic_, id_, iq_, tw_, tm_, tc_, tq_;
  std::optional<std::int64_t> previous_t_ns_;
};

/// Reads a whole log.
[[nodiscard]] std::vector<DriveLogRow> read_drive_log(const std::string& path, const DriveLogLimits& limits = {});

/// Writes a drive log. Numbers are written in the shortest form that reads back bit-exactly.
class DriveLogWriter {
 public:
  DriveLogWriter(const std::string& path, const DriveLogLayout& layout);
  /// Writes one row; the sample's frames must provide what the layout promises
  /// (abc columns from abc samples; dq columns are derived with the Park transform as needed).
  void write(const DriveLogRow& row);
  void flush();

 private:
  std::ofstream out_;
  DriveLogLayout layout_;
  std::string line_;
};

}  // namespace rpem::io
