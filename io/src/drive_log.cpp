#include "rpem/io/drive_log.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "rpem/core/clock.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {
DriveLogReader::DriveLogReader(const std::string& path, DriveLogLimits limits)
    : reader_(path, drive_log_map(), std::move(limits)) {
  check_layout();
}

DriveLogReader::DriveLogReader(std::istream& in, std::string name, DriveLogLimits limits)
    : reader_(in, std::move(name), drive_log_map(), std::move(limits)) {
  check_layout();
}

DriveLogReader::DriveLogReader(const std::string& path, LogMap map, DriveLogLimits limits)
    : reader_(path, std::move(map), std::move(limits)) {
  if (reader_.map().averaged()) {
    throw ConfigError(reader_.map().name, 0, 0, "samples", "a map of averaged samples does not give drive-log rows");
  }
  check_layout();
}

void DriveLogReader::check_layout() {
  // Our own format names its quantities in the header, so what a drive log needs is checked here; a map
  // was checked when it was loaded.
  if (const std::optional<LayoutProblem> p = drive_log_layout_problem(reader_.present())) reader_.fail_header(*p);
  auto has = [&](Quantity q) { return reader_.has(q); };
  layout_.angle = has(Quantity::kThetaEl);
  layout_.u_dc = has(Quantity::kUDc);
  layout_.voltage_abc = has(Quantity::kUA);
  layout_.voltage_dq = has(Quantity::kUD);
  layout_.current_abc = has(Quantity::kIA);
  layout_.current_dq = has(Quantity::kID);
  layout_.t_winding = has(Quantity::kTWinding);
  layout_.t_magnet = has(Quantity::kTMagnet);
  layout_.t_coolant = has(Quantity::kTCoolant);
  layout_.torque_cmd = has(Quantity::kTorqueCmd);
}

bool DriveLogReader::next(DriveLogRow& row) {
  if (!reader_.next(row_)) return false;
  const MappedRow& r = row_;
  core::DriveSample& s = row.sample;
  s.t_ns = r.t_ns;
  s.theta_el_rad = layout_.angle ? r[Quantity::kThetaEl] : 0.0;
  s.omega_el_rad_s = r[Quantity::kOmegaEl];
  s.u_dc_V = layout_.u_dc ? r[Quantity::kUDc] : 0.0;
  s.gap_before = false;
  if (layout_.voltage_abc) {
    s.voltage_frame = core::Frame::kAbc;
    s.u_V = {r[Quantity::kUA], r[Quantity::kUB], r[Quantity::kUC]};
  } else {
    s.voltage_frame = core::Frame::kDq;
    s.u_V = {r[Quantity::kUD], r[Quantity::kUQ], 0.0};
  }
  if (layout_.current_abc) {
    s.current_frame = core::Frame::kAbc;
    s.i_A = {r[Quantity::kIA], r[Quantity::kIB], r[Quantity::kIC]};
  } else {
    s.current_frame = core::Frame::kDq;
    s.i_A = {r[Quantity::kID], r[Quantity::kIQ], 0.0};
  }
  // A cell holding its column's no-reading value is NaN (MappedColumn::no_reading): no value on this row.
  auto optional = [&](bool present, Quantity q) {
    return present && !std::isnan(r[q]) ? std::optional(r[q]) : std::nullopt;
  };
  constexpr double kNoReading = std::numeric_limits<double>::quiet_NaN();
  s.t_winding_C = layout_.t_winding ? r[Quantity::kTWinding] : kNoReading;
  s.t_coolant_C = layout_.t_coolant ? r[Quantity::kTCoolant] : kNoReading;
  row.t_magnet_C = optional(layout_.t_magnet, Quantity::kTMagnet);
  row.torque_cmd_Nm = optional(layout_.torque_cmd, Quantity::kTorqueCmd);
  return true;
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
  if (!out_) throw InputError(path, 0, 0, "", "cannot create file");  // an output: not the data's fault
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
  append_number(line_, core::to_seconds(s.t_ns));
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
  if (layout_.t_winding) append_number(line_ += ',', s.t_winding_C);
  if (layout_.t_magnet) append_number(line_ += ',', row.t_magnet_C.value_or(std::nan("")));
  if (layout_.t_coolant) append_number(line_ += ',', s.t_coolant_C);
  if (layout_.torque_cmd) append_number(line_ += ',', row.torque_cmd_Nm.value_or(std::nan("")));
  line_ += '\n';
  out_ << line_;
}

void DriveLogWriter::flush() { out_.flush(); }

}  // namespace rpem::io
