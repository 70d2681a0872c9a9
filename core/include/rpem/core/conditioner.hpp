#pragma once
// Turns SI drive samples into the estimator's per-unit rotor-frame intervals. This is where the
// Park transform is done, once, for every input frame, and where the configured model extensions
// (docs/model-extensions.md; found by `rpem diagnose`) are applied.
//
// Every input goes to the stator frame with the logged angle (dq logs were made with it), takes the
// sensor and inverter corrections there, and comes back to the rotor frame with the corrected angle
// ϑ = ϑ_logged + offset. For the interval [t_{k−1}, t_k] the command u^s_{k−1} (stator frame, held)
// enters the trapezoidal predictor at both ends: u_start = T(ϑ_{k−1})·u^s_{k−1}, u_end = T(ϑ_k)·u^s_{k−1}.

#include <array>

#include "rpem/core/drive_sample.hpp"
#include "rpem/core/estimator.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/core/per_unit.hpp"

namespace rpem::core {

/// An axis inductance as a function of that axis' current (ld_saturation, lq_saturation):
///   L(i) = L_nom·(level + slope·i + curvature·i²)
/// level 1, slope and curvature 0 is the nominal constant inductance. The slope is the d axis' asymmetry:
/// the magnet biases the d path, so field-weakening current (i_d < 0) de-saturates it and magnetising
/// current saturates it; the q axis is symmetric (slope 0).
struct InductanceCurve {
  double level = 1.0;
  double curvature_per_A2 = 0.0;
  double slope_per_A = 0.0;
  [[nodiscard]] bool nominal() const noexcept { return level == 1.0 && curvature_per_A2 == 0.0 && slope_per_A == 0.0; }
  [[nodiscard]] double factor(double i_A) const noexcept { return level + (slope_per_A + curvature_per_A2 * i_A) * i_A; }
};

/// A harmonic of the rotor-frame flux linkage (flux_harmonic_6, flux_harmonic_12): the magnet's flux
/// distribution and slotting add to ψ_dq = [L_d·i_d + ψm, L_q·i_q]
///   ψ_h(ϑ) = [d_cos·cos hϑ + d_sin·sin hϑ,  q_cos·cos hϑ + q_sin·sin hϑ]   [Wb]
/// of order h = 6k (the 5th and 7th, 11th and 13th of the phase back-EMF). It induces, at speed ω,
///   e_h = ω·(∂ψ_h/∂ϑ + J·ψ_h),  J = [0 −1; 1 0]                   (docs/model-extensions.md)
/// which the conditioner takes from the applied voltage.
struct FluxHarmonic {
  double d_cos_Wb = 0.0, d_sin_Wb = 0.0, q_cos_Wb = 0.0, q_sin_Wb = 0.0;
  [[nodiscard]] bool nominal() const noexcept {
    return d_cos_Wb == 0.0 && d_sin_Wb == 0.0 && q_cos_Wb == 0.0 && q_sin_Wb == 0.0;
  }
  /// The largest |ψ_h| over a revolution [Wb].
  [[nodiscard]] double amplitude_Wb() const noexcept;
};

/// The orders of ModelExtensions::flux_harmonics.
inline constexpr std::array<int, 2> kFluxHarmonicOrders{6, 12};

/// Delays up to this many sample periods (whole and fractional) are modelled.
inline constexpr int kMaxDelayPeriods = 3;

/// Model extensions (all defaults: the nominal model). Input side: what the sensors and the inverter do
/// to the logged quantities; machine side: what the constant-parameter model leaves out.
struct ModelExtensions {
  double theta_offset_rad = 0.0;           ///< true angle = logged angle + offset
  Vec3 current_offset_A = Vec3::Zero();    ///< per phase: measured = true·(1 + gain) + offset
  Vec3 current_gain_error = Vec3::Zero();  ///< per phase, relative
  double deadtime_v_err_V = 0.0;           ///< constant part of the per-leg voltage error
  double deadtime_t_dead_s = 0.0;          ///< dead time; adds t_dead·f_sw·u_dc to the voltage error
  double switching_frequency_Hz = 0.0;     ///< f_sw for the dead-time term
  double deadtime_current_band_A = 0.0;    ///< sign(i) is linear within ±band (0: hard sign)
  /// Extra delay of the applied voltage, 0 ≤ delay < (kMaxDelayPeriods + 1)·T_samp: whole control periods
  /// (a drive's computation delay) and fractions of one.
  double delay_s = 0.0;
  InductanceCurve inductance_d;  ///< ld_saturation
  InductanceCurve inductance_q;  ///< lq_saturation
  /// cross_saturation: the two lowest-order reciprocal co-energy terms even in i_q, (c/2)·i_d·i_q² and
  /// (c₂/2)·i_d²·i_q², so that
  ///   ψ_d = L_d·i_d + ψm + (c/2 + c₂·i_d)·i_q²,   ψ_q = (L_q + c·i_d + c₂·i_d²)·i_q
  /// (L_q against i_d, and the d-axis flux against the load); quasi-static (docs/model-extensions.md).
  double cross_coupling_H_per_A = 0.0;   ///< c [H/A = Wb/A²]
  double cross_coupling_H_per_A2 = 0.0;  ///< c₂ [H/A² = Wb/A³]
  double iron_loss_r_fe_Ohm = 0.0;       ///< resistance parallel to the induced voltage; 0: none
  std::array<FluxHarmonic, kFluxHarmonicOrders.size()> flux_harmonics{};  ///< orders kFluxHarmonicOrders

