#pragma once
// Two-level voltage-source inverter with carrier-based PWM (triangular carrier, asymmetrical regular
// sampling: the duty is updated at every carrier valley and peak), dead time and device voltage drops.
//
// Switching fidelity returns the exact mean leg voltage over each plant step: within a half carrier
// period the carrier is linear, so each leg is high on one interval whose ends are the PWM edge
// (moved by the dead time according to the current sign). Averaged fidelity returns the mean over
// the whole half period. Dead time: during the blanking interval the freewheeling diode sets the
// leg, so a positive phase current loses t_dead·u_dc of volt-seconds per carrier period, a negative
// one gains it — the textbook error −sign(i)·t_dead·f_sw·u_dc.

#include "rpem/core/types.hpp"

namespace rpem::sim {

enum class InverterModel { kAveraged, kSwitching };

struct InverterConfig {
  InverterModel model = InverterModel::kSwitching;
  double switching_frequency_Hz = 4000.0;
  double dead_time_s = 0.0;
  double v_igbt_V = 0.0;   ///< on-state drop of a conducting transistor
  double v_diode_V = 0.0;  ///< forward drop of a conducting diode
  bool third_harmonic_injection = true;
};

/// Duty cycles (0…1) of the three legs for one half carrier period.
struct Duties {
  core::Vec3 d = core::Vec3::Constant(0.5);
};

/// Modulator: duties that realise a stator-frame voltage command on a DC link of u_dc (measured),
/// with sinusoidal 3rd-harmonic injection (u_0 = −(U/6)·cos 3φ), which extends the linear range to
/// |u| = u_dc/√3. Duties saturate at 0 and 1 beyond it.
[[nodiscard]] Duties modulate(const core::Vec2& u_ab_V, double u_dc_V, bool third_harmonic) noexcept;

class Inverter {
 public:
  explicit Inverter(const InverterConfig& config) noexcept;

  /// Mean phase-to-neutral voltage (αβ) over [τ, τ + h] of a half carrier period, τ measured from
  /// the half-period start. `rising` is true for the half from valley to peak. `i_abc_A` gives the
  /// current direction of each leg; `u_dc_V` is the true DC-link voltage.
  [[nodiscard]] core::Vec2 mean_voltage(bool rising, double tau_s, double h_s, const Duties& duties,
                                        const core::Vec3& i_abc_A, double u_dc_V) const noexcept;

  [[nodiscard]] double half_period_s() const noexcept { return half_period_s_; }
  [[nodiscard]] const InverterConfig& config() const noexcept { return config_; }

 private:
  [[nodiscard]] double high_fraction(bool rising, double tau, double h, double d, double i) const noexcept;

  InverterConfig config_;
  double half_period_s_;
};

}  // namespace rpem::sim
