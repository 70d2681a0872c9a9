#include "rpem/io/log_map.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <string>
#include <string_view>
#include <utility>

#include "rpem/core/reported_speed.hpp"

namespace rpem::io {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kDeg = std::numbers::pi / 180.0;

/// A unit a map may name, for one kind of quantity: SI = factor · value + offset; `per_pole_pair` units are
/// mechanical (the factor is multiplied by the map's pole_pairs).
struct Unit {
  QuantityKind kind;
  const char* name;
  double factor;
  double offset;
  bool per_pole_pair;
};

// The units a map may use (docs/drive-log.md, "Column maps"); the first of each kind is its SI unit.
constexpr std::array kUnits{
    Unit{QuantityKind::kTime, "s", 1.0, 0.0, false},
    Unit{QuantityKind::kTime, "ms", 1e-3, 0.0, false},
    Unit{QuantityKind::kTime, "us", 1e-6, 0.0, false},
    Unit{QuantityKind::kTime, "ns", 1e-9, 0.0, false},
    Unit{QuantityKind::kTime, "min", 60.0, 0.0, false},
    Unit{QuantityKind::kTime, "h", 3600.0, 0.0, false},
    Unit{QuantityKind::kAngle, "rad", 1.0, 0.0, false},
    Unit{QuantityKind::kAngle, "deg", kDeg, 0.0, false},
    Unit{QuantityKind::kAngle, "rad_mech", 1.0, 0.0, true},
    Unit{QuantityKind::kAngle, "deg_mech", kDeg, 0.0, true},
    Unit{QuantityKind::kAngle, "step60", kTwoPi / 6.0, 0.0, false},  // a six-state count (VESC's tachometer)
    Unit{QuantityKind::kSpeed, "rad/s", 1.0, 0.0, false},
    Unit{QuantityKind::kSpeed, "Hz", kTwoPi, 0.0, false},
    Unit{QuantityKind::kSpeed, "erpm", kTwoPi / 60.0, 0.0, false},
    Unit{QuantityKind::kSpeed, "rad/s_mech", 1.0, 0.0, true},
    Unit{QuantityKind::kSpeed, "Hz_mech", kTwoPi, 0.0, true},
    Unit{QuantityKind::kSpeed, "rpm", kTwoPi / 60.0, 0.0, true},
    Unit{QuantityKind::kVoltage, "V", 1.0, 0.0, false},
    Unit{QuantityKind::kVoltage, "mV", 1e-3, 0.0, false},
    Unit{QuantityKind::kVoltage, "kV", 1e3, 0.0, false},
    Unit{QuantityKind::kCurrent, "A", 1.0, 0.0, false},
    Unit{QuantityKind::kCurrent, "mA", 1e-3, 0.0, false},
    Unit{QuantityKind::kCurrent, "kA", 1e3, 0.0, false},
    Unit{QuantityKind::kTemperature, "degC", 1.0, 0.0, false},
    Unit{QuantityKind::kTemperature, "K", 1.0, -273.15, false},
    Unit{QuantityKind::kTorque, "Nm", 1.0, 0.0, false},
    Unit{QuantityKind::kTorque, "mNm", 1e-3, 0.0, false},
    Unit{QuantityKind::kRatio, "1", 1.0, 0.0, false},
    Unit{QuantityKind::kRatio, "%", 1e-2, 0.0, false},
};

constexpr std::array<QuantityInfo, kQuantityCount> kQuantities{{
    {Quantity::kThetaEl, "theta_el", QuantityKind::kAngle, false},
    {Quantity::kOmegaEl, "omega_el", QuantityKind::kSpeed, false},
    {Quantity::kUDc, "u_dc", QuantityKind::kVoltage, false},
    {Quantity::kUA, "u_a", QuantityKind::kVoltage, true},
    {Quantity::kUB, "u_b", QuantityKind::kVoltage, true},
    {Quantity::kUC, "u_c", QuantityKind::kVoltage, true},
    {Quantity::kUD, "u_d", QuantityKind::kVoltage, true},
    {Quantity::kUQ, "u_q", QuantityKind::kVoltage, true},
    {Quantity::kIA, "i_a", QuantityKind::kCurrent, false},
    {Quantity::kIB, "i_b", QuantityKind::kCurrent, false},
    {Quantity::kIC, "i_c", QuantityKind::kCurrent, false},
    {Quantity::kID, "i_d", QuantityKind::kCurrent, false},
    {Quantity::kIQ, "i_q", QuantityKind::kCurrent, false},
    {Quantity::kTWinding, "T_winding", QuantityKind::kTemperature, false},
    {Quantity::kTMagnet, "T_magnet", QuantityKind::kTemperature, false},
    {Quantity::kTDrive, "T_drive", QuantityKind::kTemperature, false},
    {Quantity::kTorqueCmd, "torque_cmd", QuantityKind::kTorque, false},
    {Quantity::kTStart, "t_start", QuantityKind::kTime, false},
    {Quantity::kTCoolant, "T_coolant", QuantityKind::kTemperature, false},
    {Quantity::kTravelEl, "travel_el", QuantityKind::kAngle, false},
    {Quantity::kDuty, "duty", QuantityKind::kRatio, false},
    {Quantity::kIMotor, "i_motor", QuantityKind::kCurrent, false},
}};

const char* si_unit(QuantityKind k) {
  for (const Unit& u : kUnits) {
    if (u.kind == k) return u.name;
  }
  return "";
}

std::string unit_names(QuantityKind k) {
  std::string s;
  for (const Unit& u : kUnits) {
    if (u.kind == k) s += (s.empty() ? "" : ", ") + std::string(u.name);
  }
  return s;
}

MappedColumn identity(Quantity q) {
  MappedColumn c;
  c.quantity = q;
  c.column.name = info(q).name;
  c.unit = si_unit(info(q).kind);
  return c;
}

/// Applies `unit` (of kind `kind`) to `c`; the map's pole pairs for mechanical units (0: not given). True if
/// the unit is mechanical.
bool apply_unit(YamlMap& m, MappedColumn& c, QuantityKind kind, long pole_pairs) {
  c.unit = m.text_or("unit", si_unit(kind));
  const auto it =
      std::find_if(kUnits.begin(), kUnits.end(), [&](const Unit& u) { return u.kind == kind && c.unit == u.name; });
  if (it == kUnits.end())
    m.fail("unit", "'" + c.unit + "' is not a unit of this quantity (one of " + unit_names(kind) + ")");
  if (it->per_pole_pair && pole_pairs <= 0) {
    m.fail("unit", "'" + c.unit + "' is mechanical: the map needs pole_pairs to make it electrical");
  }
  c.unit_factor = it->factor * (it->per_pole_pair ? static_cast<double>(pole_pairs) : 1.0);
  c.unit_offset = it->offset;
  return it->per_pole_pair;
}

/// One `column: NAME` (header) or `column: N` (headerless) entry, with unit, scale and offset.
MappedColumn parse_column(YamlMap& m, Quantity q, QuantityKind kind, bool header, bool averaged, long pole_pairs,
                          bool& mechanical) {
  MappedColumn c;
  c.quantity = q;
  if (header) {
    c.column.name = m.text("column");
    if (c.column.name.empty()) m.fail("column", "an empty column name");
  } else {
    c.column.position = static_cast<std::size_t>(m.integer("column", 1, 100000));
  }
  mechanical = apply_unit(m, c, kind, pole_pairs) || mechanical;
  c.scale = m.number_or("scale", 1.0, -1e12, 1e12);
  if (c.scale == 0.0) m.fail("scale", "0 would make every value the offset");
  c.offset = m.number_or("offset", 0.0, -1e12, 1e12);
  c.optional = m.boolean_or("optional", false);
  if (c.optional && !header) m.fail("optional", "needs a header: a position is in every row, or the row is short");
  // What a log may lack: temperatures, the count, VESC's duty and motor current; and, in an averaged log, the
  // rotor-frame voltage or current where the other is given (the layout is then checked against the header).
  const bool rotor_frame = q == Quantity::kUD || q == Quantity::kUQ || q == Quantity::kID || q == Quantity::kIQ;
  if (c.optional && kind != QuantityKind::kTemperature && q != Quantity::kTravelEl && q != Quantity::kDuty &&
      q != Quantity::kIMotor && !(rotor_frame && averaged)) {
    m.fail("optional",
           "only a quantity every log may lack (T_winding, T_magnet, T_drive, T_coolant, travel_el, duty, i_motor; "
           "in an averaged log also u_d, u_q, i_d, i_q where duty and u_dc or i_motor stand for them)");
  }
  if (m.has("no_reading")) {
    if (kind != QuantityKind::kTemperature) {
      m.fail("no_reading",
             "only a temperature sensor's column has a value for no reading (T_winding, T_magnet, T_drive, T_coolant)");
    }
    c.no_reading = m.number("no_reading", -1e12, 1e12);
  }
  m.finish();
  return c;
}

char one_character(YamlMap& m, const std::string& key, char fallback) {
  if (!m.has(key)) return fallback;
  const std::string s = m.text(key);
  if (s.size() != 1) m.fail(key, "must be one character (a tab: \"\\t\")");
  return s[0];
}

bool present(const QuantitySet& p, Quantity q) { return p[static_cast<std::size_t>(q)]; }

}  // namespace

