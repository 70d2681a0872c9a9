#pragma once
// The generator: the motor, the VESC's firmware, the app and VESC Tool's reads run together control cycle by
// control cycle; out come the rows VESC Tool writes and the truth behind each (README).
#include <optional>
#include <string>
#include <vector>

#include "indep_vesc/app.hpp"
#include "indep_vesc/case.hpp"
#include "indep_vesc/firmware.hpp"
#include "indep_vesc/plant.hpp"
#include "indep_vesc/vesc_tool_csv.hpp"

namespace indep::vesc {

/// ψm, R_s, L of a machine [Wb, Ω, H].
struct MachineValues {
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0, l_d_H = 0.0, l_q_H = 0.0;
  int pole_pairs = 0;
};

/// What each row really was (README "Truth"): the window of the firmware's averages and the plant over it.
struct RowTruth {
  double t_window_start_s = 0.0, t_read_s = 0.0;  // the previous read (logged or not) and this one
  int cycles = 0;                                 // control cycles averaged
  double modulating_fraction = 0.0;               // cycles with the bridge on
  double open_loop_fraction = 0.0;                // cycles framed by an open-loop angle (start-up or openloop)
  double hall_fraction = 0.0;                     // Hall mode: cycles framed by the Hall angle (alone or blended)
  double hall_weight_mean = 0.0;                  // ... the Hall angle's mean weight in the frame (0: the observer's)
  double hall_interpolated_fraction = 0.0;        // ... cycles framed by an interpolated Hall angle (not the nearest
                                                  //     state's: above foc_hall_interp_erpm by the transition times)
  double frame_error_mean_rad = 0.0;              // mean of wrap(frame − true d axis)
  double frame_error_max_abs_rad = 0.0;
  double omega_el_mean_rad_s = 0.0, omega_el_start_rad_s = 0.0, omega_el_end_rad_s = 0.0;
  double i_d_mean_A = 0.0, i_q_mean_A = 0.0;  // the true current in the true rotor frame, mean of the samples
  double i_d_avg_A = 0.0, i_q_avg_A = 0.0;    // ... and its mean over time (the two differ by the ripple
                                              //     the held voltage makes within each period)
  double i_dev_rms_A = 0.0;                   // rms of the current vector about its window mean
  double u_d_mean_V = 0.0, u_q_mean_V = 0.0;  // the voltage at the terminals in the true rotor frame
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0, T_winding_C = 0.0, T_magnet_C = 0.0;
  SegmentKind segment = SegmentKind::off;  // the segment running at the read
  // Classification by TruthRules:
  std::string bridge;  // modulating | bridge_off | mixed
  std::string angle;   // observer | open_loop | hall | mixed
  bool angle_locked = false;
  bool excites_psi_m = false, excites_r_s = false, transient = false;
  double psi_m_term_V = 0.0, r_s_term_V = 0.0;
};

struct LogRow {
  double t_reply_s = 0.0;  // the host's time of the row
  RowContext context;      // what VESC Tool writes
  RowTruth truth;
};

/// One control cycle, when Case::keep_cycle_trace is set.
struct CycleRecord {
  double t_s = 0.0, theta_el_rad = 0.0, omega_el_rad_s = 0.0;
  double phase_rad = 0.0;  // the firmware's frame
  AngleSource source = AngleSource::off;
  double observer_phase_rad = 0.0;  // the observer's angle (Hall mode: what the frame is above foc_sl_erpm)
  int hall_state = -1;              // Hall mode: the sensors' state read
  double hall_weight = 0.0;         // Hall mode: the Hall angle's weight in phase_rad
  bool hall_interpolating = false;  // Hall mode: interpolated, not the nearest state's angle
  bool modulating = false;
  Vec2 i_dq_true_A, i_dq_reported_A, v_dq_reported_V;
  Vec2 v_dq_applied_V;  // mean over the cycle, true rotor frame
  double psi_m_Wb = 0.0, r_s_Ohm = 0.0;
  double energy_in_J = 0.0, energy_cu_J = 0.0, energy_load_J = 0.0;
  double magnetic_energy_J = 0.0, kinetic_energy_J = 0.0;  // at the cycle's end
};

struct Result {
  Case resolved;
  MachineValues configured, true_at_reference;
  MachineValues vesc_configuration;             // the VESC's own (detected) R, L, ψ at the start
  std::optional<double> vesc_measured_flux_Wb;  // the emulated flux measurement's result
  FirmwareParams firmware;
  PlantParams plant;
  double control_period_s = 0.0;
  double initial_theta_rad = 0.0;
  std::vector<LogRow> rows;  // in the order VESC Tool writes them
  int reads = 0, lost_replies = 0;
  std::vector<SegmentSpan> spans;
  std::vector<CycleRecord> cycles;
  double end_psi_m_Wb = 0.0, end_r_s_Ohm = 0.0, end_T_winding_C = 0.0, end_T_magnet_C = 0.0;
};

Result generate(const Case& c);

/// The file as VESC Tool writes it.
std::string vesc_tool_csv(const Result& r);
/// The truth file (README "Truth").
std::string truth_json(const Result& r);
/// The per-cycle trace (README "Trace").
std::string cycle_trace_csv(const Result& r);

}  // namespace indep::vesc
