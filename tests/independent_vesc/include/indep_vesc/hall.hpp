#pragma once
// Hall-sensor mode (README "Hall mode"): three digital Hall sensors on the stator reading the rotor's field, the
// table VESC Tool's Hall detection writes for them, and the angle the FOC firmware makes of them every control
// cycle with foc_sensor_mode = FOC_SENSOR_MODE_HALL. Re-expressed from reading vedderb/bldc (b9d287b3):
// motor/foc_math.c foc_correct_hall; motor/mcpwm_foc.c mcpwm_foc_hall_detect and the two calls of
// foc_correct_hall in mcpwm_foc_adc_int_handler; util/utils_sys.c utils_read_hall_hw; util/utils_math.c
// utils_interpolate_angles_rad; motor/mcconf_default.h (foc_hall_interp_erpm 500, foc_sl_erpm_start 2500,
// foc_sl_erpm 3500, the table's 255 "invalid"). No code copied.
//
// The sensors (my derivation): sensor k (k = 0, 1, 2: H1, H2, H3) sits at the electrical position
// φ_k = φ_0 + k·120° and sees the rotor's radial field ∝ cos(θ − φ_k), θ the rotor's d axis; a latch reads 1 where
// that is positive. Each sensor switches at θ = φ_k ± 90°, i.e. the three together every 60° at
// θ = φ_0 + 30° + m·60°, one bit at a time; the six states (H1 + 2·H2 + 4·H3: 1, 3, 2, 6, 4, 5 going forwards) are
// the sectors centred on φ_0 + m·60°, and 0 and 7 never occur.
#include <array>

namespace indep::vesc {

inline constexpr int kHallInvalid = 255;  // a table entry detection could not fill (mcconf_default.h's default)

/// The three sensors' state H1 | H2 << 1 | H3 << 2 at the rotor's electrical angle (sensor 1 at offset_rad).
int hall_state(double theta_el_rad, double offset_rad);

/// The true centre of a state's sector, φ_0 + m·60° in [0, 2π); NaN for 0, 7 or out of range.
double hall_sector_centre_rad(int state, double offset_rad);

/// The table mcpwm_foc_hall_detect writes for ideal sensors: the rotor locked by d-axis current to the commanded
/// angle, swept in 1° steps three times forwards (0…359°) and three times backwards (360…0°); per state the angle of
/// the sum of the unit vectors at the angles it was read at, in [0°, 360°), as ang·200/360 truncated (0–199);
/// kHallInvalid for a state read 30 times or fewer. The rotor is taken to follow the commanded angle exactly.
std::array<int, 8> detect_hall_table(double offset_rad);

struct HallSettings {
  std::array<int, 8> table{kHallInvalid, kHallInvalid, kHallInvalid, kHallInvalid,
                           kHallInvalid, kHallInvalid, kHallInvalid, kHallInvalid};
  double interp_erpm = 500.0;     // foc_hall_interp_erpm: nearest state's angle below, interpolation above
  double sl_erpm_start = 2500.0;  // foc_sl_erpm_start: the Hall angle only below
  double sl_erpm = 3500.0;        // foc_sl_erpm: the observer only above
};

/// foc_correct_hall: per control cycle, from the observer's angle, the PLL's speed and the state read.
class HallAngle {
 public:
  explicit HallAngle(const HallSettings& s) : s_(s) {}

  /// One control cycle of dt_s; returns the angle the cycle uses. `override_active`/`override_rad`: the open-loop
  /// angle of the sensorless start-up, used only while the state read is invalid (as the firmware does).
  double correct(double observer_rad, double pll_speed_rad_s, int state, double dt_s, bool override_active = false,
                 double override_rad = 0.0);

  /// Weight of the Hall (or override) angle in the last result: 1 below foc_sl_erpm_start, 0 with the observer's.
  [[nodiscard]] double weight() const { return weight_; }
  /// The interpolated Hall angle (m_ang_hall) and its rate-limited form (m_ang_hall_rate_limited).
  [[nodiscard]] double interpolated_rad() const { return ang_; }
  [[nodiscard]] double rate_limited_rad() const { return ang_limited_; }
  /// Whether the last cycle took the nearest state's angle (below foc_hall_interp_erpm by the transition times).
  [[nodiscard]] bool nearest() const { return nearest_; }
  /// The signed time between the last two transitions (m_hall_dt_diff_last) [s].
  [[nodiscard]] double dt_last_s() const { return dt_last_; }
  [[nodiscard]] const HallSettings& settings() const { return s_; }

 private:
  HallSettings s_;
  double dt_now_ = 1.0, dt_last_ = 1.0;  // the firmware starts both at 1 s
  int prev_ = -1;                        // table value of the previous state; −1: none valid
  double ang_ = 0.0, ang_limited_ = 0.0;
  double weight_ = 0.0;
  bool nearest_ = false;
};

}  // namespace indep::vesc
