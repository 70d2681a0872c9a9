#include "rpem/sim/vesc_tool_session.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "rpem/can/vesc_firmware.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/io/errors.hpp"
#include "rpem/io/number_format.hpp"

namespace rpem::sim {
namespace {

namespace vesc = can::vesc;

/// Every field of COMM_GET_VALUES (commands.c sends them all: its mask is 0xFFFFFFFF).
constexpr std::uint32_t kAllFields = (std::uint32_t{1} << vesc::kFieldCount) - 1;

/// The values as VESC Tool holds them after the wire: scaled and cast by the firmware, divided back.
vesc::Values through_the_wire(const vesc::Values& v) noexcept {
  std::array<std::uint8_t, 128> payload{};  // every field: 78 bytes
  const std::size_t n = vesc::encode_values(v, kAllFields, payload);
  vesc::Values out;
  [[maybe_unused]] const vesc::ParseResult parsed =
      vesc::parse_values(std::span<const std::uint8_t>(payload.data(), n), out);
  assert(n > 0 && parsed == vesc::ParseResult::kOk);
  return out;
}

/// mc_interface_get_battery_level for BATTERY_TYPE_LIION_3_0__4_2 (motor/mc_interface.c): the energy left
/// from the per-cell voltage through the firmware's capacity fit (util/utils_math.c,
/// utils_batt_liion_norm_v_to_capacity), over the energy of 85 % of the capacity at the mean cell voltage.
/// Returns the level (0–1); `wh_left` the energy left.
double battery_level(const VescConfig& c, double v_in_V, double& wh_left) noexcept {
  const double cells = c.battery_cells;
  const double x = std::clamp((v_in_V / cells - 3.2) / (4.2 - 3.2), 0.0, 1.0);
  const double capacity = x * (0.317147 + x * (1.675683 + x * (-3.501286 + x * (5.487810 + x * -2.979767))));
  const double ah_total = 0.85 * c.battery_Ah;
  wh_left = capacity * ah_total * 0.5 * (3.2 * cells + v_in_V);
  return wh_left / (ah_total * 0.5 * (3.2 + 4.2) * cells);
}

}  // namespace

VescToolSession::VescToolSession(Scenario scenario, const VescToolLink& link)
    : vesc_(scenario.vesc),
      pole_pairs_(scenario.machine.machine.rated.pole_pairs),
      motor_(std::move(scenario), VescMotor::Settings{}),
      link_(link),
      rng_(link.seed) {
  next_poll_ns_ = draw_interval_ns();
}

void VescToolSession::Window::add(const TruthRow& t) noexcept {
  if (cycles == 0) omega_start = t.omega_el_rad_s;
  omega_end = t.omega_el_rad_s;
  ++cycles;
  psi_m += t.parameters.psi_m_Wb;
  r_s += t.parameters.r_s_Ohm;
  l_d += t.l_d_H;
  l_q += t.l_q_H;
  t_w += t.t_winding_C;
  t_m += t.t_magnet_C;
  modulating += t.modulating() ? 1.0 : 0.0;
  locked += t.angle_locked() ? 1.0 : 0.0;
  off_zero += !t.modulating() && t.off_report == OffVoltageReport::kZero ? 1.0 : 0.0;
  omega += t.omega_el_rad_s;
  torque += t.torque_Nm;
  i += t.i_dq_A;
  frame_error += core::wrap_angle(t.theta_frame_rad - t.theta_el_rad);
  regimes |= static_cast<std::uint8_t>(1U << static_cast<unsigned>(t.regime));
}

std::int64_t VescToolSession::draw_interval_ns() {
  std::uniform_real_distribution<double> u(1.0 - link_.jitter, 1.0 + link_.jitter);
  return std::max<std::int64_t>(std::llround(u(rng_) / link_.rate_Hz * 1e9), 1);
}

std::int64_t VescToolSession::log_time_ms(std::int64_t t_ns) const noexcept {
  return link_.start_ms_today + t_ns / 1'000'000;
}

std::int32_t VescToolSession::ms_today(std::int64_t t_ns) const noexcept {
  // QTime::msecsSinceStartOfDay: whole milliseconds, wrapping at midnight.
  const std::int64_t ms = log_time_ms(t_ns);
  return static_cast<std::int32_t>(((ms % kMsPerDay) + kMsPerDay) % kMsPerDay);
}

bool VescToolSession::run_to(std::int64_t t_ns) {
  while (!started_ || motor_.time_ns() < t_ns) {
    const TruthRow at_start = motor_.truth();
    if (!motor_.step()) return false;
    if (started_) window_.add(at_start);  // the step completed the cycle that began at `at_start`
    started_ = true;
  }
  return true;
}

VescSetupValues VescToolSession::read_setup(const vesc::Values& now) const noexcept {
  const vesc::Status filtered = motor_.status(0);
  VescSetupValues s;
  const double wheel_m = vesc_.wheel_diameter_m * std::numbers::pi;
  double wh_left = 0.0;
  const double level = battery_level(vesc_, now.v_in_V, wh_left);
  s.current_motor_A = vesc::wire_float32(filtered.current_A, 1e2f);  // mc_interface_get_tot_current_filtered
  s.current_in_A = vesc::wire_float32(filtered.current_in_A, 1e2f);
  s.speed_m_s = vesc::wire_float32(now.erpm / pole_pairs_ / 60.0 * wheel_m / vesc_.gear_ratio, 1e3f);
  s.battery_level = vesc::wire_float16(level, 1e3f);
  s.amp_hours_Ah = vesc::wire_float32(now.amp_hours_Ah, 1e4f);
  s.amp_hours_charged_Ah = vesc::wire_float32(now.amp_hours_charged_Ah, 1e4f);
  s.watt_hours_Wh = vesc::wire_float32(now.watt_hours_Wh, 1e4f);
  s.watt_hours_charged_Wh = vesc::wire_float32(now.watt_hours_charged_Wh, 1e4f);
  // mc_interface_get_distance(_abs): 6 tachometer steps per electrical revolution, 2·p poles.
  const double metres_per_step = wheel_m / (6.0 * pole_pairs_ * vesc_.gear_ratio);
  s.distance_m = vesc::wire_float32(now.tachometer * metres_per_step, 1e3f);
  s.distance_abs_m = vesc::wire_float32(now.tachometer_abs * metres_per_step, 1e3f);
  s.num_vescs = 1;
  s.battery_wh = vesc::wire_float32(wh_left, 1e3f);
  return s;
}

VescToolTruth VescToolSession::summarize(const Window& w, std::int64_t t_ns) const noexcept {
  VescToolTruth t;
  const double inv = w.cycles > 0 ? 1.0 / w.cycles : std::nan("");
  t.t_ns = t_ns;
  t.ms_today = ms_today(t_ns);
  t.log_time_ms = log_time_ms(t_ns);
  t.window_start_ns = window_start_ns_;
  t.cycles = w.cycles;
  t.lost_before = lost_;
  t.psi_m_Wb = w.psi_m * inv;
  t.r_s_Ohm = w.r_s * inv;
  t.l_d_H = w.l_d * inv;
  t.l_q_H = w.l_q * inv;
  t.t_winding_C = w.t_w * inv;
  t.t_magnet_C = w.t_m * inv;
  t.modulating = w.modulating * inv;
  t.angle_locked = w.locked * inv;
  t.off_zero = w.off_zero * inv;
  t.regimes = w.regimes;
  t.omega_el_start_rad_s = w.omega_start;
  t.omega_el_end_rad_s = w.omega_end;
  t.omega_el_mean_rad_s = w.omega * inv;
  t.i_dq_A = w.i * inv;
  t.torque_Nm = w.torque * inv;
  t.frame_error_rad = w.frame_error * inv;
  return t;
}

bool VescToolSession::next(VescToolRow& row, VescToolTruth& truth) {
  for (;;) {
    const std::int64_t t = next_poll_ns_;
    if (!run_to(t)) return false;
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    const double u = u01(rng_);
    const bool lost = u < link_.loss;
    next_poll_ns_ = t + draw_interval_ns() + (lost ? std::llround(link_.timeout_s * 1e9) : 0);
    if (lost && u < 0.5 * link_.loss) {  // the request never reached the firmware
      ++counters_.lost_requests;
      ++lost_;
      continue;
    }
    // The firmware reads, at the end of the control cycle the poll arrived in: the averages since the
    // previous read, then resets them.
    const std::int64_t read_ns = motor_.time_ns();
    const vesc::Values values = motor_.read_values();
    truth = summarize(window_, read_ns);
    window_ = Window{};
    window_start_ns_ = read_ns;
    const std::int32_t previous_setup_ms = setup_ms_;
    const VescSetupValues previous_setup = setup_;
    setup_ = read_setup(values);
    setup_ms_ = ms_today(read_ns);
    if (lost) {  // the reply never reached VESC Tool
      ++counters_.lost_replies;
      ++lost_;
      setup_ms_ = previous_setup_ms;
      setup_ = previous_setup;
      continue;
    }
    row.ms_today = truth.ms_today;
    row.values = through_the_wire(values);
    row.ms_today_setup = previous_setup_ms;
    row.setup = previous_setup;
    lost_ = 0;
    ++counters_.rows;
    return true;
  }
}

VescToolTruthWriter::VescToolTruthWriter(const std::string& path) : out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw io::InputError(path, 0, 0, "", "cannot create file");
  out_ << "ms_today,t_s,t_start_s,cycles,lost_before,psi_m,r_s,l_d,l_q,T_winding,T_magnet,modulating,angle_locked,"
          "off_zero,regime,omega_el_start,omega_el_end,omega_el_mean,i_d,i_q,torque,frame_error,t\n";
}

