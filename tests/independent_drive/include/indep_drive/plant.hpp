#pragma once
// The machine and the averaged inverter output stage, integrated on flux-linkage states
// (README "Plant"). In the rotor frame at the true angle θ:
//
//   dψ/dt = u − R_s·i − ω·J·ψ,            dθ/dt = ω          (J = rotation by +90°)
//   ψ     = ψ_map(i_m) + ψm·h(θ)          (h: flux harmonics, HarmonicFlux)
//   i     = i_m + (dψ/dt + ω·J·ψ) / R_fe  (iron loss: a resistance across the induced voltage)
//   u     = Park(Clarke(v_leg + e_dead(i_abc)), θ)
//
// e_dead is the per-leg dead-time and device voltage, smooth in the phase current (DeadTime).
#include <array>
#include <limits>

#include "indep_drive/flux_model.hpp"
#include "indep_drive/frames.hpp"

namespace indep {

/// Rotor-frame magnet-flux harmonics relative to ψm, from back-EMF harmonics of order n∓1 in the stator frame:
///   h(θ) = Σ_n [ h_lo·e^{jφ_lo}·e^{−jnθ} + h_hi·e^{jφ_hi}·e^{+jnθ} ]      (n = 6: 5th and 7th; n = 12: 11th and 13th)
/// so the stator-frame magnet flux is ψm·(e^{jθ} + h_lo·e^{jφ_lo}·e^{−j(n−1)θ} + h_hi·e^{jφ_hi}·e^{j(n+1)θ}).
struct HarmonicPair {
  int order = 6;                            // n
  double h_lo_rel = 0.0, phi_lo_rad = 0.0;  // stator order n−1 (negative sequence)
  double h_hi_rel = 0.0, phi_hi_rad = 0.0;  // stator order n+1 (positive sequence)
};

struct HarmonicFlux {
  std::array<HarmonicPair, 2> pairs{};
  int count = 0;
  void add(const HarmonicPair& p) { pairs[static_cast<std::size_t>(count++)] = p; }
  [[nodiscard]] Vec2 value(double theta) const;       // h(θ)
  [[nodiscard]] Vec2 derivative(double theta) const;  // dh/dθ
};

/// Per-leg average voltage error of dead time and device drops against the leg current (README "Dead time"):
///   e(i) = −(t_dead·f_sw·u_dc + v_device)·tanh(i / i_band)
struct DeadTime {
  double amplitude_V = 0.0;  // t_dead·f_sw·u_dc + v_device
  double band_A = 1.0;       // i_band
  [[nodiscard]] double error_V(double i_A) const;
};

/// What the plant sees at an instant besides its state.
struct Operating {
  double omega_el_rad_s = 0.0;
  double r_s_Ohm = 0.0;
  double psi_m_Wb = 0.0;
};

struct PlantState {
  Vec2 psi_Wb;           // rotor-frame flux linkage (harmonics included)
  double theta_rad = 0;  // true electrical angle, unwrapped
  Vec2 i_m_A;            // magnetising current of the last evaluation (Newton's start)
};

struct PlantEval {
  Vec2 i_A;      // terminal current, rotor frame
  Vec2 i_m_A;    // magnetising current
  Vec2 u_V;      // applied voltage, rotor frame
  Vec2 dpsi_dt;  // V
  std::array<double, 3> i_abc_A{};
};

class Plant {
 public:
  Plant(FluxModel flux, HarmonicFlux harmonics, double r_fe_Ohm, DeadTime dead_time, bool dead_time_on);

  /// The state's currents and flux derivative for leg voltages v_leg (w.r.t. the DC midpoint, before dead time).
  [[nodiscard]] PlantEval evaluate(const PlantState& x, const std::array<double, 3>& v_leg_V, const Operating& op) const;

  /// Electromagnetic torque 1.5·p·(ψ_d·i_m,q − ψ_q·i_m,d + ψm·i_m·dh/dθ) [Nm].
  [[nodiscard]] double torque_Nm(const PlantState& x, const PlantEval& e, const Operating& op, int pole_pairs) const;
  /// Magnetic field energy 1.5·(i_m·ψ_map − W'(i_m)) [J] (harmonic part excluded: it is linear in i).
  [[nodiscard]] double field_energy_J(const PlantEval& e, const Operating& op) const;
  /// Iron loss 1.5·R_fe·|i − i_m|² [W].
  [[nodiscard]] double iron_loss_W(const PlantEval& e) const;

  [[nodiscard]] const FluxModel& flux() const { return flux_; }
  [[nodiscard]] const HarmonicFlux& harmonics() const { return harmonics_; }

 private:
  FluxModel flux_;
  HarmonicFlux harmonics_;
  double r_fe_ = std::numeric_limits<double>::infinity();
  DeadTime dead_time_;
  bool dead_time_on_ = false;
};

}  // namespace indep
