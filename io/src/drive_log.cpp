#include "rpem/io/drive_log.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "rpem/core/frames.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {
namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r'; }

/// Splits a row at commas into trimmed cells; the cells' strings are reused from row to row.
void split(const std::string& line, std::vector<std::string>& cells) {
  std::size_t n = 0;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::size_t first = start;
    std::size_t last = comma == std::string::npos ? line.size() : comma;
    while (first < last && blank(line[first])) ++first;
    while (last > first && blank(line[last - 1])) --last;
    if (n == cells.size()) cells.emplace_back();
    cells[n++].assign(line, first, last - first);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  cells.resize(n);
}

/// A number for a message (six significant digits).
std::string g6(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

}  // namespace

DriveLogReader::DriveLogReader(const std::string& path, DriveLogLimits limits)
    : path_(path), file_(path, std::ios::binary), in_(file_), limits_(std::move(limits)) {
  if (!file_) throw DriveLogError(path, 0, 0, "", "cannot open file");
  std::error_code ec;
  bytes_total_ = std::filesystem::file_size(path, ec);
  read_header();
}

DriveLogReader::DriveLogReader(std::istream& in, std::string name, DriveLogLimits limits)
    : path_(std::move(name)), in_(in), limits_(std::move(limits)) {
  read_header();
}

void DriveLogReader::read_header() {
  std::string header_line;
  if (!std::getline(in_, header_line)) throw DriveLogError(path_, 1, 0, "", "empty file: expected a header row");
  line_ = 1;
  bytes_read_ = header_line.size() + 1;
  split(header_line, header_);
  auto find = [&](const char* name) {
    Column c;
    for (std::size_t k = 0; k < header_.size(); ++k) {
      if (header_[k] == name) {
        if (c.present()) fail(name, "column appears twice in the header");
        c.index = static_cast<int>(k);
      }
    }
    return c;
  };
  t_ = find("t");
  theta_ = find("theta_el");
  omega_ = find("omega_el");
  udc_ = find("u_dc");
  ua_ = find("u_a"), ub_ = find("u_b"), uc_ = find("u_c");
  ud_ = find("u_d"), uq_ = find("u_q");
  ia_ = find("i_a"), ib_ = find("i_b"), ic_ = find("i_c");
  id_ = find("i_d"), iq_ = find("i_q");
  tw_ = find("T_winding"), tm_ = find("T_magnet"), tc_ = find("T_coolant"), tq_ = find("torque_cmd");

  for (auto [col, name] : {std::pair{t_, "t"}, {omega_, "omega_el"}}) {
    if (!col.present()) fail(name, "required column is missing from the header");
  }
  auto group = [&](std::initializer_list<std::pair<Column, const char*>> cols, const char* what) {
    int present = 0;
    for (const auto& [c, n] : cols) present += c.present() ? 1 : 0;
    if (present != 0 && present != static_cast<int>(cols.size())) {
      for (const auto& [c, n] : cols) {
        if (!c.present()) fail(n, std::string("incomplete ") + what + " column group");
      }
    }
    return present != 0;
  };
  layout_.voltage_abc = group({{ua_, "u_a"}, {ub_, "u_b"}, {uc_, "u_c"}}, "phase-voltage");
  layout_.voltage_dq = group({{ud_, "u_d"}, {uq_, "u_q"}}, "rotor-frame voltage");
  layout_.current_abc = group({{ia_, "i_a"}, {ib_, "i_b"}, {ic_, "i_c"}}, "phase-current");
  layout_.current_dq = group({{id_, "i_d"}, {iq_, "i_q"}}, "rotor-frame current");
  if (!layout_.voltage_abc && !layout_.voltage_dq) fail("u_a,u_b,u_c|u_d,u_q", "no voltage-command columns");
  if (!layout_.current_abc && !layout_.current_dq) fail("i_a,i_b,i_c|i_d,i_q", "no current columns");
  // A log entirely in the rotor frame needs no angle, and may not know its DC link (docs/drive-log.md).
  const bool rotor_frame_only = !layout_.voltage_abc && !layout_.current_abc;
  for (auto [col, name] : {std::pair{theta_, "theta_el"}, {udc_, "u_dc"}}) {
    if (!col.present() && !rotor_frame_only) {
      fail(name, "required column is missing from the header (optional only when voltage and current are both "
                 "given as u_d,u_q and i_d,i_q only)");
    }
  }
  layout_.angle = theta_.present();
  layout_.u_dc = udc_.present();
  layout_.t_winding = tw_.present();
  layout_.t_magnet = tm_.present();
  layout_.t_coolant = tc_.present();
  layout_.torque_cmd = tq_.present();
}

