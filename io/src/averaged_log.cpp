#include "rpem/io/averaged_log.hpp"

#include <cmath>
#include <limits>

#include "rpem/io/csv_table.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::io {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Data rows start at line 2; CsvTable skips blank lines, so line numbers of later rows are approximate
/// only for logs with blank lines inside.
std::size_t line_of(std::size_t row) { return row + 2; }

}  // namespace

bool is_averaged_log(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw DriveLogError(path, 0, 0, "", "cannot open file");
  std::string header;
  std::getline(in, header);
  std::size_t start = 0;
  while (start <= header.size()) {
    const std::size_t comma = std::min(header.find(',', start), header.size());
    std::string cell = header.substr(start, comma - start);
    const auto first = cell.find_first_not_of(" \t\r\"");
    const auto last = cell.find_last_not_of(" \t\r\"");
    if (first != std::string::npos && cell.substr(first, last - first + 1) == "t_start") return true;
    start = comma + 1;
  }
  return false;
}

std::vector<core::AveragedSample> read_averaged_log(const std::string& path, AveragedLogLayout* layout_out) {
  CsvTable table = [&] {
    try {
      return CsvTable::read(path, /*allow_nan=*/true);
    } catch (const DriveLogError&) {
      throw;
    } catch (const InputError& e) {
      throw DriveLogError(e.file(), e.line(), 0, e.field(), e.reason());
    }
  }();
  auto required = [&](const char* name) -> const std::vector<double>& {
    if (!table.has(name)) throw DriveLogError(path, 1, 0, std::string("column ") + name, "required column is missing from the header");
    return table.column(name);
  };
  const auto& t = required("t");
  const auto& t_start = required("t_start");
  const auto& i_d = required("i_d");
  const auto& i_q = required("i_q");
  const auto& u_d = required("u_d");
  const auto& u_q = required("u_q");
  const auto& omega = required("omega_el");
  AveragedLogLayout layout;
  layout.u_dc = table.has("u_dc");
  layout.t_winding = table.has("T_winding");
  layout.t_magnet = table.has("T_magnet");
  layout.t_drive = table.has("T_drive");
  layout.t_coolant = table.has("T_coolant");
  auto optional = [&](bool present, const char* name, std::size_t k) { return present ? table.column(name)[k] : kNaN; };
  if (table.rows() == 0) throw DriveLogError(path, 2, 0, "", "no samples");

  std::vector<core::AveragedSample> out(table.rows());
  for (std::size_t k = 0; k < table.rows(); ++k) {
    for (const auto& [col, name] : {std::pair{&t, "t"}, {&t_start, "t_start"}, {&i_d, "i_d"}, {&i_q, "i_q"},
                                    {&u_d, "u_d"}, {&u_q, "u_q"}, {&omega, "omega_el"}}) {
      if (!std::isfinite((*col)[k])) throw DriveLogError(path, line_of(k), 0, std::string("column ") + name, "NaN in a required column");
    }
    core::AveragedSample& s = out[k];
    s.t_ns = std::llround(t[k] * 1e9);
    s.t_start_ns = std::llround(t_start[k] * 1e9);
    if (k > 0 && s.t_ns <= out[k - 1].t_ns) throw DriveLogError(path, line_of(k), 0, "column t", "time does not increase");
    if (s.t_start_ns > s.t_ns) throw DriveLogError(path, line_of(k), 0, "column t_start", "window starts after it ends (t_start > t)");
    s.i_dq_A = {i_d[k], i_q[k]};
    s.u_dq_V = {u_d[k], u_q[k]};
    s.omega_el_rad_s = omega[k];
    s.u_dc_V = optional(layout.u_dc, "u_dc", k);
    s.t_winding_C = optional(layout.t_winding, "T_winding", k);
    s.t_magnet_C = optional(layout.t_magnet, "T_magnet", k);
    s.t_drive_C = optional(layout.t_drive, "T_drive", k);
    s.t_coolant_C = optional(layout.t_coolant, "T_coolant", k);
  }
  if (layout_out) *layout_out = layout;
  return out;
}

