#pragma once
// The drive-log CSV: the project's measured-data format (docs/drive-log.md).
// One header row; SI units; required columns t, theta_el, omega_el, u_dc, a voltage command
// (u_a,u_b,u_c and/or u_d,u_q) and a measured current (i_a,i_b,i_c and/or i_d,i_q); optional
// T_winding, T_magnet [°C], torque_cmd [Nm]. Extra columns are ignored. A log whose voltage and current
// are both in the rotor frame only may omit theta_el and u_dc.

#include <cstdint>
#include <fstream>
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
  bool torque_cmd = false;
};

/// Streams a drive log row by row. Every problem throws DriveLogError naming file, line and column.
class DriveLogReader {
 public:
  explicit DriveLogReader(const std::string& path);

  /// Reads the next row; false at end of file.
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
  [[nodiscard]] double cell(const Column& c, const char* name) const;
  [[noreturn]] void fail(const std::string& column, const std::string& reason) const;

  std::string path_;
  std::ifstream in_;
  std::size_t line_ = 0;
  std::uint64_t bytes_total_ = 0;
  std::uint64_t bytes_read_ = 0;
  DriveLogLayout layout_;
  std::vector<std::string> header_;
  std::vector<std::string> cells_;
  Column t_, theta_, omega_, udc_, ua_, ub_, uc_, ud_, uq_, ia_, ib_, ic_, id_, iq_, tw_, tm_, tq_;
  std::optional<double> previous_t_s_;
};

/// Reads a whole log.
[[nodiscard]] std::vector<DriveLogRow> read_drive_log(const std::string& path);

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
