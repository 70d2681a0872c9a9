#pragma once
// The app layer: runs the scenario's segments against the firmware once per millisecond, as a VESC app or
// VESC Tool would (README "Scenario"). The flux measurement follows the sequence of vedderb/bldc conf_general.c,
// conf_general_measure_flux_linkage_openloop, as conf_general_detect_apply_all calls it: current gains from
// the detected R and L with a 1500 µs time constant; the open-loop current ramped in over 200 ms at standstill,
// held 1 s, the open-loop ERPM ramped at erpm_per_s until the duty cycle reaches 0.3 (at most 0.9·l_max_duty)
// or 12 000 ERPM, held 1 s; v_d, v_q, i_d, i_q averaged over 1 s give (|v| − R·|i|)/ω − L·|i|, written to the
// configuration for 0.5 s more; then the bridge off and, while the motor coasts with a duty above 0.02 (at most
// 0.2 s), the mean of v_q/ω: the "undriven" flux linkage, which detect_apply_all keeps when it has more than 60
// samples (0.1 ms apart). The gains are restored at the end.
#include <optional>
#include <vector>

#include "indep_vesc/firmware.hpp"
#include "indep_vesc/scenario.hpp"

namespace indep::vesc {

/// A segment as it ran.
struct SegmentSpan {
  Segment segment;
  double t_start_s = 0.0, t_end_s = 0.0;
};

class App {
 public:
  explicit App(std::vector<Segment> segments);

  /// The millisecond at time t_s (called every 1 ms, in order).
  void step_1ms(double t_s, VescFirmware& fw);
  /// Closes the running segment at t_s (end of the log).
  void finish(double t_s);

  [[nodiscard]] const std::vector<SegmentSpan>& spans() const { return spans_; }
  /// The running segment's kind (off after the last segment).
  [[nodiscard]] SegmentKind kind_now() const;
  /// The running segment's torque on the shaft and its added friction [Nm].
  [[nodiscard]] double external_torque_Nm() const;
  [[nodiscard]] double added_friction_Nm() const;
  /// The running segment's added viscous load [Nm·s] (a brake proportional to the shaft speed).
  [[nodiscard]] double added_viscous_Nm_s() const;
  /// What the emulated flux measurement found, if it ran to its end.
  [[nodiscard]] std::optional<double> measured_flux_linkage_Wb() const { return flux_; }

 private:
  void begin(std::size_t index, double t_s, VescFirmware& fw);
  bool run_segment(double t_s, VescFirmware& fw);  // false when the segment is done
  bool run_flux_measurement(double t_s, VescFirmware& fw);

  std::vector<Segment> segments_;
  std::vector<SegmentSpan> spans_;
  std::size_t index_ = 0;
  bool started_ = false, done_ = false;
  double t_begin_ = 0.0;
  double command_A_ = 0.0, ramp_from_A_ = 0.0, brake_sign_ = -1.0;

  // Flux measurement state.
  enum class Flux { lock, hold, ramp, settle, average, configure, undriven, stopped } flux_phase_ = Flux::lock;
  int flux_ms_ = 0;
  double flux_erpm_ = 0.0;
  double sum_vd_ = 0.0, sum_vq_ = 0.0, sum_id_ = 0.0, sum_iq_ = 0.0;
  double flux_openloop_ = 0.0, sum_undriven_ = 0.0;
  int undriven_samples_ = 0;
  double kp_before_ = 0.0, ki_before_ = 0.0;
  std::optional<double> flux_;
  void end_flux_measurement(VescFirmware& fw);
};

}  // namespace indep::vesc