AveragedLogWriter::AveragedLogWriter(const std::string& path, const AveragedLogLayout& layout)
    : out_(path, std::ios::binary | std::ios::trunc), layout_(layout) {
  if (!out_) throw DriveLogError(path, 0, 0, "", "cannot create file");
  std::string h = "t,t_start,i_d,i_q,u_d,u_q,omega_el";
  if (layout_.u_dc) h += ",u_dc";
  if (layout_.t_winding) h += ",T_winding";
  if (layout_.t_magnet) h += ",T_magnet";
  if (layout_.t_drive) h += ",T_drive";
  if (layout_.t_coolant) h += ",T_coolant";
  out_ << h << '\n';
}

void AveragedLogWriter::write(const core::AveragedSample& s) {
  line_.clear();
  append_number(line_, 1e-9 * static_cast<double>(s.t_ns));
  append_number(line_ += ',', 1e-9 * static_cast<double>(s.t_start_ns));
  for (double v : {s.i_dq_A[0], s.i_dq_A[1], s.u_dq_V[0], s.u_dq_V[1], s.omega_el_rad_s}) append_number(line_ += ',', v);
  if (layout_.u_dc) append_number(line_ += ',', s.u_dc_V);
  if (layout_.t_winding) append_number(line_ += ',', s.t_winding_C);
  if (layout_.t_magnet) append_number(line_ += ',', s.t_magnet_C);
  if (layout_.t_drive) append_number(line_ += ',', s.t_drive_C);
  if (layout_.t_coolant) append_number(line_ += ',', s.t_coolant_C);
  line_ += '\n';
  out_ << line_;
}

void AveragedLogWriter::flush() { out_.flush(); }

DriveLogRow to_drive_log_row(const core::AveragedSample& s) {
  DriveLogRow r;
  r.sample.t_ns = s.t_ns;
  r.sample.theta_el_rad = 0.0;
  r.sample.omega_el_rad_s = s.omega_el_rad_s;
  r.sample.u_dc_V = std::isnan(s.u_dc_V) ? 0.0 : s.u_dc_V;
  r.sample.voltage_frame = core::Frame::kDq;
  r.sample.u_V = {s.u_dq_V[0], s.u_dq_V[1], 0.0};
  r.sample.current_frame = core::Frame::kDq;
  r.sample.i_A = {s.i_dq_A[0], s.i_dq_A[1], 0.0};
  r.sample.gap_before = s.gap_before;
  if (!std::isnan(s.t_winding_C)) r.t_winding_C = s.t_winding_C;
  if (!std::isnan(s.t_magnet_C)) r.t_magnet_C = s.t_magnet_C;
  if (!std::isnan(s.t_coolant_C)) r.t_coolant_C = s.t_coolant_C;
  return r;
}

DriveLogLayout rotor_frame_layout(const AveragedLogLayout& a) {
  DriveLogLayout l;
  l.angle = false;
  l.u_dc = a.u_dc;
  l.voltage_abc = l.current_abc = false;
  l.voltage_dq = l.current_dq = true;
  l.t_winding = a.t_winding;
  l.t_magnet = a.t_magnet;
  l.t_coolant = a.t_coolant;
  return l;
}

void check_averaged_supports(const MachineConfig& c, const std::string& config_name, bool has_u_dc,
                             const std::string& log_path) {
  const core::ModelExtensions& x = c.estimator.extensions;
  if (!x.current_offset_A.isZero(0.0) || !x.current_gain_error.isZero(0.0)) {
    throw ConfigError(config_name, 0, 0, "model_extensions.current_offset/current_gain",
                      "per-phase current offsets and gains have no rotor-frame mean, so averaged samples (" + log_path +
                          ") cannot be corrected for them; remove them for this source");
  }
  check_log_supports(c, config_name, has_u_dc, log_path);
}

}  // namespace rpem::io
