#pragma once
// The simulated drive: plant + inverter + FOC + sensors, stepped one control period at a time. It
// produces exactly what a drive logs (docs/drive-log.md: commands, not actual voltages) and, beside
// it, the truth. One simulator serves `rpem sim`, `rpem reproduce`, rpemd's built-in source, the tests
// and the benchmarks.
//
// Period k (t_k = k·T): sample the sensors; emit row k with the command that acts over [t_k, t_k+1]
// (computed in period k − 1); run the FOC on the samples (its command acts in period k + 1);
// integrate the plant over [t_k, t_k+1] — at switching fidelity from one switching instant to the next
// (EdgeIntegrator) or in fixed steps with the inverter's mean voltage over each (Scenario::integrator).
//
// Regimes (sim/regime.hpp; docs/scenarios.md, "Regimes"), each for whole periods from the first t_k at or
// after its event: in open loop the controller's frame is the commanded angle, which the row logs as its
// angle and speed; with the bridge off the plant freewheels (PmsmPlant::freewheel), the row logs a zero
// command, and the FOC keeps tracking the back EMF with a zero current reference, so that its first command
// after the bridge is back on is the back EMF, as the firmware presets its integrators to it.

#include <cstdint>
#include <memory>

#include "rpem/io/drive_log.hpp"
#include "rpem/sim/edge_integrator.hpp"
#include "rpem/sim/foc.hpp"
#include "rpem/sim/inverter.hpp"
#include "rpem/sim/plant.hpp"
#include "rpem/sim/regime.hpp"
#include "rpem/sim/scenario.hpp"
#include "rpem/sim/sensors.hpp"
#include "rpem/sim/thermal_plant.hpp"

namespace rpem::sim {

/// The true state at a sample instant (the truth CSV).
struct TruthRow {
  std::int64_t t_ns = 0;
  PlantParameters parameters;
  double l_d_H = 0.0, l_q_H = 0.0;  ///< apparent inductances at the operating point
  double t_winding_C = 0.0, t_magnet_C = 0.0;
  double omega_el_rad_s = 0.0;
  double theta_el_rad = 0.0;
  double torque_Nm = 0.0;
  core::Vec2 i_dq_A = core::Vec2::Zero();
  DriveRegime regime = DriveRegime::kClosedLoop;             ///< over the period from t
  OffVoltageReport off_report = OffVoltageReport::kBackEmf;  ///< bridge off: what a VESC reports as v_d, v_q
  double theta_frame_rad = 0.0;  ///< the angle of the controller's dq frame, which the row logs (wrapped)

  /// The bridge applies the controller's command.
  [[nodiscard]] bool modulating() const noexcept { return regime != DriveRegime::kBridgeOff; }
  /// The controller's frame is the rotor's (a sensor or an observer tracks it), not a commanded angle.
  [[nodiscard]] bool angle_locked() const noexcept { return regime != DriveRegime::kOpenLoop; }
};

class DriveSimulator {
 public:
  explicit DriveSimulator(Scenario scenario);

  /// Advances one control period. Returns false once the scenario's duration is reached.
  bool next(io::DriveLogRow& row, TruthRow& truth) noexcept;

  /// The drive-log layout this scenario writes.
  [[nodiscard]] io::DriveLogLayout layout() const noexcept;
  [[nodiscard]] const Scenario& scenario() const noexcept { return scenario_; }
  [[nodiscard]] const PmsmPlant& plant() const noexcept { return plant_; }
  [[nodiscard]] std::int64_t period_ns() const noexcept { return period_ns_; }
  [[nodiscard]] std::int64_t samples_total() const noexcept { return samples_total_; }
  /// Bridge-off periods whose back EMF (line-to-line peak √3·|ω|·ψm) reached the DC link: the diodes would
  /// have rectified, which the freewheeling plant does not model.
  [[nodiscard]] std::uint64_t rectifying_periods() const noexcept { return rectifying_periods_; }
  /// The loss-driven thermal plant (`thermal_plant:`); null when the temperatures are signals.
  [[nodiscard]] const ThermalPlant* thermal_plant() const noexcept {
    return scenario_.thermal_plant.enabled ? &thermal_ : nullptr;
  }
  /// The edge-to-edge integrator (its counters); null with fixed steps.
  [[nodiscard]] const EdgeIntegrator* edge_integrator() const noexcept { return edge_to_edge_ ? &edges_ : nullptr; }

 private:
  [[nodiscard]] PlantParameters parameters_at(double t_s) noexcept;
  /// Takes the regime of the period at t (entering open loop places the commanded frame).
  void update_regime(double t_s) noexcept;
  /// Samples the sensors at t_k and runs the controller.
  void sample_and_control(double t_s) noexcept;
  /// Integrates the plant over [t_k, t_k+1].
  void integrate(std::int64_t k) noexcept;
  void fill_row(std::int64_t t_ns, io::DriveLogRow& row) const noexcept;
  void fill_truth(std::int64_t t_ns, TruthRow& truth) const noexcept;

  Scenario scenario_;
  PmsmPlant plant_;
  Inverter inverter_;
  EdgeIntegrator edges_;
  bool edge_to_edge_;
  FocController foc_;
  Sensors sensors_;
  std::int64_t period_ns_;
  std::int64_t samples_total_;
  std::int64_t k_ = 0;  ///< index of the next logged sample
  std::int64_t warmup_periods_ = 0;
  int substeps_ = 1;

  PlantParameters parameters_;
  RegimeTimeline regimes_;
  ThermalPlant thermal_;  ///< enabled by the scenario's thermal_plant
  RegimeNow regime_;
  double theta_frame_rad_ = 0.0;    ///< open loop: the commanded angle (unwrapped)
  double omega_frame_rad_s_ = 0.0;  ///< open loop: the commanded speed (electrical)
  std::uint64_t rectifying_periods_ = 0;
  double torque_signal_Nm_ = 0.0;
  double load_signal_Nm_ = 0.0;  ///< inertia mechanics' load
  double u_dc_V_ = 0.0;
  core::Vec2 command_now_V_ = core::Vec2::Zero();   ///< acts over the current period
  core::Vec2 command_next_V_ = core::Vec2::Zero();  ///< computed this period, acts in the next
  Duties duties_now_, duties_next_;
  double u_dc_modulated_V_ = 0.0;  ///< the measured DC link duties_next_ was modulated for
  double u_dc_meas_V_ = 0.0;
  double torque_cmd_Nm_ = 0.0;
  double t_winding_C_ = 0.0;
  double t_magnet_C_ = 0.0;

  // samples taken at the start of the current period
  core::Vec3 i_meas_A_ = core::Vec3::Zero();
  double theta_meas_rad_ = 0.0;
  double omega_meas_rad_s_ = 0.0;
};

}  // namespace rpem::sim