void DriveLogReader::fail(const std::string& column, const std::string& reason) const {
  throw DriveLogError(path_, line_, 0, "column " + column, reason);
}

void DriveLogReader::fail(const Column& c, const char* name, const std::string& reason) const {
  throw DriveLogError(path_, line_, static_cast<std::size_t>(c.index) + 1, std::string("column ") + name, reason);
}

double DriveLogReader::cell(const Column& c, const char* name) const {
  if (static_cast<std::size_t>(c.index) >= cells_.size()) fail(name, "row has too few cells");
  const std::string& s = cells_[static_cast<std::size_t>(c.index)];
  if (s.empty()) fail(c, name, "empty cell");
  double v = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size()) fail(c, name, "'" + s + "' is not a number");
  if (std::isnan(v)) fail(c, name, "NaN");
  if (!std::isfinite(v)) fail(c, name, "'" + s + "' is not finite");
  return v;
}

double DriveLogReader::cell(const Column& c, const char* name, const Bound& bound, const char* unit) const {
  const double v = cell(c, name);
  if (std::abs(v) > bound.max_abs) {
    fail(c, name, g6(v) + " " + unit + " is beyond the plausible ±" + g6(bound.max_abs) + " " +
                      unit + " (" + bound.why + ")");
  }
  return v;
}

double DriveLogReader::temperature(const Column& c, const char* name) const {
  const double v = cell(c, name);
  if (v < limits_.temperature_min_C || v > limits_.temperature_max_C) {
    fail(c, name, g6(v) + " °C is outside the plausible [" + g6(limits_.temperature_min_C) + ", " +
                      g6(limits_.temperature_max_C) + "] °C");
  }
  return v;
}

double DriveLogReader::command(const Column& c, const char* name, double u_dc_V) const {
  const double v = cell(c, name, limits_.voltage_V, "V");
  if (u_dc_V >= 1.0 && std::abs(v) > limits_.command_per_dc_link * u_dc_V) {
    fail(c, name, g6(v) + " V is more than " + g6(limits_.command_per_dc_link) +
                      " x this row's u_dc = " + g6(u_dc_V) +
                      " V (a two-level inverter applies at most u_dc/2 from the link's midpoint)");
  }
  return v;
}

bool DriveLogReader::next(DriveLogRow& row) {
  std::string text;
  while (std::getline(in_, text)) {
    ++line_;
    bytes_read_ += text.size() + 1;
    if (std::all_of(text.begin(), text.end(), blank)) continue;  // blank line
    split(text, cells_);
    if (cells_.size() != header_.size()) {
      fail("*", "row has " + std::to_string(cells_.size()) + " cells, header has " + std::to_string(header_.size()));
    }
    core::DriveSample& s = row.sample;
    const std::int64_t t_ns = std::llround(cell(t_, "t", limits_.time_s, "s") * 1e9);
    if (previous_t_ns_ && t_ns <= *previous_t_ns_) fail(t_, "t", "time does not increase (by at least 1 ns)");
    previous_t_ns_ = t_ns;
    s.t_ns = t_ns;
    s.theta_el_rad = theta_.present() ? cell(theta_, "theta_el", limits_.angle_rad, "rad") : 0.0;
    s.omega_el_rad_s = cell(omega_, "omega_el", limits_.speed_rad_s, "rad/s");
    s.u_dc_V = udc_.present() ? cell(udc_, "u_dc", limits_.voltage_V, "V") : 0.0;
    s.gap_before = false;
    const double u_dc = s.u_dc_V;
    if (layout_.voltage_abc) {
      s.voltage_frame = core::Frame::kAbc;
      s.u_V = {command(ua_, "u_a", u_dc), command(ub_, "u_b", u_dc), command(uc_, "u_c", u_dc)};
      if (layout_.voltage_dq) (void)command(ud_, "u_d", u_dc), (void)command(uq_, "u_q", u_dc);  // validate all cells
    } else {
      s.voltage_frame = core::Frame::kDq;
      s.u_V = {command(ud_, "u_d", u_dc), command(uq_, "u_q", u_dc), 0.0};
    }
    const Bound& i_max = limits_.current_A;
    if (layout_.current_abc) {
      s.current_frame = core::Frame::kAbc;
      s.i_A = {cell(ia_, "i_a", i_max, "A"), cell(ib_, "i_b", i_max, "A"), cell(ic_, "i_c", i_max, "A")};
      if (layout_.current_dq) (void)cell(id_, "i_d", i_max, "A"), (void)cell(iq_, "i_q", i_max, "A");
    } else {
      s.current_frame = core::Frame::kDq;
      s.i_A = {cell(id_, "i_d", i_max, "A"), cell(iq_, "i_q", i_max, "A"), 0.0};
    }
    row.t_winding_C = layout_.t_winding ? std::optional(temperature(tw_, "T_winding")) : std::nullopt;
    row.t_magnet_C = layout_.t_magnet ? std::optional(temperature(tm_, "T_magnet")) : std::nullopt;
    row.t_coolant_C = layout_.t_coolant ? std::optional(temperature(tc_, "T_coolant")) : std::nullopt;
    row.torque_cmd_Nm =
        layout_.torque_cmd ? std::optional(cell(tq_, "torque_cmd", limits_.torque_Nm, "Nm")) : std::nullopt;
    ++rows_;
    return true;
  }
  if (rows_ == 0) throw DriveLogError(path_, line_, 0, "", "no samples: the header is followed by no data rows");
  return false;
}

