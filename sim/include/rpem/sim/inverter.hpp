#pragma once
// Two-level voltage-source inverter with carrier-based PWM (triangular carrier, asymmetrical regular
// sampling: the duty is updated at every carrier valley and peak), dead time and device voltage drops.
//
// Within a half carrier period the carrier is linear, so each leg switches at most once: its gates
// command one state up to the PWM edge, both transistors off for the dead time (blanking), and the
// other state after it (schedule()). During blanking the freewheeling diode sets the leg by the sign
// of the phase current, so a positive current loses t_dead·u_dc of volt-seconds per carrier period, a
// negative one gains it — the textbook error −sign(i)·t_dead·f_sw·u_dc. leg_voltage() gives the leg's
// voltage for a command and a current sign, device drops included.
//
// Switching fidelity: mean_voltage() returns the exact mean over a fixed plant step with the current
// sign at its start (the fixed-step integrator), and EdgeIntegrator integrates from edge to edge
// with the sign followed through its zero crossings. Averaged fidelity returns the mean over the
// whole half period.

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

/// What a leg's gates command: the upper transistor on, the lower one on, or neither (dead time).
enum class LegCommand { kLow, kHigh, kBlank };

/// A leg over one half carrier period: `first` on [0, switch_s), blanking on [switch_s, on_s),
/// `last` on [on_s, half period]. A leg that does not switch has switch_s = on_s = half period.
struct LegSchedule {
  LegCommand first = LegCommand::kHigh;
  LegCommand last = LegCommand::kHigh;
  double switch_s = 0.0;  ///< the PWM edge: the conducting transistor turns off
  double on_s = 0.0;      ///< the dead time later (at most the half period): the other turns on
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

  /// Leg `d`'s commands over a half carrier period (switching fidelity).
  [[nodiscard]] LegSchedule schedule(bool rising, double d) const noexcept;

  /// Leg voltage against the DC link's negative rail under command `c` with a phase current of sign
  /// `sign` (+1: out of the leg; 0: no current, ideal devices): high through the upper transistor
  /// (u_dc − v_igbt) or diode (u_dc + v_diode), low through the lower diode (−v_diode) or transistor
  /// (+v_igbt); blanking leaves it to the diode the current's sign selects.
  [[nodiscard]] double leg_voltage(LegCommand c, int sign, double u_dc_V) const noexcept;

  [[nodiscard]] double half_period_s() const noexcept { return half_period_s_; }
  [[nodiscard]] const InverterConfig& config() const noexcept { return config_; }

 private:
  [[nodiscard]] double high_fraction(bool rising, double tau, double h, double d, double i) const noexcept;

  InverterConfig config_;
  double half_period_s_;
};

}  // namespace rpem::sim