  [[nodiscard]] bool saturation() const noexcept {
    return !inductance_d.nominal() || !inductance_q.nominal() || cross_coupling_H_per_A != 0.0 ||
           cross_coupling_H_per_A2 != 0.0;
  }
  [[nodiscard]] bool harmonics() const noexcept {
    for (const FluxHarmonic& h : flux_harmonics) {
      if (!h.nominal()) return true;
    }
    return false;
  }
  /// Whether SampleConditioner's condition() and observed_current_dq_A() read the machine's constants
  /// under these extensions: the inductance curves scale x_d and x_q, iron loss needs them and ψm, r_s.
  /// Without either, conditioners of one base and these extensions give the same results for any machine.
  [[nodiscard]] bool reads_machine() const noexcept { return saturation() || iron_loss_r_fe_Ohm > 0.0; }
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
  [[nodiscard]] Vec2 logged_current_dq_A(const DriveSample& s) const noexcept {
    return logged_current_dq_A(s, Rotation::of(s.theta_el_rad));
  }
  /// The same with the logged angle's rotation computed by the caller (it depends on nothing configured).
  [[nodiscard]] static Vec2 logged_current_dq_A(const DriveSample& s, const Rotation& logged) noexcept;
  /// What the log would show for a model current (magnetising, rotor frame, pu): the extensions'
  /// observation model — iron-loss current added, per-phase gain and offset applied — as dq at the
  /// logged angle [A]. The inverse of the corrections condition() applies; `rpem diagnose` compares
  /// models in this measured space.
  [[nodiscard]] Vec2 observed_current_dq_A(const DriveSample& s, const Vec2& i_model_pu) const noexcept {
    return observed_current_dq_A(s, Rotation::of(s.theta_el_rad), i_model_pu);
  }
  /// The same with the logged angle's rotation, Rotation::of(s.theta_el_rad), computed by the caller
  /// (a replay of many models over one log computes it once per sample).
  [[nodiscard]] Vec2 observed_current_dq_A(const DriveSample& s, const Rotation& logged,
                                           const Vec2& i_model_pu) const noexcept;

  /// Forgets the previous sample: the next one starts a new interval chain (resynchronises).
  void reset() noexcept { has_previous_ = false; }

  /// New base, machine and extensions; the sample chain carries on (no resynchronisation).
  void reconfigure(const PerUnitBase& base, const MachinePu& machine, const ModelExtensions& x) noexcept;
  [[nodiscard]] const ModelExtensions& extensions() const noexcept { return extensions_; }
  [[nodiscard]] const PerUnitBase& base() const noexcept { return base_; }

