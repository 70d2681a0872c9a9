#pragma once
// Turns SI drive samples into the estimator's per-unit rotor-frame intervals. This is where the
// Park transform is done, once, for every input frame, and where the configured model
// extensions that act on the inputs (docs/model-extensions.md) are applied.
//
// For the interval [t_{k−1}, t_k] the command u^s_{k−1} (stator frame, held) enters the trapezoidal
// predictor at both ends: u_start = T(ϑ_{k−1})·u^s_{k−1}, u_end = T(ϑ_k)·u^s_{k−1}.

#include <array>

#include "rpem/core/drive_sample.hpp"
#include "rpem/core/estimator.hpp"
#include "rpem/core/frames.hpp"
#include "rpem/core/per_unit.hpp"

namespace rpem::core {

/// Input-side model extensions (all zero: the nominal model).
struct InputCorrections {
  double theta_offset_rad = 0.0;             ///< true angle = measured angle + offset
  Vec3 current_offset_A = Vec3::Zero();      ///< per phase: measured = true·(1 + gain) + offset
  Vec3 current_gain_error = Vec3::Zero();    ///< per phase, relative
  double deadtime_v_err_V = 0.0;             ///< constant part of the per-leg voltage error
  double deadtime_t_dead_s = 0.0;            ///< dead time; adds t_dead·f_sw·u_dc to the voltage error
  double switching_frequency_Hz = 0.0;       ///< f_sw for the dead-time term
  double deadtime_current_band_A = 0.0;      ///< sign(i) is linear within ±band (0: hard sign)
  double delay_s = 0.0;                      ///< extra delay of the applied voltage, 0 ≤ delay < T_samp
};

class SampleConditioner {
 public:
  SampleConditioner(const PerUnitBase& base, const InputCorrections& corrections) noexcept;

  /// Converts one sample. A non-finite input yields a non-finite sample (rejected by the estimator)
  /// and restarts the interval chain. Real-time safe.
  [[nodiscard]] EstimatorSample condition(const DriveSample& s) noexcept;

  /// Forgets the previous sample: the next one starts a new interval chain (resynchronises).
  void reset() noexcept { has_previous_ = false; }

  void set_corrections(const InputCorrections& c) noexcept;
  [[nodiscard]] const InputCorrections& corrections() const noexcept { return corrections_; }
  [[nodiscard]] const PerUnitBase& base() const noexcept { return base_; }

  /// Measured current in the rotor frame [A], after the current corrections, at rotation `rot`.
  [[nodiscard]] Vec2 current_dq_A(const DriveSample& s, const Rotation& rot) const noexcept;
  /// Voltage command in the stator frame [V], as issued (before dead-time correction).
  [[nodiscard]] static Vec2 command_alphabeta_V(const DriveSample& s, const Rotation& rot) noexcept;

 private:
  [[nodiscard]] Vec2 deadtime_error_alphabeta_V(const Vec2& i_ab_A, double u_dc_V) const noexcept;

  PerUnitBase base_;
  InputCorrections corrections_;
  // Reciprocals, so the per-sample path multiplies instead of dividing.
  double inv_current_A_ = 0.0, inv_voltage_V_ = 0.0, inv_omega_rad_s_ = 0.0;
  Vec3 inv_current_gain_ = Vec3::Ones();  ///< 1/(1 + gain error) per phase
  bool has_previous_ = false;
  std::int64_t previous_t_ns_ = 0;
  Rotation previous_rotation_;
  double previous_n_pu_ = 0.0;
  Vec2 previous_u_ab_V_ = Vec2::Zero();  ///< applied voltage of the previous command (after corrections)
  Vec2 older_u_ab_V_ = Vec2::Zero();     ///< the command before that (for the delay extension)
};

}  // namespace rpem::core