const std::array<QuantityInfo, kQuantityCount>& quantities() noexcept { return kQuantities; }

bool is_no_reading(const MappedColumn& c, double cell) noexcept {
  if (!c.no_reading) return false;
  constexpr double kSixDigitsHalfStep = 5e-6;  // half the sixth significant digit, relative
  return std::abs(cell - *c.no_reading) <= kSixDigitsHalfStep * std::max(1.0, std::abs(*c.no_reading));
}

const QuantityInfo& info(Quantity q) noexcept {
  const QuantityInfo& i = kQuantities[static_cast<std::size_t>(q)];
  assert(i.quantity == q);  // the table is in enum order
  return i;
}

std::optional<Quantity> quantity_named(std::string_view name) noexcept {
  for (const QuantityInfo& i : kQuantities) {
    if (name == i.name) return i.quantity;
  }
  return std::nullopt;
}

std::string ColumnRef::label() const { return name.empty() ? std::to_string(position) : name; }

const MappedColumn* LogMap::find(Quantity q) const noexcept {
  for (const MappedColumn& c : columns) {
    if (c.quantity == q) return &c;
  }
  return nullptr;
}

LogMap drive_log_map(const std::string& name) {
  LogMap m;
  m.name = name;
  m.columns_optional = true;
  MappedColumn t;
  t.column.name = "t";
  t.unit = "s";
  m.time = t;
  m.nan_temperature_is_no_reading = true;
  for (const QuantityInfo& q : kQuantities) {
    if (q.quantity != Quantity::kTStart && q.quantity != Quantity::kTDrive) m.columns.push_back(identity(q.quantity));
  }
  return m;
}

