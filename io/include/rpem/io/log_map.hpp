#pragma once
// A log map (docs/drive-log.md, "Column maps"): how the columns of a CSV that is not in our own format
// become the quantities of a drive log or an averaged log — which column holds which quantity, in which
// unit, scaled and offset how; the separator, the header, skipped and comment lines; where time comes from
// (a column in a unit, wrapping at a period, stamped at a resolution; or evenly spaced rows); whether the
// rows are instantaneous samples or means over windows. Our own drive-log and averaged-log formats are
// identity maps (drive_log_map(), averaged_log_map()), VESC Tool's realtime log is a map compiled in from
// config/log-maps/vesc-tool.yaml (vesc_tool_log.hpp): every CSV is read by one reader (mapped_log.hpp).

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rpem/core/reported_speed.hpp"
#include "rpem/io/yaml_map.hpp"

namespace rpem::io {

/// What a column can hold, as our drive-log and averaged-log columns name it.
enum class Quantity : std::uint8_t {
  kThetaEl,
  kOmegaEl,
  kUDc,
  kUA,
  kUB,
  kUC,
  kUD,
  kUQ,
  kIA,
  kIB,
  kIC,
  kID,
  kIQ,
  kTWinding,
  kTMagnet,
  kTDrive,
  kTorqueCmd,
  kTStart,
  kTCoolant,  ///< the machine's coolant (issue 24: the thermal network's boundary)
  kTravelEl,  ///< the electrical angle the drive has counted (VESC's tachometer, 60° steps): averaged logs only
  /// The duty cycle as VESC reports it, |u_dq|·√3/u_dc signed by u_q (rotor_frame_rebuild.hpp): averaged logs only
  kDuty,
  /// The motor current as VESC reports it, |i_dq| signed by u_q·i_q: averaged logs only
  kIMotor,
  kCount
};
inline constexpr std::size_t kQuantityCount = static_cast<std::size_t>(Quantity::kCount);

/// The physical kind of a quantity: its SI unit, the units a map may give it in, and its plausibility bound.
enum class QuantityKind : std::uint8_t { kTime, kAngle, kSpeed, kVoltage, kCurrent, kTemperature, kTorque, kRatio };

struct QuantityInfo {
  Quantity quantity;
  const char* name;  ///< our column name (docs/drive-log.md)
  QuantityKind kind;
  bool voltage_command;  ///< held to 2·u_dc of its row (a two-level inverter's reach)
};

/// The catalogue of quantities, in enum order.
[[nodiscard]] const std::array<QuantityInfo, kQuantityCount>& quantities() noexcept;
[[nodiscard]] const QuantityInfo& info(Quantity q) noexcept;
[[nodiscard]] std::optional<Quantity> quantity_named(std::string_view name) noexcept;

/// Where a mapped value is found: a header name, or (headerless files) a 1-based position.
struct ColumnRef {
  std::string name;                         ///< header name; empty for a position
  std::size_t position = 0;                 ///< 1-based position when the file has no header
  [[nodiscard]] std::string label() const;  ///< the name, or the position as text
};

/// One mapped column: SI value = factor · (cell · scale + offset), with factor the unit's (unit_factor()).
struct MappedColumn {
  Quantity quantity = Quantity::kOmegaEl;
  ColumnRef column;
  double scale = 1.0;
  double offset = 0.0;
  double unit_factor = 1.0;  ///< the map's unit in SI (1 mA = 1e-3 A; 1 rpm with p pole pairs = 2πp/60 rad/s)
  double unit_offset = 0.0;  ///< added after the factor (kelvin → °C: −273.15)
  std::string unit = "SI";   ///< as the map wrote it, for messages
  /// Read where the header has it, the quantity absent where not (`optional: true`; a header map's temperatures
  /// and travel_el only: quantities every log may lack).
  bool optional = false;
  /// The value, in the column's own unit, its logger writes where the sensor gives no reading (`no_reading:`; a
  /// temperature's only: VESC's −100 °C for a motor without a sensor). Such a cell is no reading on its row, and a
  /// column that holds nothing else is absent (ReadRepairs::no_reading).
  std::optional<double> no_reading{};
};

/// Whether a cell's value (the column's own unit, before scale and offset) is the column's no-reading value: equal to
/// within half the last digit of six significant ones, the precision QTextStream and printf's %g write by default.
[[nodiscard]] bool is_no_reading(const MappedColumn& c, double cell) noexcept;

/// How a sample's window is known (averaged logs).
enum class Window : std::uint8_t {
  kInstantaneous,  ///< each row is a sample at its time (drive-log rows; t_start = t)
  kStartColumn,    ///< averaged over [t_start, t], t_start from its own column (our averaged log)
  kPreviousRow,  ///< averaged since the previous row's time (VESC's read-and-reset means); the first row only opens a window
};

struct LogMap {
  std::string name;  ///< where the map comes from (a file, or a built-in format's name), for messages
  char separator = ',';
  bool header = true;          ///< the first line read names the columns
  std::size_t skip_lines = 0;  ///< lines before the header (or the first row) that are not read
  char comment = '\0';         ///< lines starting with it (after blanks) are skipped; '\0': none
  Window window = Window::kInstantaneous;
  /// Every mapped column may be absent from the header (the quantity is then absent): our own formats,
  /// where the header names the quantities. A user's map requires each of its columns.
  bool columns_optional = false;
  /// A cell "nan" in a temperature sensor's column is no reading on its row (our own drive and averaged logs:
  /// their writers put it where a sensor gave none, e.g. a slow sensor's frame between its readings).
  bool nan_temperature_is_no_reading = false;
  /// A cell "nan" in u_dc means "not reported" (our averaged log: a window without a DC-link reading).
  bool nan_u_dc_is_missing = false;