 private:
  /// The parts every sample needs: angles, corrected current, speed, inductances.
  struct Measured {
    Rotation logged;  ///< at the logged angle
    Rotation rot;     ///< at the corrected angle
    Vec2 i_ab_pu;     ///< corrected phase currents, stator frame (before iron loss)
    Vec2 i_dq_pu;     ///< magnetising current, rotor frame (iron-loss current removed)
    Vec2 i_fe_dq_pu;  ///< iron-loss current
    double n_pu;
    double x_d_pu, x_q_pu;  ///< inductances at the measured current (the nominal ones without curves)
  };
  [[nodiscard]] Measured measure(const DriveSample& s, const Rotation& logged) const noexcept;
  /// The true phase currents from measured ones: (measured − offset)/(1 + gain error).
  [[nodiscard]] Vec3 corrected_phases_A(const Vec3& measured_A) const noexcept;
  /// The corrected phase currents, stator frame [pu].
  [[nodiscard]] Vec2 current_alphabeta_pu(const DriveSample& s, const Rotation& logged) const noexcept;
  /// The command issued with the sample, stator frame [pu].
  [[nodiscard]] Vec2 command_alphabeta_pu(const DriveSample& s, const Rotation& logged) const noexcept;
  [[nodiscard]] double deadtime_voltage_V(double u_dc_V) const noexcept;
  [[nodiscard]] Vec2 deadtime_error_alphabeta_V(const Vec2& i_ab_A, double u_dc_V) const noexcept;
  /// The voltage the flux harmonics and the cross-saturation's d-axis flux induce at this sample, rotor
  /// frame [pu]: n·(∂ψ_h/∂ϑ + J·ψ_h) + n·J·[(c/2 + c₂·i_d)·i_q², 0].
  /// (`harmonics` false: without the flux harmonics, for the steady state.)
  [[nodiscard]] Vec2 extra_emf_pu(const Rotation& rot, double n_pu, const Vec2& i_dq_pu, bool harmonics) const noexcept;
  /// x_d, x_q at a rotor-frame current [pu]: the saturation curves and the cross-coupling's L_q(i_d).
  [[nodiscard]] Vec2 inductances_pu(const Vec2& i_dq_pu) const noexcept;
  /// The command the machine sees over the interval ending now, stator frame [pu]: the command issued
  /// `delay` earlier, blended between the two issued around that instant.
  [[nodiscard]] Vec2 delayed_command_alphabeta_pu(double dt_s) const noexcept;

  PerUnitBase base_;
  MachinePu machine_;
  ModelExtensions extensions_;
  // Reciprocals, so the per-sample path multiplies instead of dividing.
  double inv_current_A_ = 0.0, inv_voltage_V_ = 0.0, inv_omega_rad_s_ = 0.0;
  ScaledClarke current_pu_, voltage_pu_;  ///< phase samples [A], [V] → stator frame [pu], one step
  double inv_r_fe_pu_ = 0.0;              ///< 1/r_fe in pu; 0 without iron loss
  Vec3 inv_current_gain_ = Vec3::Ones();  ///< 1/(1 + gain error) per phase
  Rotation offset_rotation_;              ///< by theta_offset_rad
  std::array<FluxHarmonic, kFluxHarmonicOrders.size()> harmonics_pu_{};  ///< flux harmonics in pu
  double half_cross_pu_ = 0.0;                                           ///< c/2 in pu (ψ_b/I_b²)
  double cross2_pu_ = 0.0;                                               ///< c₂ in pu (ψ_b/I_b³)
  double cross_x_q_pu_per_A_ = 0.0;                                      ///< c/L_b: x_q's change per ampere of i_d [pu/A]
  double cross_x_q_pu_per_A2_ = 0.0;                                     ///< c₂/L_b [pu/A²]
  // Which extensions are active, decided when configured (the per-sample path tests one flag each).
  bool angle_offset_ = false, phase_corrections_ = false, saturation_ = false, deadtime_ = false;
  bool harmonics_ = false, cross_ = false, delay_ = false;
  bool corrections_ = false;  ///< dead time or iron loss: the voltage takes a correction
  bool emf_ = false;          ///< flux harmonics or cross-saturation: extra_emf_pu() is not zero
  bool has_previous_ = false;
  std::int64_t previous_t_ns_ = 0;
  Rotation previous_rotation_;
  double previous_n_pu_ = 0.0;
  Vec2 previous_correction_ab_pu_ = Vec2::Zero();  ///< inverter and iron-loss corrections at the previous sample
  Vec2 previous_emf_pu_ = Vec2::Zero();            ///< extra_emf_pu() at the previous sample
  RotationTracker logged_rotation_;                ///< at the logged angle, incremental between consecutive samples
  /// The last commands issued, stator frame [pu], newest first (commands_[0] is the previous sample's).
  std::array<Vec2, kMaxDelayPeriods + 2> commands_{};
};

}  // namespace rpem::core