LogMap averaged_log_map(const std::string& name) {
  LogMap m;
  m.name = name;
  m.columns_optional = true;
  m.nan_temperature_is_no_reading = true;
  m.nan_u_dc_is_missing = true;
  m.window = Window::kStartColumn;
  MappedColumn t;
  t.column.name = "t";
  t.unit = "s";
  m.time = t;
  for (Quantity q : {Quantity::kTStart, Quantity::kID, Quantity::kIQ, Quantity::kUD, Quantity::kUQ, Quantity::kOmegaEl,
                     Quantity::kUDc, Quantity::kTWinding, Quantity::kTMagnet, Quantity::kTDrive, Quantity::kTCoolant}) {
    m.columns.push_back(identity(q));
  }
  return m;
}

std::optional<LayoutProblem> drive_log_layout_problem(const QuantitySet& p) {
  if (!present(p, Quantity::kOmegaEl)) return LayoutProblem{"omega_el", "required"};
  for (Quantity q : {Quantity::kTStart, Quantity::kTDrive, Quantity::kTravelEl, Quantity::kDuty, Quantity::kIMotor}) {
    if (present(p, q)) return LayoutProblem{info(q).name, "not a quantity of instantaneous samples (averaged logs only)"};
  }
  struct Group {
    std::array<Quantity, 3> members;
    std::size_t size;
    const char* what;
  };
  const std::array<Group, 4> groups{{{{Quantity::kUA, Quantity::kUB, Quantity::kUC}, 3, "phase-voltage"},
                                     {{Quantity::kUD, Quantity::kUQ}, 2, "rotor-frame voltage"},
                                     {{Quantity::kIA, Quantity::kIB, Quantity::kIC}, 3, "phase-current"},
                                     {{Quantity::kID, Quantity::kIQ}, 2, "rotor-frame current"}}};
  std::array<bool, 4> has{};
  for (std::size_t g = 0; g < groups.size(); ++g) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < groups[g].size; ++k) n += present(p, groups[g].members[k]) ? 1 : 0;
    if (n != 0 && n != groups[g].size) {
      for (std::size_t k = 0; k < groups[g].size; ++k) {
        if (!present(p, groups[g].members[k])) {
          return LayoutProblem{info(groups[g].members[k]).name,
                               std::string("incomplete ") + groups[g].what + " column group"};
        }
      }
    }
    has[g] = n != 0;
  }
  if (!has[0] && !has[1]) return LayoutProblem{"u_a,u_b,u_c|u_d,u_q", "no voltage-command columns"};
  if (!has[2] && !has[3]) return LayoutProblem{"i_a,i_b,i_c|i_d,i_q", "no current columns"};
  // A log entirely in the rotor frame needs no angle, and may not know its DC link (docs/drive-log.md).
  const bool rotor_frame_only = !has[0] && !has[2];
  for (Quantity q : {Quantity::kThetaEl, Quantity::kUDc}) {
    if (!present(p, q) && !rotor_frame_only) {
      return LayoutProblem{info(q).name,
                           "required (optional only when voltage and current are both given as u_d,u_q and "
                           "i_d,i_q only)"};
    }
  }
  return std::nullopt;
}

