#pragma once
// The averaged drive log (docs/drive-log.md, "Averaged logs"): one row per window of averaged rotor-frame
// values, as VESC polling, a signal map or the native telemetry averaged by `rpem record` deliver them, and
// as the independent generator writes them (`indep_drive_log --averaged`).
//
//   t, t_start, i_d, i_q, u_d, u_q, omega_el   required: window [t_start, t] [s], means [A, V, rad/s]
//   u_dc, T_winding, T_magnet, T_drive, T_coolant   optional [V, °C]; a cell "nan" means not reported
//
// A header with a t_start column marks the file as an averaged log. Any CSV of window means reads into the
// same samples through a column map (log_map.hpp): VESC Tool's realtime log is one (vesc_tool_log.hpp).

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "rpem/core/averaged_sample.hpp"
#include "rpem/io/drive_log.hpp"
#include "rpem/io/log_map.hpp"
#include "rpem/io/machine_config.hpp"
#include "rpem/io/mapped_log.hpp"

namespace rpem::io {

/// The optional columns a log holds.
struct AveragedLogLayout {
  bool u_dc = false;
  bool t_winding = false;
  bool t_magnet = false;
  bool t_drive = false;
  bool t_coolant = false;
  bool u_dq = false;     ///< u_d, u_q columns (else rebuilt from duty and u_dc: rotor_frame_rebuild.hpp)
  bool i_dq = false;     ///< i_d, i_q columns (else rebuilt from i_motor)
  bool duty = false;     ///< VESC's duty cycle
  bool i_motor = false;  ///< VESC's motor current
};

/// What reading an averaged log through a map did besides delivering samples.
struct AveragedLogRead {
  AveragedLogLayout layout;
  std::uint64_t rows = 0;  ///< data rows read
  /// Rows that only open the first window (window: previous_row: the first row, whose own window began at
  /// a read before the log started; it is read and checked, but is no sample).
  std::uint64_t opening_rows = 0;
  /// Windows after a read whose time is unknown (window: previous_row; docs/drive-log.md, "Rows stamped late"):
  /// read and checked, but no samples.
  std::uint64_t unknown_windows = 0;
  ReadRepairs repairs;
  /// Each sample's duty cycle at its read, and at the read that starts its window with the DC link there (NaN:
  /// not known, a window from its own t_start), and its motor current, in the samples' order (empty: the log has
  /// none): what rotor_frame_rebuild.hpp completes a log without d/q values from.
  std::vector<double> duty;
  std::vector<double> duty_at_start;
  std::vector<double> u_dc_at_start_V;
  std::vector<double> i_motor_A;
};

/// Reads a whole log of averaged samples as `map` describes it (our averaged log: averaged_log_map();
/// VESC Tool's realtime log: vesc_tool_log_map(); a user's map), each cell held to `limits`. With
/// window: previous_row each row's window starts at the previous row's t, and the first row is no sample.
[[nodiscard]] std::vector<core::AveragedSample> read_averaged_log(const std::string& path, const LogMap& map,
                                                                  const DriveLogLimits& limits,
                                                                  AveragedLogRead* read = nullptr);

class AveragedLogWriter {
 public:
  AveragedLogWriter(const std::string& path, const AveragedLogLayout& layout);
  void write(const core::AveragedSample& s);
  void flush();

 private:
  std::ofstream out_;
  AveragedLogLayout layout_;
  std::string line_;
};

/// An averaged sample as a rotor-frame-only drive-log row (dq voltage and current, angle 0): the form the
/// steady-state model of `rpem diagnose` replays. The window's end time stands for the sample.
[[nodiscard]] DriveLogRow to_drive_log_row(const core::AveragedSample& s);
/// The drive-log layout of such rows.
[[nodiscard]] DriveLogLayout rotor_frame_layout(const AveragedLogLayout& layout);

/// Throws DriveLogError where a log of averaged windows carries no voltages: u_d and u_q exactly 0 in every sample
/// while the machine turned or carried current — zeros a logger wrote for values it does not read (docs/drive-log.md,
/// "Errors"), a bridge off throughout whose logger writes zeros then, or voltages below the column's resolution
/// throughout: in each case nothing in the log can be estimated or diagnosed. The error names the back EMF the
/// speeds imply at the configured ψm and the largest current — at rest throughout, the drop that current implies
/// across the configured R_s — so that the reader can judge. A machine at rest unexcited throughout is no error
/// (nothing was there to record; the tools say that nothing adapted).
void check_voltages_recorded(const std::vector<core::AveragedSample>& samples, const core::MachineSi& machine,
                             const std::string& log_path);

/// Throws ConfigError when the configuration needs what averaged samples cannot carry: per-phase current
/// offsets and gains (no rotor-frame mean), or a dead time in seconds without the log's u_dc.
void check_averaged_supports(const MachineConfig& c, const std::string& config_name, bool has_u_dc,
                             const std::string& log_path);

}  // namespace rpem::io