  // Time: a column (time.has_value()), or rows evenly spaced by period_s from 0.
  std::optional<MappedColumn> time;  ///< quantity ignored; SI value in s
  double period_s = 0.0;
  double wrap_s = 0.0;        ///< the time column wraps to 0 at this period (ms_today: a day); 0: never
  double resolution_s = 0.0;  ///< equal stamps are spread over one resolution step; 0: equal stamps are an error

  std::vector<MappedColumn> columns;

  /// The column naming the recording each row belongs to (`session: {column: …}`; the Paderborn bench's
  /// profile_id): a file whose rows come from two recordings is refused where the second begins, since each starts
  /// from its own state and the time between them is not in the file. Read where the header has it.
  std::optional<ColumnRef> session;

  /// The speed column is a type-2 PLL's speed at the read (omega_el's `pll: {kp, ki}`; VESC's erpm, lagging a
  /// ramp by k_p/k_i = 66.7 ms by default): the reader rebuilds each window's mean speed from it and the previous
  /// row's (core::window_mean_speed_rad_s) and states the rebuild's error bound
  /// (core::window_mean_speed_error_rad_s). Not given: the column is the window's mean speed.
  /// window: previous_row only.
  core::PllGains speed_pll;
  /// How long the logger waits for a reply before it asks again (VESC Tool: 0.99 s). A request it gave up on
  /// may still have been read, and a read resets the means, so a row this long after the one before has an
  /// unknown window and is stamped perhaps long after its read (where it is also 1.5 median spacings: a logger
  /// polling slower than this spaces its rows by its poll period). 0: the logger never asks again.
  /// window: previous_row only.
  double request_timeout_s = 0.0;

  [[nodiscard]] bool averaged() const noexcept { return window != Window::kInstantaneous; }
  [[nodiscard]] const MappedColumn* find(Quantity q) const noexcept;
};

/// Our drive log (docs/drive-log.md) as a map: every column named as its quantity, SI, comma-separated.
[[nodiscard]] LogMap drive_log_map(const std::string& name = "drive log");
/// Our averaged log: the same with t_start, windows from their t_start column, "nan" = not reported.
[[nodiscard]] LogMap averaged_log_map(const std::string& name = "averaged log");

/// Reads a map from YAML (schema: docs/drive-log.md, "Column maps"). Unknown keys, units that are not the
/// quantity's, a map that does not give what its kind of log needs: ConfigError with file:line:column.
[[nodiscard]] LogMap load_log_map(const std::string& path);
[[nodiscard]] LogMap parse_log_map(const std::string& text, const std::string& name);

/// Which quantities a set of columns provides.
using QuantitySet = std::array<bool, kQuantityCount>;

/// The layout rules of each kind of log, shared by a map (checked when it is loaded) and by our own formats
/// (checked against the header): returns the first quantity missing or in excess and why, or nothing.
struct LayoutProblem {
  std::string column;  ///< a quantity name, or a group such as "u_a,u_b,u_c|u_d,u_q"
  std::string reason;
  std::vector<Quantity> instead = {};  ///< the quantities that would stand for the missing one (named as the file does)
};
/// " (or duty and u_dc)": what would stand for the missing quantity, each named by `name` (a map's quantity name, a
/// file's column); empty where nothing would.
[[nodiscard]] std::string instead_text(const LayoutProblem& problem, const std::function<std::string(Quantity)>& name);
[[nodiscard]] std::optional<LayoutProblem> drive_log_layout_problem(const QuantitySet& present);
[[nodiscard]] std::optional<LayoutProblem> averaged_log_layout_problem(const QuantitySet& present);

}  // namespace rpem::io
