#pragma once
// Turns SI drive samples into the estimator's per-unit rotor-frame intervals. This is where the
// Park transform is done, once, for every input frame, and where the configured model extensions
// (docs/model-extensions.md; found by `rpem diagnose`) are applied.
//
// Every input goes to the stator frame with the logged angle (dq logs were made with it), takes the
// sensor and inverter corrections there, and comes back to the rotor frame with the corrected angle
// ϑ = ϑ_logged + offset. For the interval [t_{k−1}, t_k] the command u^s_{k−1} (stator frame, held)
// enters the trapezoidal predictor at both ends: u_start = T(ϑ_{k−1})·u^s_{k−1}, u_end = T(ϑ_k)·u^s_{k−1}.

#include "rpem/core/drive_sample.hpp"
#include "rpem/core/estimator.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/core/per_unit.hpp"

namespace rpem::core {

/// An axis inductance as a function of that axis' current (ld_saturation, lq_saturation):
///   L(i) = L_nom·(level + curvature·i²)
/// level 1 and curvature 0 is the nominal constant inductance.
struct InductanceCurve {
  double level = 1.0;
  double curvature_per_A2 = 0.0;
  [[nodiscard]] bool nominal() const noexcept { return level == 1.0 && curvature_per_A2 == 0.0; }
  [[nodiscard]] double factor(double i_A) const noexcept { return level + curvature_per_A2 * i_A * i_A; }
};

/// Model extensions (all defaults: the nominal model). Input side: what the sensors and the inverter do
/// to the logged quantities; machine side: what the constant-parameter model leaves out.
struct ModelExtensions {
  double theta_offset_rad = 0.0;             ///< true angle = logged angle + offset
  Vec3 current_offset_A = Vec3::Zero();      ///< per phase: measured = true·(1 + gain) + offset
  Vec3 current_gain_error = Vec3::Zero();    ///< per phase, relative
  double deadtime_v_err_V = 0.0;             ///< constant part of the per-leg voltage error
  double deadtime_t_dead_s = 0.0;            ///< dead time; adds t_dead·f_sw·u_dc to the voltage error
  double switching_frequency_Hz = 0.0;       ///< f_sw for the dead-time term
  double deadtime_current_band_A = 0.0;      ///< sign(i) is linear within ±band (0: hard sign)
  double delay_s = 0.0;                      ///< extra delay of the applied voltage, 0 ≤ delay < T_samp
  InductanceCurve inductance_d;              ///< ld_saturation
  InductanceCurve inductance_q;              ///< lq_saturation
  double iron_loss_r_fe_Ohm = 0.0;           ///< resistance parallel to the induced voltage; 0: none

  [[nodiscard]] bool saturation() const noexcept { return !inductance_d.nominal() || !inductance_q.nominal(); }
};

/// One sample's inputs for the steady-state model (dq logs sampled far apart in time): the command
/// as the machine sees it, the measured current, the speed and the inductances at that current, pu.
struct SteadyStateInputs {
  Vec2 u_pu = Vec2::Zero();
  Vec2 i_pu = Vec2::Zero();
  double n_pu = 0.0;
  double x_d_pu = 0.0;
  double x_q_pu = 0.0;
};

class SampleConditioner {
 public:
  /// `machine` is the nominal machine (the inductance curves scale its inductances; iron loss needs
  /// its flux linkage and resistance).
  SampleConditioner(const PerUnitBase& base, const MachinePu& machine, const ModelExtensions& extensions) noexcept;

  /// Converts one sample. A non-finite input yields a non-finite sample (rejected by the estimator)
  /// and restarts the interval chain. Real-time safe.
  [[nodiscard]] EstimatorSample condition(const DriveSample& s) noexcept;

  /// The same sample for the steady-state model: the command issued with it (the dead-time error
  /// averaged over an electrical revolution, −(4/π)·v_err·i/|i|; no delay), independent of other
  /// samples. Real-time safe.
  [[nodiscard]] SteadyStateInputs steady_state(const DriveSample& s) const noexcept;

