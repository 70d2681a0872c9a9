#pragma once
// Averaged rotor-frame samples (README "Averaged mode"): contiguous windows of uneven length, each closed
// by a host timestamp t and opened at the previous one (t_start).
#include <array>
#include <cstdint>
#include <random>
#include <vector>

namespace indep {

struct AveragedRow {
  double t_s = 0, t_start_s = 0;
  double i_d_A = 0, i_q_A = 0, u_d_V = 0, u_q_V = 0, omega_el_rad_s = 0, u_dc_V = 0;
  double T_winding_C = 0, T_magnet_C = 0;
};

/// i_d, i_q, u_d, u_q, ω, u_dc, T_winding, T_magnet.
using AveragedSample = std::array<double, 8>;

class IntervalAverager {
 public:
  /// Window lengths uniform in mean·(1 ± jitter), clipped to [min, max].
  IntervalAverager(double mean_interval_s, double jitter_rel, double min_interval_s, double max_interval_s,
                   std::uint64_t seed);
  /// A signal linear between (t0, y0) and (t1, y1), integrated exactly over each window it touches.
  void add_segment(double t0, const AveragedSample& y0, double t1, const AveragedSample& y1);
  /// One sample at t (a drive's per-cycle value): windows average the samples whose t lies in [t_start, t).
  void add_sample(double t, const AveragedSample& y);
  [[nodiscard]] const std::vector<AveragedRow>& rows() const { return rows_; }

 private:
  void close_window();
  double next_length();
  double mean_, jitter_, min_, max_;
  std::mt19937_64 rng_;
  double start_ = 0.0, end_ = 0.0;
  AveragedSample sum_{};
  double weight_ = 0.0;
  std::vector<AveragedRow> rows_;
};

}  // namespace indep
