#pragma once
// The drive-log CSV: the project's measured-data format (docs/drive-log.md); any CSV of instantaneous
// samples through a column map reads into the same rows.
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
#include "rpem/io/log_limits.hpp"
#include "rpem/io/log_map.hpp"
#include "rpem/io/mapped_log.hpp"

namespace rpem::io {

/// A row: the sample (with the winding and coolant sensors' readings, NaN for none) and what only a log carries.
struct DriveLogRow {
  core::DriveSample sample;
  std::optional<double> t_magnet_C;  ///< a magnet sensor (a test bench's; validation only, never an input)
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

/// Streams a drive log row by row: our drive-log CSV, or any CSV through a map of instantaneous samples
/// (log_map.hpp; read by MappedLogReader, which checks every cell). Every problem throws DriveLogError
/// naming file, line and column; a log without a single row is refused ("no samples") when its end is reached.
class DriveLogReader {
 public:
  explicit DriveLogReader(const std::string& path, DriveLogLimits limits = {});
  /// Reads from `in`, which must outlive the reader; `name` stands for the file in messages.
  DriveLogReader(std::istream& in, std::string name, DriveLogLimits limits = {});
  /// Reads `path` as `map` describes it (a map of instantaneous samples).
  DriveLogReader(const std::string& path, LogMap map, DriveLogLimits limits);

  /// Reads the next row; false at end of file (after at least one row: an empty log throws).
  bool next(DriveLogRow& row);

  [[nodiscard]] const DriveLogLayout& layout() const noexcept { return layout_; }
  [[nodiscard]] std::size_t line() const noexcept { return reader_.line(); }
  [[nodiscard]] std::uint64_t bytes_total() const noexcept { return reader_.bytes_total(); }
  [[nodiscard]] std::uint64_t bytes_read() const noexcept { return reader_.bytes_read(); }
  [[nodiscard]] const MappedLogReader& reader() const noexcept { return reader_; }

 private:
  void check_layout();

  MappedLogReader reader_;
  DriveLogLayout layout_;
  MappedRow row_;
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