std::string instead_text(const LayoutProblem& problem, const std::function<std::string(Quantity)>& name) {
  std::string names;
  for (const Quantity q : problem.instead) names += (names.empty() ? "" : " and ") + name(q);
  return names.empty() ? std::string() : " (or " + names + ")";
}

std::optional<LayoutProblem> averaged_log_layout_problem(const QuantitySet& p) {
  // The rotor-frame voltage, or the duty cycle and the DC link it is rebuilt from; the rotor-frame current, or
  // the motor current (rotor_frame_rebuild.hpp).
  const bool voltage_from_duty = present(p, Quantity::kDuty) && present(p, Quantity::kUDc);
  const bool current_from_motor = present(p, Quantity::kIMotor);
  for (Quantity q : {Quantity::kID, Quantity::kIQ, Quantity::kUD, Quantity::kUQ, Quantity::kOmegaEl}) {
    const bool rebuilt = ((q == Quantity::kUD || q == Quantity::kUQ) && voltage_from_duty) ||
                         ((q == Quantity::kID || q == Quantity::kIQ) && current_from_motor);
    if (!present(p, q) && !rebuilt) {
      if (q == Quantity::kUD || q == Quantity::kUQ)
        return LayoutProblem{info(q).name, "required", {Quantity::kDuty, Quantity::kUDc}};
      if (q == Quantity::kID || q == Quantity::kIQ) return LayoutProblem{info(q).name, "required", {Quantity::kIMotor}};
      return LayoutProblem{info(q).name, "required"};
    }
  }
  for (const auto& [a, b] : {std::pair{Quantity::kUD, Quantity::kUQ}, std::pair{Quantity::kID, Quantity::kIQ}}) {
    if (present(p, a) != present(p, b)) {
      return LayoutProblem{info(present(p, a) ? b : a).name,
                           "required with " + std::string(info(present(p, a) ? a : b).name)};
    }
  }
  for (Quantity q : {Quantity::kThetaEl, Quantity::kUA, Quantity::kUB, Quantity::kUC, Quantity::kIA, Quantity::kIB,
                     Quantity::kIC, Quantity::kTorqueCmd}) {
    if (present(p, q)) {
      return LayoutProblem{
          info(q).name,
          "not a quantity of averaged samples (their means are rotor-frame: i_d, i_q, "
          "u_d, u_q, omega_el, u_dc, T_winding, T_magnet, T_drive, T_coolant; and travel_el, duty, i_motor)"};
    }
  }
  return std::nullopt;
}