std::vector<DriveLogRow> read_drive_log(const std::string& path, const DriveLogLimits& limits) {
  DriveLogReader reader(path, limits);
  std::vector<DriveLogRow> rows;
  DriveLogRow row;
  while (reader.next(row)) rows.push_back(row);
  return rows;
}

DriveLogWriter::DriveLogWriter(const std::string& path, const DriveLogLayout& layout)
    : out_(path, std::ios::binary | std::ios::trunc), layout_(layout) {
  if (!out_) throw DriveLogError(path, 0, 0, "", "cannot create file");
  std::string h = "t,theta_el,omega_el,u_dc";
  if (layout_.voltage_abc) h += ",u_a,u_b,u_c";
  if (layout_.voltage_dq) h += ",u_d,u_q";
  if (layout_.current_abc) h += ",i_a,i_b,i_c";
  if (layout_.current_dq) h += ",i_d,i_q";
  if (layout_.t_winding) h += ",T_winding";
  if (layout_.t_magnet) h += ",T_magnet";
  if (layout_.t_coolant) h += ",T_coolant";
  if (layout_.torque_cmd) h += ",torque_cmd";
  out_ << h << '\n';
}

void DriveLogWriter::write(const DriveLogRow& row) {
  const core::DriveSample& s = row.sample;
  const core::Rotation rot = core::Rotation::of(s.theta_el_rad);
  auto to_abc = [&](core::Frame f, const core::Vec3& v) -> core::Vec3 {
    if (f == core::Frame::kAbc) return v;
    const core::Vec2 ab = f == core::Frame::kAlphaBeta ? core::Vec2(v.head<2>()) : core::inverse_park(v.head<2>(), rot);
    return core::inverse_clarke(ab);
  };
  auto to_dq = [&](core::Frame f, const core::Vec3& v) -> core::Vec2 {
    if (f == core::Frame::kDq) return v.head<2>();
    const core::Vec2 ab = f == core::Frame::kAbc ? core::clarke(v) : core::Vec2(v.head<2>());
    return core::park(ab, rot);
  };
  line_.clear();
  append_number(line_, 1e-9 * static_cast<double>(s.t_ns));
  for (double v : {s.theta_el_rad, s.omega_el_rad_s, s.u_dc_V}) append_number(line_ += ',', v);
  if (layout_.voltage_abc) {
    const core::Vec3 u = to_abc(s.voltage_frame, s.u_V);
    for (int k = 0; k < 3; ++k) append_number(line_ += ',', u[k]);
  }
  if (layout_.voltage_dq) {
    const core::Vec2 u = to_dq(s.voltage_frame, s.u_V);
    for (int k = 0; k < 2; ++k) append_number(line_ += ',', u[k]);
  }
  if (layout_.current_abc) {
    const core::Vec3 i = to_abc(s.current_frame, s.i_A);
    for (int k = 0; k < 3; ++k) append_number(line_ += ',', i[k]);
  }
  if (layout_.current_dq) {
    const core::Vec2 i = to_dq(s.current_frame, s.i_A);
    for (int k = 0; k < 2; ++k) append_number(line_ += ',', i[k]);
  }
  if (layout_.t_winding) append_number(line_ += ',', row.t_winding_C.value_or(std::nan("")));
  if (layout_.t_magnet) append_number(line_ += ',', row.t_magnet_C.value_or(std::nan("")));
  if (layout_.t_coolant) append_number(line_ += ',', row.t_coolant_C.value_or(std::nan("")));
  if (layout_.torque_cmd) append_number(line_ += ',', row.torque_cmd_Nm.value_or(std::nan("")));
  line_ += '\n';
  out_ << line_;
}

void DriveLogWriter::flush() { out_.flush(); }

}  // namespace rpem::io
