#pragma once
// What the drive measures (README "Sensors"): each error is applied to the true value first, then noise,
// then quantisation —
//   current:  i_meas = Q_adc(g_x·i_x + o_x + n),  n ~ N(0, σ_i²),  Q_adc rounds to 2·FS/2^bits, clips at ±FS
//   angle:    θ_meas = p·Q_enc((θ + Δθ)/p) mod 2π,  Q_enc rounds to 2π/N_enc (mechanical)
//   u_dc:     u_meas = Q(u_dc + n_u), speed ω_meas = ω + n_ω, temperatures T + n_T
#include <array>
#include <cstdint>
#include <random>

namespace indep {

struct SensorSpec {
  double current_noise_A = 0.0;
  int adc_bits = 12;  // 0: no quantisation
  double adc_full_scale_A = 1.0;
  std::int64_t encoder_counts_per_rev = 1 << 14;  // mechanical; 0: ideal
  double u_dc_noise_V = 0.0;
  int u_dc_adc_bits = 12;
  double u_dc_full_scale_V = 1.0;
  double omega_noise_rad_s = 0.0;
  double temperature_noise_K = 0.0;
};

struct SensorErrors {
  std::array<double, 3> gain{1.0, 1.0, 1.0};
  std::array<double, 3> offset_A{0.0, 0.0, 0.0};
  double logged_minus_true_rad = 0.0;  // θ_logged = θ_true + this, before quantisation
};

/// Rounds v to a grid of 2·full_scale/2^bits within ±full_scale (bits = 0: unchanged).
double quantise_bipolar(double v, double full_scale, int bits);

class Sensors {
 public:
  Sensors(const SensorSpec& spec, const SensorErrors& errors, int pole_pairs, std::uint64_t seed);
  std::array<double, 3> currents(const std::array<double, 3>& i_true_A);
  [[nodiscard]] double angle(double theta_true_rad) const;
  double u_dc(double u_dc_true_V);
  double omega(double omega_true_rad_s);
  double temperature(double t_true_C);

 private:
  double gauss(double sigma);
  SensorSpec spec_;
  SensorErrors errors_;
  int pole_pairs_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
};

}  // namespace indep
