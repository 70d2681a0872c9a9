#pragma once
// The inverter as the controller drives it: modulation (zero-sequence injection, linear range) and the
// command delay line (README "Inverter"). The leg voltages it produces are averages over a PWM period
// (zero-order hold); the dead-time error on top of them lives in the plant (DeadTime), since it follows
// the instantaneous current.
#include <array>
#include <cstddef>
#include <string_view>

namespace indep {

enum class Modulation { sine, third_harmonic, space_vector };

/// Modulation from its name (`sine`, `third_harmonic`, `space_vector`); throws std::invalid_argument.
Modulation modulation_from_name(std::string_view name);
const char* modulation_name(Modulation m);

/// Largest phase-voltage amplitude of the linear range: u_dc/2 (sine), u_dc/√3 (third harmonic, space vector).
double linear_limit_V(double u_dc_V, Modulation m);

/// Leg duty cycles for zero-sum phase commands u_abc at DC-link voltage u_dc (as the controller measures it):
///   d_x = ½ + (u_x + u_0)/u_dc, clamped to [0, 1];  u_0 = 0 (sine), −Û/6·cos 3φ (third harmonic),
///   −(max + min)/2 (space vector: min-max injection).
std::array<double, 3> duty_cycles(const std::array<double, 3>& u_abc_V, double u_dc_V, Modulation m);

/// The command delay: duties issued at t_k act from t_k + delay (delay = n·T_c + f·T_c, 0 ≤ f < 1, n ≤ 3),
/// so within [t_k, t_k+1) the legs carry issue k−n−1 until t_k + f·T_c and issue k−n after it.
class DelayLine {
 public:
  static constexpr int kMaxPeriods = 4;
  explicit DelayLine(double delay_periods);
  /// Stores the duties issued in the current period (call once per period, before `first`/`second`).
  void push(const std::array<double, 3>& duties);
  [[nodiscard]] const std::array<double, 3>& first() const;   // acts on [t_k, t_k + f·T_c)
  [[nodiscard]] const std::array<double, 3>& second() const;  // acts on [t_k + f·T_c, t_k+1)
  [[nodiscard]] double fraction() const { return fraction_; }
  [[nodiscard]] int whole_periods() const { return whole_; }

 private:
  [[nodiscard]] const std::array<double, 3>& issued_ago(int periods) const;
  std::array<std::array<double, 3>, kMaxPeriods + 2> ring_{};
  std::size_t head_ = 0;  // index of the newest issue
  int whole_ = 0;
  double fraction_ = 0.0;
};

}  // namespace indep
