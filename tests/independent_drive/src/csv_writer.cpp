#include "indep_drive/csv_writer.hpp"

#include <charconv>
#include <cstdio>
#include <initializer_list>
#include <stdexcept>

namespace indep {

namespace {

void append_row(std::string& out, std::initializer_list<double> values) {
  char buf[32];
  bool first = true;
  for (double v : values) {
    if (!first) out.push_back(',');
    first = false;
    const auto res = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, res.ptr);
  }
  out.push_back('\n');
}

}  // namespace

std::string log_csv(const std::vector<LogRow>& rows) {
  std::string out = std::string(kLogHeader) + "\n";
  out.reserve(rows.size() * 200);
  for (const LogRow& r : rows) {
    append_row(out, {r.t_s, r.theta_el_rad, r.omega_el_rad_s, r.u_dc_V, r.u_abc_V[0], r.u_abc_V[1], r.u_abc_V[2],
                     r.i_abc_A[0], r.i_abc_A[1], r.i_abc_A[2], r.T_winding_C, r.T_magnet_C, r.torque_cmd_Nm});
  }
  return out;
}

std::string averaged_csv(const std::vector<AveragedRow>& rows) {
  std::string out = std::string(kAveragedHeader) + "\n";
  for (const AveragedRow& r : rows) {
    append_row(out, {r.t_s, r.t_start_s, r.i_d_A, r.i_q_A, r.u_d_V, r.u_q_V, r.omega_el_rad_s, r.u_dc_V, r.T_winding_C,
                     r.T_magnet_C});
  }
  return out;
}

std::string plant_csv(const std::vector<PlantRow>& rows) {
  std::string out = std::string(kPlantHeader) + "\n";
  out.reserve(rows.size() * 200);
  for (const PlantRow& r : rows) {
    append_row(out,
               {r.t_s, r.theta_el_rad, r.omega_el_rad_s, r.i_A.x, r.i_A.y, r.u_applied_V.x, r.u_applied_V.y,
                r.u_applied_ab_V.x, r.u_applied_ab_V.y, r.psi_m_Wb, r.r_s_Ohm, r.torque_Nm, r.T_winding_C, r.T_magnet_C});
  }
  return out;
}

void write_file(const std::string& path, const std::string& text) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) throw std::runtime_error(path + ": cannot be written");
  const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  if (std::fclose(f) != 0 || !ok) throw std::runtime_error(path + ": write failed");
}

}  // namespace indep