void VescToolTruthWriter::write(const VescToolTruth& t) {
  line_.clear();
  line_ += std::to_string(t.ms_today);
  auto number = [this](double v) { io::append_number(line_ += ',', v); };
  number(1e-9 * static_cast<double>(t.t_ns));
  number(1e-9 * static_cast<double>(t.window_start_ns));
  (line_ += ',') += std::to_string(t.cycles);
  (line_ += ',') += std::to_string(t.lost_before);
  for (double v :
       {t.psi_m_Wb, t.r_s_Ohm, t.l_d_H, t.l_q_H, t.t_winding_C, t.t_magnet_C, t.modulating, t.angle_locked, t.off_zero}) {
    number(v);
  }
  line_ += ',';
  bool first = true;
  for (unsigned r = 0; r < 3; ++r) {
    if ((t.regimes >> r & 1U) == 0) continue;
    if (!first) line_ += '+';
    line_ += regime_name(static_cast<DriveRegime>(r));
    first = false;
  }
  for (double v : {t.omega_el_start_rad_s, t.omega_el_end_rad_s, t.omega_el_mean_rad_s, t.i_dq_A[0], t.i_dq_A[1],
                   t.torque_Nm, t.frame_error_rad, 1e-3 * static_cast<double>(t.log_time_ms)}) {
    number(v);
  }
  line_ += '\n';
  out_ << line_;
}

}  // namespace rpem::sim
