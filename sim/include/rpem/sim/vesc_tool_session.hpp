#pragma once
// VESC Tool logging an emulated VESC (`rpem sim --vesc-tool-out`; docs/scenarios.md, "VESC Tool logs"): the
// drive of a scenario read as VESC Tool reads a VESC with realtime data on, at the rate its link allows, and
// the truth of every row.
//
// The poll (vedderb/vesc_tool): a timer sends COMM_GET_VALUES and COMM_GET_VALUES_SETUP together
// (mainwindow.cpp, mPollRtTimer; mobile/main.qml, rtTimer), but Commands::getValues sends nothing while a
// request is outstanding — mTimeoutValues, cleared by the reply, else counted down by the 10 ms timer from
// mTimeoutCount = 100 (commands.cpp) — so rows come as fast as the link answers: here at uneven intervals,
// uniform in (1 ± jitter)/rate. A poll is lost with probability `loss`, half of them on the way to the VESC
// (the firmware never reads) and half on the way back (the firmware read and reset its averages, and no row
// is written); VESC Tool then polls again after its 1 s timeout.
//
// The firmware's read (sim/vesc_motor.hpp): every control cycle up to the poll, the averages since the
// previous read — the previous row's, or a lost reply's. Each row's time is the read's (the reply's travel
// time, constant, would shift every row alike); the values pass through the wire as the firmware scales and
// casts them and VESC Tool divides them back (can::vesc::encode_values, parse_values). The setup reply of a
// poll arrives after its values reply, so a row carries the previous poll's setup values, stamped with that
// poll's time (the first row: none, -1).

#include <cstdint>
#include <random>

#include "rpem/sim/vesc_motor.hpp"
#include "rpem/sim/vesc_tool_log.hpp"

namespace rpem::sim {

struct VescToolLink {
  double rate_Hz = 11.0;   ///< mean rows per second
  double jitter = 0.5;     ///< intervals uniform in (1 ± jitter)/rate
  double loss = 0.002;     ///< probability that a poll is lost
  double timeout_s = 1.0;  ///< VESC Tool's wait before it polls again (mTimeoutCount 100 × the 10 ms timer)
  std::uint64_t seed = 1;
  std::int64_t start_ms_today = std::int64_t{12} * 3'600'000;  ///< UTC time of day at drive time 0 [ms]
};

/// The truth of one row: what happened over its window.
struct VescToolTruth {
  std::int32_t ms_today = 0;
  std::int64_t log_time_ms = 0;      ///< ms_today unwrapped (+1 day per midnight since the first row): the log's time
  std::int64_t t_ns = 0;             ///< the firmware's read (drive time)
  std::int64_t window_start_ns = 0;  ///< the previous read: the window's start (a lost reply's read included)
  int cycles = 0;                    ///< control cycles averaged
  int lost_before = 0;               ///< polls lost since the previous row
  // Means over the window's cycles (true values, at each cycle's start):
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0, l_d_H = 0.0, l_q_H = 0.0;
  double t_winding_C = 0.0, t_magnet_C = 0.0;
  double modulating = 0.0;    ///< fraction of cycles with the bridge on
  double angle_locked = 0.0;  ///< fraction of cycles in the rotor's frame (not open loop)
  double off_zero = 0.0;      ///< fraction of cycles off with v_d = v_q = 0 reported (OffVoltageReport::kZero)
  std::uint8_t regimes = 0;   ///< bit DriveRegime: present in the window
  double omega_el_start_rad_s = 0.0, omega_el_end_rad_s = 0.0, omega_el_mean_rad_s = 0.0;
  core::Vec2 i_dq_A = core::Vec2::Zero();  ///< true rotor-frame current
  double torque_Nm = 0.0;
  double frame_error_rad = 0.0;  ///< the reported frame's angle less the rotor's
};

class VescToolSession {
 public:
  struct Counters {
    std::uint64_t rows = 0, lost_requests = 0, lost_replies = 0;
  };

  VescToolSession(Scenario scenario, const VescToolLink& link);

  /// The next row VESC Tool writes and its truth; false once the scenario has ended.
  bool next(VescToolRow& row, VescToolTruth& truth);

  [[nodiscard]] const Counters& counters() const noexcept { return counters_; }
  [[nodiscard]] const VescMotor& motor() const noexcept { return motor_; }

 private:
  /// Sums of the truth over the cycles since the previous read.
  struct Window {
    int cycles = 0;
    double psi_m = 0, r_s = 0, l_d = 0, l_q = 0, t_w = 0, t_m = 0, modulating = 0, locked = 0, off_zero = 0;
    double omega_start = 0, omega_end = 0, omega = 0, torque = 0, frame_error = 0;
    core::Vec2 i = core::Vec2::Zero();
    std::uint8_t regimes = 0;
    void add(const TruthRow& t) noexcept;
  };

  /// Runs the drive up to `t_ns`, summing each completed cycle's truth. False once the scenario has ended.
  bool run_to(std::int64_t t_ns);
  [[nodiscard]] std::int64_t draw_interval_ns();
  /// The UTC time of day at drive time t_ns, unwrapped [ms since the first day's midnight].
  [[nodiscard]] std::int64_t log_time_ms(std::int64_t t_ns) const noexcept;
  [[nodiscard]] std::int32_t ms_today(std::int64_t t_ns) const noexcept;
  /// COMM_GET_VALUES_SETUP now (mc_interface_get_setup_values and friends), as VESC Tool decodes it.
  [[nodiscard]] VescSetupValues read_setup(const can::vesc::Values& now) const noexcept;
  [[nodiscard]] VescToolTruth summarize(const Window& w, std::int64_t t_ns) const noexcept;

  VescConfig vesc_;
  int pole_pairs_;
  VescMotor motor_;
  VescToolLink link_;
  std::mt19937_64 rng_;
  Window window_;
  std::int64_t next_poll_ns_ = 0;
  std::int64_t window_start_ns_ = 0;
  std::int32_t setup_ms_ = -1;  ///< the pending setup reply (shown in the next row)
  VescSetupValues setup_;
  int lost_ = 0;
  bool started_ = false;
  Counters counters_;
};

/// The truth CSV beside a VESC Tool log, one line per row:
///   ms_today,t_s,t_start_s,cycles,lost_before,psi_m,r_s,l_d,l_q,T_winding,T_magnet,modulating,angle_locked,
///   off_zero,regime,omega_el_start,omega_el_end,omega_el_mean,i_d,i_q,torque,frame_error,t
/// (SI; `regime` is closed_loop, open_loop, bridge_off, or their names joined by '+' when the window holds several;
/// `t` is the row's time as a reader of the log has it — ms_today in seconds, a day added at each midnight — so that
/// the file is a truth `rpem diagnose --truth` reads: t, psi_m, r_s).
class VescToolTruthWriter {
 public:
  explicit VescToolTruthWriter(const std::string& path);
  void write(const VescToolTruth& t);

 private:
  std::ofstream out_;
  std::string line_;
};

}  // namespace rpem::sim