  /// The logged current as dq at the logged angle, uncorrected [A]: what the log itself says.
  [[nodiscard]] Vec2 logged_current_dq_A(const DriveSample& s) const noexcept;
  /// What the log would show for a model current (magnetising, rotor frame, pu): the extensions'
  /// observation model — iron-loss current added, per-phase gain and offset applied — as dq at the
  /// logged angle [A]. The inverse of the corrections condition() applies; `rpem diagnose` compares
  /// models in this measured space.
  [[nodiscard]] Vec2 observed_current_dq_A(const DriveSample& s, const Vec2& i_model_pu) const noexcept;

  /// Forgets the previous sample: the next one starts a new interval chain (resynchronises).
  void reset() noexcept { has_previous_ = false; }

  /// New base, machine and extensions; the sample chain carries on (no resynchronisation).
  void reconfigure(const PerUnitBase& base, const MachinePu& machine, const ModelExtensions& x) noexcept;
  [[nodiscard]] const ModelExtensions& extensions() const noexcept { return extensions_; }
  [[nodiscard]] const PerUnitBase& base() const noexcept { return base_; }

 private:
  /// The parts every sample needs: angles, corrected current, speed, inductances.
  struct Measured {
    Rotation logged;       ///< at the logged angle
    Rotation rot;          ///< at the corrected angle
    Vec2 i_ab_A;           ///< corrected phase currents, stator frame (before iron loss)
    Vec2 i_dq_pu;          ///< magnetising current, rotor frame (iron-loss current removed)
    Vec2 i_fe_dq_pu;       ///< iron-loss current
    double n_pu;
    double x_d_pu, x_q_pu;  ///< inductances at the measured current (the nominal ones without curves)
  };
  [[nodiscard]] Measured measure(const DriveSample& s, const Rotation& logged) const noexcept;
  /// The true phase currents from measured ones: (measured − offset)/(1 + gain error).
  [[nodiscard]] Vec3 corrected_phases_A(const Vec3& measured_A) const noexcept;
  [[nodiscard]] Vec2 current_alphabeta_A(const DriveSample& s, const Rotation& logged) const noexcept;
  [[nodiscard]] static Vec2 command_alphabeta_V(const DriveSample& s, const Rotation& logged) noexcept;
  [[nodiscard]] double deadtime_voltage_V(double u_dc_V) const noexcept;
  [[nodiscard]] Vec2 deadtime_error_alphabeta_V(const Vec2& i_ab_A, double u_dc_V) const noexcept;

  PerUnitBase base_;
  MachinePu machine_;
  ModelExtensions extensions_;
  // Reciprocals, so the per-sample path multiplies instead of dividing.
  double inv_current_A_ = 0.0, inv_voltage_V_ = 0.0, inv_omega_rad_s_ = 0.0;
  double inv_r_fe_pu_ = 0.0;                 ///< 1/r_fe in pu; 0 without iron loss
  Vec3 inv_current_gain_ = Vec3::Ones();     ///< 1/(1 + gain error) per phase
  Rotation offset_rotation_;                 ///< by theta_offset_rad
  // Which extensions are active, decided when configured (the per-sample path tests one flag each).
  bool angle_offset_ = false, phase_corrections_ = false, saturation_ = false, deadtime_ = false;
  bool has_previous_ = false;
  std::int64_t previous_t_ns_ = 0;
  Rotation previous_rotation_;
  double previous_n_pu_ = 0.0;
  Vec2 previous_u_ab_V_ = Vec2::Zero();  ///< applied voltage of the previous command (after corrections)
  RotationTracker logged_rotation_;      ///< at the logged angle, incremental between consecutive samples
  Vec2 older_u_ab_V_ = Vec2::Zero();     ///< the command before that (for the delay extension)
};

}  // namespace rpem::core