namespace {

/// The time section: evenly spaced rows (period_s) or a time column (column, unit, scale, offset, wrap, resolution).
void parse_time(YamlMap time, LogMap& m) {
  if (time.has("period_s")) {
    m.period_s = time.number("period_s", 1e-9, 1e6);
    for (const char* k : {"column", "unit", "wrap", "resolution"}) {
      if (time.has(k)) time.fail(k, "rows are timed by period_s; a time column is not read as well");
    }
  } else {
    if (!time.has("column")) time.fail("", "give the time column (column, unit) or evenly spaced rows (period_s)");
    MappedColumn t;
    if (m.header) {
      t.column.name = time.text("column");
    } else {
      t.column.position = static_cast<std::size_t>(time.integer("column", 1, 100000));
    }
    (void)apply_unit(time, t, QuantityKind::kTime, 0);
    t.scale = time.number_or("scale", 1.0, 1e-12, 1e12);
    t.offset = time.number_or("offset", 0.0, -1e12, 1e12);
    // wrap and resolution are in the column's own unit (ms_today: 86400000 and 1).
    m.wrap_s = time.number_or("wrap", 0.0, 0.0, 1e18) * t.unit_factor * t.scale;
    m.resolution_s = time.number_or("resolution", 0.0, 0.0, 1e18) * t.unit_factor * t.scale;
    if (m.wrap_s > 0.0 && m.resolution_s >= m.wrap_s) time.fail("resolution", "is not shorter than the wrap period");
    m.time = t;
  }
  time.finish();
}

/// The columns section: one entry per quantity the log holds (a speed may come from a PLL); `mechanical` tells
/// whether any column is in a mechanical unit. Unknown names are left to the caller's finish().
QuantitySet parse_columns(YamlMap& columns, LogMap& m, long pole_pairs, bool& mechanical) {
  QuantitySet present{};
  for (const QuantityInfo& q : kQuantities) {
    std::optional<YamlMap> c = columns.optional_map(q.name);
    if (!c) continue;
    if (std::optional<YamlMap> pll = c->optional_map("pll")) {
      // The speed a type-2 PLL reports at the read (VESC: foc_pll_kp, foc_pll_ki; docs/drive-log.md).
      if (q.quantity != Quantity::kOmegaEl) pll->fail("", "only a speed (omega_el) comes from a PLL");
      if (m.window != Window::kPreviousRow) {
        pll->fail("", "a PLL's speed at the read is rebuilt into window means only with window: previous_row");
      }
      const double kp = pll->number("kp", 1e-3, 1e7);
      const double ki = pll->number("ki", 1e-3, 1e10);
      pll->finish();
      m.speed_pll = {kp, ki};
    }
    MappedColumn column = parse_column(*c, q.quantity, q.kind, m.header, m.averaged(), pole_pairs, mechanical);
    // Two quantities are never one cell (i_d and i_q from one column read each as the other, silently).
    for (const MappedColumn& other : m.columns) {
      if (other.column.name == column.column.name && other.column.position == column.column.position) {
        c->fail("column", "'" + column.column.label() + "' is read as " + info(other.quantity).name +
                              " already: each quantity has a column of its own");
      }
    }
    m.columns.push_back(std::move(column));
    present[static_cast<std::size_t>(q.quantity)] = true;
  }
  return present;
}

LogMap parse(YamlMap root) {
  LogMap m;
  m.name = root.file();
  m.separator = one_character(root, "separator", ',');
  if (m.separator == '"' || m.separator == '\n' || m.separator == '\r') root.fail("separator", "cannot separate cells");
  // A character of a number ("-1.5e+3") would split the numbers themselves.
  if (std::string_view("0123456789.+-eE").find(m.separator) != std::string_view::npos)
    root.fail("separator", std::string("'") + m.separator + "' is part of a number and cannot separate cells");
  m.header = root.boolean_or("header", true);
  m.skip_lines = static_cast<std::size_t>(root.integer_or("skip_lines", 0, 0, 1000000));
  m.comment = one_character(root, "comment", '\0');
  if (m.comment != '\0' && m.comment == m.separator) root.fail("comment", "is the separator");
  const std::string samples = root.choice("samples", {"instantaneous", "averaged"});
  const long pole_pairs = root.integer_or("pole_pairs", 0, 1, 1000);

  parse_time(root.map("time"), m);

  if (samples == "averaged") {
    m.window = root.choice("window", {"previous_row", "t_start"}) == "t_start" ? Window::kStartColumn : Window::kPreviousRow;
  } else if (root.has("window")) {
    root.fail("window", "only averaged samples have windows");
  }
  if (root.has("request_timeout_s") && m.window != Window::kPreviousRow) {
    root.fail("request_timeout_s", "a logger's request timeout matters only with window: previous_row");
  }
  m.request_timeout_s = root.number_or("request_timeout_s", 0.0, 1e-3, 1e6);

  if (std::optional<YamlMap> session = root.optional_map("session")) {
    ColumnRef s;
    if (m.header) {
      s.name = session->text("column");
    } else {
      s.position = static_cast<std::size_t>(session->integer("column", 1, 100000));
    }
    session->finish();
    m.session = s;
  }

  YamlMap columns = root.map("columns");
  bool mechanical = false;
  const QuantitySet present = parse_columns(columns, m, pole_pairs, mechanical);
  columns.finish();  // names no quantity: rejected with its line
  const std::optional<LayoutProblem> problem =
      m.averaged() ? averaged_log_layout_problem(present) : drive_log_layout_problem(present);
  if (problem) {
    const auto quantity_name = [](Quantity q) { return std::string(info(q).name); };
    columns.fail("", problem->column + ": " + problem->reason + instead_text(*problem, quantity_name) + " in " +
                         (m.averaged() ? "an averaged" : "a drive") + " log, which this map gives");
  }
  if ((m.window == Window::kStartColumn) != present[static_cast<std::size_t>(Quantity::kTStart)]) {
    columns.fail("", m.window == Window::kStartColumn ? "window: t_start needs a t_start column"
                                                      : "t_start is read only with window: t_start");
  }
  if (root.has("pole_pairs") && !mechanical) {
    root.fail("pole_pairs", "no column is in a mechanical unit (rpm, rad/s_mech, Hz_mech, rad_mech, deg_mech)");
  }
  root.finish();
  return m;
}

}  // namespace

LogMap load_log_map(const std::string& path) { return parse(YamlMap::load_file(path)); }

LogMap parse_log_map(const std::string& text, const std::string& name) { return parse(YamlMap::load_string(text, name)); }

}  // namespace rpem::io
